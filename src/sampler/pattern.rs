//! 2D sample patterns: N points in [0, 1)², each set a deterministic function of (N, seed).
//!
//! `points(pattern, n, seed)` is the common entry point; each pattern lives in its own file
//! (`regular`, `stratified`, `poisson`, `ccvt`, `sobol`). The independent pattern is the
//! `IndependentSampler` stream and needs no file of its own. Every pattern returns exactly
//! `n` points except Poisson disk, which may stop short when the domain is saturated (see
//! `poisson`).

use std::fmt;
use std::str::FromStr;

use glam::Vec2;

use super::independent::{IndependentSampler, hash_words};
use super::{Sampler, ccvt, poisson, regular, sobol, stratified};

/// The 2D point patterns the bench compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pattern {
    /// Uniform random points.
    Independent,
    /// Cell centres of a k×k grid.
    Regular,
    /// One uniform point in each of k×k strata (jittered sampling).
    Stratified,
    /// Dart throwing with a minimum toroidal distance.
    Poisson,
    /// Capacity-constrained Voronoi tessellation (Balzer, Schlömer & Deussen 2009).
    Ccvt,
    /// Owen-scrambled Sobol' (0,2)-sequence.
    Sobol,
}

impl Pattern {
    pub const ALL: [Pattern; 6] = [
        Pattern::Independent,
        Pattern::Regular,
        Pattern::Stratified,
        Pattern::Poisson,
        Pattern::Ccvt,
        Pattern::Sobol,
    ];

    /// The name `FromStr` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Pattern::Independent => "independent",
            Pattern::Regular => "regular",
            Pattern::Stratified => "stratified",
            Pattern::Poisson => "poisson",
            Pattern::Ccvt => "ccvt",
            Pattern::Sobol => "sobol",
        }
    }
}

impl fmt::Display for Pattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Pattern {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Pattern::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Pattern::ALL.iter().map(|p| p.name()).collect();
                format!(
                    "unknown sample pattern '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// `n` points of `pattern` in [0, 1)², determined by (`pattern`, `n`, `seed`).
pub fn points(pattern: Pattern, n: usize, seed: u64) -> Vec<Vec2> {
    match pattern {
        Pattern::Independent => independent_points(n, seed),
        Pattern::Regular => regular::points(n, seed),
        Pattern::Stratified => stratified::points(n, seed),
        Pattern::Poisson => poisson::points(n, seed),
        Pattern::Ccvt => ccvt::points(n, seed),
        Pattern::Sobol => sobol::points(n, seed),
    }
}

/// `n` independent uniform points.
pub fn independent_points(n: usize, seed: u64) -> Vec<Vec2> {
    let mut rng = pattern_rng(seed, n, Pattern::Independent);
    (0..n).map(|_| rng.next_2d()).collect()
}

/// The random stream of one pattern for one (seed, n); patterns never share a stream.
pub(crate) fn pattern_rng(seed: u64, n: usize, pattern: Pattern) -> IndependentSampler {
    IndependentSampler::new(hash_words(&[seed, n as u64, pattern as u64]))
}

/// A uniform f64 in [0, 1) with 53 random bits.
pub(crate) fn uniform_f64(rng: &mut IndependentSampler) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The largest k with k² ≤ n: the side of the grid that the regular and stratified
/// patterns lay out.
pub fn grid_side(n: usize) -> usize {
    let mut k = (n as f64).sqrt() as usize;
    while k * k > n {
        k -= 1;
    }
    while (k + 1) * (k + 1) <= n {
        k += 1;
    }
    k
}

/// The cell of a k-cell partition of [0, 1) that `x` falls in: floor(x·k), computed
/// exactly (an f32 times k < 2^29 is exact in f64).
pub fn cell_index(x: f32, k: usize) -> usize {
    (x as f64 * k as f64).floor() as usize
}

/// The f32 nearest to (i + u)/k, moved by an ulp at a time until `cell_index` puts it in
/// cell i: rounding to f32 may otherwise cross the cell's upper edge (or reach 1.0).
pub fn cell_coordinate(i: usize, k: usize, u: f64) -> f32 {
    let mut x = ((i as f64 + u) / k as f64) as f32;
    while cell_index(x, k) > i {
        x = f32::from_bits(x.to_bits() - 1);
    }
    while cell_index(x, k) < i {
        x = f32::from_bits(x.to_bits() + 1);
    }
    x
}

/// Wraps a coordinate onto the unit torus and rounds it to an f32 in [0, 1) (a value that
/// rounds up to 1.0 is the torus' 0).
pub fn wrap_unit(x: f64) -> f32 {
    let y = (x - x.floor()) as f32;
    if y >= 1.0 { 0.0 } else { y }
}

/// Distance on the unit torus, in f64 from the stored f32 coordinates (so a check against
/// a radius gives the same answer wherever it is made).
pub fn toroidal_distance(a: Vec2, b: Vec2) -> f64 {
    let axis = |p: f32, q: f32| {
        let d = (p as f64 - q as f64).abs();
        d.min(1.0 - d)
    };
    let dx = axis(a.x, b.x);
    let dy = axis(a.y, b.y);
    (dx * dx + dy * dy).sqrt()
}

/// The smallest toroidal distance between two of `points` (infinity for fewer than two);
/// O(n²), for tests and diagnostics.
pub fn min_toroidal_distance(points: &[Vec2]) -> f64 {
    let mut best = f64::INFINITY;
    for (i, &a) in points.iter().enumerate() {
        for &b in &points[i + 1..] {
            best = best.min(toroidal_distance(a, b));
        }
    }
    best
}

/// The spacing of N points in the densest (hexagonal) packing of the unit square,
/// √(2/(√3·N)) (Lagae & Dutré 2008, "A comparison of methods for generating Poisson disk
/// distributions"); minimum distances are quoted relative to it.
pub fn max_packing_radius(n: usize) -> f64 {
    (2.0 / (3f64.sqrt() * n as f64)).sqrt()
}
