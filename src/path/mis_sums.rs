//! The weights of `mis::strategy_weight` at O(1) cost per strategy: partial sums carried
//! along each subpath, so that a bidirectional estimator that tries every (s, t) of a
//! camera sample does not walk the whole path once per connection.
//!
//! `strategy_weight` is w_s = 1 / (1 + L(s) + R(s)) with
//! L(s) = Σ_{j<s} [j can make the path] Π_{i=j}^{s−1} ρ_i,  ρ_i = from_camera(xi) / from_light(xi),
//! R(s) = Σ_{j>s} [j can make the path] Π_{i=s}^{j−1} σ_i,  σ_i = from_light(xi) / from_camera(xi)
//! (Veach 1997, eqs. 10.9 and 10.10; each ratio squared for the power heuristic). Written
//! inside out, L(s) = ρ_(s−1) (c_(s−1) + ρ_(s−2) (c_(s−2) + ρ_(s−3) (…))), c_j the indicator
//! of strategy j. A connection changes only the densities of the two vertices on each side
//! of the joint (x(s−2) … x(s+1)); everything deeper belongs to one subpath and is the same
//! for every strategy that uses it. So each subpath keeps, per vertex k, the partial sum
//! G_k = c_k + ρ_(k−1) G_(k−1) (light side; mirrored on the camera side), computed once
//! per subpath, and a strategy adds its joint's two factors on each side. The same
//! recursion underlies the running MIS quantities of Georgiev's technical report
//! "Implementing Vertex Connection and Merging" (2012) and of van Antwerpen's (2011); here
//! it runs over the density records of `mis` rather than subpath-specific quantities, so
//! every rule of `StrategyRules` carries over unchanged. The partial sums are stored
//! divided by each vertex's own density (`SubpathSums`), so that a strategy's weight needs
//! one division. Sums are kept scaled (`ScaledRatio`) so that no f64 overflow or underflow
//! of a partial product changes a weight.

use crate::path::mis::{Heuristic, PathDensity, ScaledRatio, StrategyRules};

/// x^p in f64: the density itself (balance heuristic) or its square (power heuristic).
#[inline(always)]
fn heuristic_power(x: f32, power: bool) -> f64 {
    let x = x as f64;
    if power { x * x } else { x }
}

/// 1/den^p in f64: ∞ for den = 0.
#[inline(always)]
fn reciprocal(den: f32, power: bool) -> f64 {
    1.0 / heuristic_power(den, power)
}

/// The ratio num^p / den^p given den's reciprocal: exactly 0 when num is 0 (every strategy
/// beyond that vertex is impossible, whatever den), ∞ when only den is 0.
#[inline(always)]
fn ratio(num: f32, reciprocal_den: f64, power: bool) -> f64 {
    if num == 0.0 {
        return 0.0;
    }
    heuristic_power(num, power) * reciprocal_den
}

/// One subpath's partial sums (see the module comment), each already divided by its
/// vertex's own sampling density (to the heuristic's power), and those densities'
/// reciprocals: a strategy's weight then needs no division beyond its last.
#[derive(Clone, Debug, Default)]
pub struct SubpathSums {
    /// G_k / own_k^p (light side), H_m / own_m^p (camera side).
    over_own: Vec<ScaledRatio>,
    /// 1 / own_k^p.
    reciprocal: Vec<f64>,
}

impl SubpathSums {
    fn push(&mut self, sum: ScaledRatio, own: f32, power: bool) {
        let r = reciprocal(own, power);
        self.over_own.push(sum.scaled(r));
        self.reciprocal.push(r);
    }

    /// A light subpath x0 x1 … as `mis` sees its vertices (from_light its own sampling
    /// density, from_camera the reverse one, `connectible` the light side's rule), with
    /// x0's strategy s = 0 possible or not (`light_hittable`): G_0 = c_0,
    /// G_k = c_k + ρ_(k−1) G_(k−1).
    pub fn fill_light(
        &mut self,
        vertices: impl Iterator<Item = PathDensity>,
        light_hittable: bool,
        heuristic: Heuristic,
    ) {
        self.fill(
            vertices,
            light_hittable,
            1,
            |v| (v.from_light, v.from_camera),
            heuristic,
        );
    }

    /// A camera subpath z0 z1 … (z0 the camera; from_camera its own sampling density,
    /// from_light the reverse one): H_0 = 0, H_1 = c'_1, H_m = c'_m + σ_(m−1) H_(m−1), c'_m
    /// the indicator of the strategy with m camera vertices. H_0 = 0 is never multiplied:
    /// z0's ratio belongs to no strategy.
    pub fn fill_camera(
        &mut self,
        vertices: impl Iterator<Item = PathDensity>,
        heuristic: Heuristic,
    ) {
        self.fill(
            vertices,
            false,
            2,
            |v| (v.from_camera, v.from_light),
            heuristic,
        );
    }

    /// S_0 = [first], S_k = [vertices k−1 and k connectible] + ratio_(k−1) S_(k−1), the
    /// ratio read from `k ≥ multiplied_from` on; `own_and_reverse` gives a vertex's own
    /// sampling density and the other direction's.
    fn fill(
        &mut self,
        vertices: impl Iterator<Item = PathDensity>,
        first: bool,
        multiplied_from: usize,
        own_and_reverse: impl Fn(&PathDensity) -> (f32, f32),
        heuristic: Heuristic,
    ) {
        let power = heuristic == Heuristic::Power;
        self.over_own.clear();
        self.reciprocal.clear();
        let mut previous: Option<PathDensity> = None;
        for (k, v) in vertices.enumerate() {
            let (sum, c) = match previous {
                None => (ScaledRatio::ZERO, first),
                Some(p) => {
                    let sum = if k >= multiplied_from {
                        self.over_own[k - 1].scaled(heuristic_power(own_and_reverse(&p).1, power))
                    } else {
                        ScaledRatio::ZERO
                    };
                    (sum, p.connectible && v.connectible)
                }
            };
            self.push(
                if c { sum.plus_one() } else { sum },
                own_and_reverse(&v).0,
                power,
            );
            previous = Some(v);
        }
    }
}

/// The vertices on both sides of strategy s's joint as the complete path sees them, the
/// densities the connection created included: x(s−1), x(s−2) on the light side and x(s),
/// x(s+1) on the camera side (None where the path has no such vertex). Their own sampling
/// densities (from_light on the light side, from_camera on the camera side) are the
/// subpaths', and are read from the sums, except x0's for s = 1 (next-event estimation
/// samples its own light point).
#[derive(Clone, Copy, Debug, Default)]
pub struct Joint {
    pub light: [Option<PathDensity>; 2],
    pub camera: [Option<PathDensity>; 2],
}

/// The weight of strategy (s, t) for its path of s + t vertices, from its joint and the
/// partial sums of the light subpath (its first s − 1 vertices are read) and of the camera
/// subpath (its first t): `mis::strategy_weight` of the same path, up to rounding.
pub fn joint_weight(
    joint: &Joint,
    light: &SubpathSums,
    camera: &SubpathSums,
    s: usize,
    t: usize,
    rules: &StrategyRules,
) -> f32 {
    let n = s + t;
    let power = rules.heuristic == Heuristic::Power;
    let conn = |v: Option<PathDensity>| v.is_some_and(|v| v.connectible);
    let [x_s1, x_s2] = joint.light;
    let [x_s, x_sp1] = joint.camera;
    if t == 0 || !rules.can_make_joining(n, s, conn(x_s1), conn(x_s)) {
        return 0.0;
    }
    // L(s) = ρ_(s−1) (c_(s−1) + ρ_(s−2) G_(s−2)).
    let left = match (x_s1, s) {
        (Some(a), s) if s >= 1 => {
            let inner = match x_s2 {
                Some(b) if s >= 2 => {
                    light.over_own[s - 2].scaled(heuristic_power(b.from_camera, power))
                }
                _ => ScaledRatio::ZERO,
            };
            let inner = if rules.can_make_joining(n, s - 1, conn(x_s2), a.connectible) {
                inner.plus_one()
            } else {
                inner
            };
            let own = if s >= 2 {
                light.reciprocal[s - 1]
            } else {
                reciprocal(a.from_light, power)
            };
            inner.scaled(ratio(a.from_camera, own, power))
        }
        _ => ScaledRatio::ZERO,
    };
    // R(s) = σ_s (c_(s+1) + σ_(s+1) H_(t−2)), H_0 = 0 unread (t = 2).
    let right = match (x_s, x_sp1) {
        (Some(a), Some(b)) if t >= 2 => {
            let inner = if t >= 3 {
                camera.over_own[t - 2].scaled(heuristic_power(b.from_light, power))
            } else {
                ScaledRatio::ZERO
            };
            let inner = if rules.can_make_joining(n, s + 1, a.connectible, b.connectible) {
                inner.plus_one()
            } else {
                inner
            };
            inner.scaled(ratio(a.from_light, camera.reciprocal[t - 1], power))
        }
        _ => ScaledRatio::ZERO,
    };
    let w = 1.0 / (1.0 + left.value() + right.value());
    if w.is_finite() { w as f32 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::mis::strategy_weight;
    use crate::path::mis::tests::path_far_below_f64;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// `joint_weight` of strategy s on a complete path given as `mis` records: the light
    /// subpath is path[..s], the camera subpath path[s..] reversed, the joint the records
    /// around s.
    fn recursive_weight(path: &[PathDensity], s: usize, rules: &StrategyRules) -> f32 {
        let n = path.len();
        let t = n - s;
        let mut light = SubpathSums::default();
        light.fill_light(
            path[..s].iter().copied(),
            rules.light_hittable,
            rules.heuristic,
        );
        let mut camera = SubpathSums::default();
        camera.fill_camera(path[s..].iter().rev().copied(), rules.heuristic);
        let at = |i: Option<usize>| i.and_then(|i| path.get(i).copied());
        let joint = Joint {
            light: [at(s.checked_sub(1)), at(s.checked_sub(2))],
            camera: [at(Some(s)), at((t >= 2).then_some(s + 1))],
        };
        joint_weight(&joint, &light, &camera, s, t, rules)
    }

    fn assert_same_weights(path: &[PathDensity], rules: &StrategyRules, what: &str) {
        for s in 0..path.len() {
            let direct = strategy_weight(path, s, rules);
            let recursive = recursive_weight(path, s, rules);
            let tolerance = 1e-5 * direct.max(1e-30);
            assert!(
                (direct - recursive).abs() <= tolerance,
                "{what}, s = {s}: strategy_weight {direct}, recursive {recursive}"
            );
        }
    }

    #[test]
    fn the_recursive_weights_are_those_of_strategy_weight_on_random_paths() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
        for case in 0..4000 {
            let n = rng.random_range(2..12);
            let density = |rng: &mut Xoshiro256PlusPlus| match rng.random_range(0..10) {
                0 => 0.0,
                1 => 10f32.powf(rng.random_range(-30.0..30.0)),
                _ => rng.random_range(0.01..5.0),
            };
            let path: Vec<PathDensity> = (0..n)
                .map(|_| PathDensity {
                    from_light: density(&mut rng),
                    from_camera: density(&mut rng),
                    connectible: rng.random_range(0..5) > 0,
                })
                .collect();
            for heuristic in [Heuristic::Balance, Heuristic::Power] {
                let rules = StrategyRules {
                    heuristic,
                    hide_emitters: rng.random_range(0..4) == 0,
                    light_hittable: rng.random_range(0..3) > 0,
                    light_seen_by_camera: rng.random_range(0..3) > 0,
                };
                assert_same_weights(&path, &rules, &format!("case {case}, {heuristic:?}"));
            }
        }
    }

    #[test]
    fn partial_products_beyond_f64_keep_their_weights() {
        // The partial products fall to 10⁻³⁵⁰ and climb back to 1; their squares (power
        // heuristic) to 10⁻⁷⁰⁰.
        for heuristic in [Heuristic::Balance, Heuristic::Power] {
            let (path, rules) = path_far_below_f64(heuristic);
            for s in [1, 11] {
                let w = recursive_weight(&path, s, &rules);
                assert!((w - 0.5).abs() < 1e-6, "{heuristic:?}, s = {s}: {w}");
            }
            assert_same_weights(&path, &rules, &format!("{heuristic:?}"));
        }
    }
}
