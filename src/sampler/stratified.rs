//! Stratified (jittered) sampling: one uniform point in each cell of a k×k grid.

use glam::Vec2;

use super::Sampler;
use super::independent::IndependentSampler;
use super::pattern::{Pattern, cell_coordinate, grid_side, pattern_rng, uniform_f64};

/// One uniform point in each stratum of the k×k grid with the largest k such that
/// k² ≤ n, row by row. When n is not a square the remaining n − k² points are uniform
/// random over the whole square: every point is still uniformly distributed, and the
/// first k² keep the one-per-stratum property.
pub fn points(n: usize, seed: u64) -> Vec<Vec2> {
    let k = grid_side(n);
    let mut rng = pattern_rng(seed, n, Pattern::Stratified);
    let mut points = Vec::with_capacity(n);
    for j in 0..k {
        for i in 0..k {
            let x = cell_coordinate(i, k, uniform_f64(&mut rng));
            let y = cell_coordinate(j, k, uniform_f64(&mut rng));
            points.push(Vec2::new(x, y));
        }
    }
    points.extend((k * k..n).map(|_| rng.next_2d()));
    points
}

/// The same layout in f64 coordinates from a caller's stream (the discrete density of
/// `ccvt`): one uniform point per stratum of the largest k×k grid, the rest uniform.
pub(crate) fn points_f64(n: usize, rng: &mut IndependentSampler) -> Vec<[f64; 2]> {
    let k = grid_side(n);
    let mut points = Vec::with_capacity(n);
    for j in 0..k {
        for i in 0..k {
            let x = (i as f64 + uniform_f64(rng)) / k as f64;
            let y = (j as f64 + uniform_f64(rng)) / k as f64;
            points.push([
                x.min(1.0 - f64::EPSILON / 2.0),
                y.min(1.0 - f64::EPSILON / 2.0),
            ]);
        }
    }
    points.extend((k * k..n).map(|_| [uniform_f64(rng), uniform_f64(rng)]));
    points
}
