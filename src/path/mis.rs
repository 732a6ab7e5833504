//! Multiple importance sampling weights (Veach 1997, §9.2), for two strategies and for all
//! the ways (s, t) a bidirectional estimator can make a path (Veach 1997, §10.3).

/// Power heuristic with β = 2 for a sample drawn by strategy *a*, when strategy *b* could
/// have drawn it too (Veach 1997, eq. 9.13): p_a² / (p_a² + p_b²). The densities must be in
/// the same measure; a weight that is not finite (both zero, or a density that is) is 0.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    let sum = a + b;
    if sum.is_finite() {
        let w = a / sum;
        if w.is_finite() {
            return w;
        }
    }
    // The squares overflow f32 for densities above ~1.8·10¹⁹ (a light of tiny area seen
    // from afar): such a light would be black. f64 holds them.
    let (a, b) = (pdf_a as f64 * pdf_a as f64, pdf_b as f64 * pdf_b as f64);
    let w = (a / (a + b)) as f32;
    if w.is_finite() { w } else { 0.0 }
}

/// Balance heuristic (Veach 1997, eq. 9.10): p_a / (p_a + p_b).
#[inline]
pub fn balance_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let sum = pdf_a + pdf_b;
    if sum.is_finite() {
        let w = pdf_a / sum;
        if w.is_finite() {
            return w;
        }
    }
    // The sum overflows f32 when both densities are near its limit.
    let w = (pdf_a as f64 / (pdf_a as f64 + pdf_b as f64)) as f32;
    if w.is_finite() { w } else { 0.0 }
}

/// Which heuristic weighs the strategies of a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Heuristic {
    /// p_s / Σ p_j (Veach 1997, eq. 9.10).
    Balance,
    /// p_s² / Σ p_j² (Veach 1997, eq. 9.13 with β = 2).
    Power,
}

/// One vertex of a complete path x0 … xk (x0 on a light, xk on the camera) as the weights
/// of its strategies see it: its densities when the light subpath makes it and when the
/// camera subpath does (`path::vertex` gives the measures), and whether a connection may
/// end at it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathDensity {
    /// x0: the light's origin density (choice of the light included); xi: the density of
    /// sampling it from x(i−1).
    pub from_light: f32,
    /// The density of sampling it from x(i+1) (unused for xk).
    pub from_camera: f32,
    /// A connection may end here: not a surface the path crossed through a delta
    /// component.
    pub connectible: bool,
}

/// Which strategies an estimator uses, beyond what the path's delta vertices allow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrategyRules {
    pub heuristic: Heuristic,
    /// The emitter seen directly is left out (paths of one segment count for no strategy).
    pub hide_emitters: bool,
    /// A camera subpath can hit x0: false for point, spot and directional lights.
    pub light_hittable: bool,
    /// Light tracing's s = 1, t = 1 strategy (the light point joined to the camera) can
    /// make the path: false for lights at infinity and delta lights, which the camera
    /// never sees.
    pub light_seen_by_camera: bool,
}

impl StrategyRules {
    /// True when strategy s (s light vertices, t = k + 1 − s camera vertices, t ≥ 1) can
    /// make a path of `path.len()` vertices.
    #[inline(always)]
    fn can_make(&self, path: &[PathDensity], s: usize) -> bool {
        let n = path.len();
        debug_assert!(s < n, "strategies keep at least one camera vertex");
        let before = s.checked_sub(1).is_some_and(|i| path[i].connectible);
        self.can_make_joining(n, s, before, path[s].connectible)
    }

    /// `can_make` for a path of `n` vertices given only whether x(s−1) and x(s), the
    /// vertices strategy s joins, are connectible (`before` is unused for s = 0).
    #[inline(always)]
    pub fn can_make_joining(&self, n: usize, s: usize, before: bool, after: bool) -> bool {
        if n == 2 && self.hide_emitters {
            return false;
        }
        match s {
            0 => self.light_hittable,
            _ => before && after && !(n == 2 && s == 1 && !self.light_seen_by_camera),
        }
    }
}

/// The weight of strategy `s` (s light vertices) for the complete path `path`, over every
/// strategy t ≥ 1 that `rules` allows: h(p_s) / Σ_j h(p_j) with p_j the density with which
/// strategy j makes the path (Veach 1997, eq. 10.9). Only ratios are needed:
/// p_(j−1)/p_j = from_camera(x(j−1)) / from_light(x(j−1)) (eq. 10.10). The ratios are
/// products over the path, kept in a scaled f64 so that neither overflow nor underflow
/// of a partial product changes a weight; 0 when strategy s could not have made the path.
pub fn strategy_weight(path: &[PathDensity], s: usize, rules: &StrategyRules) -> f32 {
    let n = path.len();
    if s >= n || !rules.can_make(path, s) {
        return 0.0;
    }
    let power = rules.heuristic == Heuristic::Power;
    let mut sum = 1.0f64;
    // Strategies with fewer light vertices: x(j) moves to the camera side. A density of 0
    // there ends them all (each later one needs it too).
    let mut ratio = ScaledRatio::ONE;
    for j in (0..s).rev() {
        let v = &path[j];
        if v.from_camera == 0.0 {
            break;
        }
        if !ratio.times(v.from_camera, v.from_light) {
            return 0.0;
        }
        if rules.can_make(path, j) {
            sum += ratio.heuristic(power);
        }
    }
    // Strategies with more light vertices: x(j − 1) moves to the light side.
    let mut ratio = ScaledRatio::ONE;
    for j in s + 1..n {
        let v = &path[j - 1];
        if v.from_light == 0.0 {
            break;
        }
        if !ratio.times(v.from_light, v.from_camera) {
            return 0.0;
        }
        if rules.can_make(path, j) {
            sum += ratio.heuristic(power);
        }
    }
    let w = 1.0 / sum;
    if w.is_finite() { w as f32 } else { 0.0 }
}

/// A non-negative ratio m·2^e, m kept within [2⁻²⁵⁶, 2²⁵⁶] (or 0): a product of path
/// densities, or a sum of such products, that no f64 overflow or underflow cuts short.
#[derive(Clone, Copy, Debug)]
pub(super) struct ScaledRatio {
    m: f64,
    e: i32,
}

impl ScaledRatio {
    pub(super) const ZERO: ScaledRatio = ScaledRatio { m: 0.0, e: 0 };
    const ONE: ScaledRatio = ScaledRatio { m: 1.0, e: 0 };
    /// 2²⁵⁶.
    const LIMIT: f64 = 1.157_920_892_373_162e77;

    /// self × num / den for num > 0; false when the ratio is infinite (den = 0: the other
    /// strategy's density has no finite ratio to ours, and this one's weight is 0).
    #[inline(always)]
    fn times(&mut self, num: f32, den: f32) -> bool {
        self.m *= num as f64 / den as f64;
        if self.m > Self::LIMIT || self.m < 1.0 / Self::LIMIT {
            return self.rescale();
        }
        true
    }

    /// self × r for r ≥ 0: exactly 0 for r = 0 (whatever self is), ∞ or NaN kept (they
    /// make the weight that reads them 0).
    #[inline(always)]
    pub(super) fn scaled(self, r: f64) -> ScaledRatio {
        if r == 0.0 {
            return ScaledRatio::ZERO;
        }
        if self.m == 0.0 {
            // 0 × ∞ is NaN: an infinite ratio makes the weight 0 even over an empty sum,
            // as `strategy_weight` has it.
            return ScaledRatio {
                m: self.m * r,
                e: 0,
            };
        }
        let mut out = ScaledRatio {
            m: self.m * r,
            e: self.e,
        };
        if out.m > Self::LIMIT || out.m < 1.0 / Self::LIMIT {
            out.rescale();
        }
        out
    }

    /// self + 1.
    #[inline(always)]
    pub(super) fn plus_one(self) -> ScaledRatio {
        let m = match self.e {
            0 => self.m + 1.0,
            // 1 in units of 2^e (0 once it is below f64's range: negligible beside m).
            e if e > 0 => {
                return ScaledRatio {
                    m: self.m + 2f64.powi(-e),
                    e,
                };
            }
            // self < 1 (m ≤ 2²⁵⁶, e ≤ −256): plain f64 holds the sum.
            e => self.m * 2f64.powi(e) + 1.0,
        };
        let mut out = ScaledRatio { m, e: 0 };
        if m > Self::LIMIT {
            out.rescale();
        }
        out
    }

    /// The value as an f64 (∞ or 0 where it leaves f64's range).
    #[inline(always)]
    pub(super) fn value(self) -> f64 {
        self.heuristic(false)
    }

    /// Moves powers of 2²⁵⁶ from m to e; false for an infinite or NaN m.
    #[cold]
    fn rescale(&mut self) -> bool {
        if !self.m.is_finite() || self.m == 0.0 {
            return false;
        }
        while self.m > Self::LIMIT {
            self.m /= Self::LIMIT;
            self.e += 256;
        }
        while self.m < 1.0 / Self::LIMIT {
            self.m *= Self::LIMIT;
            self.e -= 256;
        }
        true
    }

    /// The ratio (balance heuristic) or its square (power heuristic) as an f64, ∞ or 0 only
    /// where that leaves f64's range.
    #[inline(always)]
    fn heuristic(self, power: bool) -> f64 {
        let (m, e) = if power {
            (self.m * self.m, 2 * self.e)
        } else {
            (self.m, self.e)
        };
        if e == 0 {
            m
        } else {
            // In two steps, so that 2^e alone does not overflow where the product would not.
            let half = e / 2;
            m * 2f64.powi(half) * 2f64.powi(e - half)
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    #[test]
    fn weights_of_two_strategies_sum_to_one() {
        for (a, b) in [(1.0, 3.0), (0.2, 0.0), (5.0, 5.0), (1e-20, 1e-3)] {
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
            assert!((balance_heuristic(a, b) + balance_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(2.0, 0.0), 1.0);
        assert_eq!(balance_heuristic(1.0, 3.0), 0.25);
        assert_eq!(power_heuristic(1.0, 3.0), 0.1);
    }

    #[test]
    fn densities_whose_squares_overflow_f32_keep_their_weight() {
        assert_eq!(power_heuristic(3e19, 0.3), 1.0);
        assert!(power_heuristic(0.3, 3e19) < 1e-30);
        assert_eq!(power_heuristic(3e19, 3e19), 0.5);
        assert_eq!(power_heuristic(1.4e19, 1.4e19), 0.5);
        assert_eq!(balance_heuristic(3e38, 3e38), 0.5);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 0.0);
    }

    /// Vertices 0..12 (light to camera) where only strategies s = 1 and s = 11 can connect,
    /// with `factors[j]` = from_camera / from_light of vertex j.
    fn path_with_ratios(factors: &[(f32, f32)]) -> Vec<PathDensity> {
        factors
            .iter()
            .enumerate()
            .map(|(j, &(from_camera, from_light))| PathDensity {
                from_light,
                from_camera,
                connectible: matches!(j, 0 | 1 | 10 | 11),
            })
            .collect()
    }

    /// A path on which going from s = 11 down to s = 1 the ratio falls to 10⁻³⁵⁰ (below
    /// f64) and climbs back to 1: strategies 1 and 11, the only ones that can make it, have
    /// the same density, weight ½ each. With its rules for `heuristic`.
    pub(in crate::path) fn path_far_below_f64(
        heuristic: Heuristic,
    ) -> (Vec<PathDensity>, StrategyRules) {
        let mut factors = vec![(1.0, 1.0)];
        factors.extend([(1e35, 1e-35); 5]);
        factors.extend([(1e-35, 1e35); 5]);
        factors.push((1.0, 1.0));
        let rules = StrategyRules {
            heuristic,
            hide_emitters: false,
            light_hittable: false,
            light_seen_by_camera: true,
        };
        (path_with_ratios(&factors), rules)
    }

    #[test]
    fn a_ratio_far_below_f64_on_the_way_does_not_lose_a_strategy_of_equal_density() {
        for heuristic in [Heuristic::Balance, Heuristic::Power] {
            let (path, rules) = path_far_below_f64(heuristic);
            for s in [1, 11] {
                let w = strategy_weight(&path, s, &rules);
                assert!((w - 0.5).abs() < 1e-6, "{heuristic:?}, s = {s}: {w}");
            }
            assert_eq!(strategy_weight(&path, 5, &rules), 0.0, "not connectible");
        }
    }

    #[test]
    fn weights_of_every_strategy_sum_to_one_and_skip_the_ones_that_cannot_make_the_path() {
        let path: Vec<PathDensity> = [(0.3, 2.0), (4.0, 0.5), (1e-3, 7.0), (2.0, 2.0), (0.0, 1.0)]
            .iter()
            .enumerate()
            .map(|(j, &(from_light, from_camera))| PathDensity {
                from_light,
                from_camera,
                connectible: j != 2,
            })
            .collect();
        let rules = StrategyRules {
            heuristic: Heuristic::Balance,
            hide_emitters: false,
            light_hittable: true,
            light_seen_by_camera: true,
        };
        // Strategies 2 and 3 join at vertex 2, which is not connectible.
        let w: Vec<f32> = (0..5).map(|s| strategy_weight(&path, s, &rules)).collect();
        assert_eq!((w[2], w[3]), (0.0, 0.0));
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6, "{w:?}");
        // Balance weights are proportional to the strategies' densities: p_s = Π_{i<s}
        // from_light · Π_{s≤i<4} from_camera.
        let p = |s: usize| -> f64 {
            let l: f64 = path[..s].iter().map(|v| v.from_light as f64).product();
            let c: f64 = path[s..4].iter().map(|v| v.from_camera as f64).product();
            l * c
        };
        let total = p(0) + p(1) + p(4);
        for s in [0, 1, 4] {
            assert!((w[s] as f64 - p(s) / total).abs() < 1e-6, "s = {s}");
        }
    }
}
