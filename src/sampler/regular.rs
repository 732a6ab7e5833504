//! Regular grid: the centres of the cells of a k×k grid.

use glam::Vec2;

use super::Sampler;
use super::pattern::{Pattern, cell_coordinate, grid_side, pattern_rng};

/// The cell centres of the k×k grid with the largest k such that k² ≤ n, row by row.
/// When n is not a square the remaining n − k² points are uniform random (the only use
/// of `seed`), so the pattern still returns n points; pass a square n for a pure grid.
pub fn points(n: usize, seed: u64) -> Vec<Vec2> {
    let k = grid_side(n);
    let mut points = Vec::with_capacity(n);
    for j in 0..k {
        for i in 0..k {
            points.push(Vec2::new(
                cell_coordinate(i, k, 0.5),
                cell_coordinate(j, k, 0.5),
            ));
        }
    }
    let mut rng = pattern_rng(seed, n, Pattern::Regular);
    points.extend((k * k..n).map(|_| rng.next_2d()));
    points
}
