//! Poisson-disk point sets by dart throwing on the unit torus.
//!
//! Dart throwing (random sequential adsorption) proposes uniform points and keeps those at
//! least r away from every kept point. Two accelerations leave that distribution unchanged
//! (Ebeida et al. 2011, "Efficient maximal Poisson-disk sampling", phase 1): a grid of cells
//! of side ≤ r/√2 holds at most one point each, so a test visits a few cells; and darts are
//! thrown only into "active" cells (no point yet, not known to be covered by one disk), a
//! uniform choice among equal cells, so no dart lands where it is certain to fail.
//!
//! The radius is a fixed fraction of the densest packing's spacing,
//! r = `RELATIVE_RADIUS` · √(2/(√3·N)) (Lagae & Dutré 2008). Throwing stops at N points,
//! after `ATTEMPTS_PER_POINT`·N darts, or when no active cell is left; the result respects r
//! exactly (toroidal distance of the stored f32 coordinates, `pattern::toroidal_distance`)
//! but may hold fewer than N points.

use glam::Vec2;

use super::independent::IndependentSampler;
use super::pattern::{
    Pattern, cell_coordinate, cell_index, max_packing_radius, pattern_rng, toroidal_distance,
    uniform_f64,
};

/// The minimum distance relative to the densest packing's spacing.
pub const RELATIVE_RADIUS: f64 = 0.75;

/// The dart budget per requested point.
pub const ATTEMPTS_PER_POINT: usize = 200;

/// The minimum distance `points` uses for N points.
pub fn radius(n: usize) -> f64 {
    RELATIVE_RADIUS * max_packing_radius(n)
}

/// A Poisson-disk set of (up to) `n` points with minimum toroidal distance `radius(n)`.
pub fn points(n: usize, seed: u64) -> Vec<Vec2> {
    dart_throwing(n, radius(n), seed, ATTEMPTS_PER_POINT * n).points
}

/// What a dart-throwing run produced.
pub struct DartThrowing {
    pub points: Vec<Vec2>,
    /// Darts thrown (proposals tested against the neighbours).
    pub attempts: usize,
    /// Whether it stopped because no active cell was left (the set is then close to
    /// maximal: only cells covered by several disks together may still be active).
    pub exhausted: bool,
}

/// Dart throwing on the torus: up to `n` points at toroidal distance ≥ `r` from each other,
/// at most `max_attempts` darts.
pub fn dart_throwing(n: usize, r: f64, seed: u64, max_attempts: usize) -> DartThrowing {
    if n == 0 {
        return DartThrowing {
            points: Vec::new(),
            attempts: 0,
            exhausted: false,
        };
    }
    let mut rng = pattern_rng(seed, n, Pattern::Poisson);
    // Cells of side 1/g ≤ r/√2: a cell's diagonal is at most r, so it holds one point.
    let g = ((2f64.sqrt() / r).ceil() as usize).clamp(1, 1 << 14);
    let side = 1.0 / g as f64;
    let offsets = neighbour_offsets(g, r);

    let mut grid = vec![u32::MAX; g * g];
    let mut active: Vec<u32> = (0..(g * g) as u32).collect();
    let mut points: Vec<Vec2> = Vec::with_capacity(n);
    let mut attempts = 0;
    while points.len() < n && attempts < max_attempts && !active.is_empty() {
        let slot = pick(&mut rng, active.len());
        let cell = active[slot] as usize;
        let (cx, cy) = (cell % g, cell / g);
        attempts += 1;
        let p = Vec2::new(
            cell_coordinate(cx, g, uniform_f64(&mut rng)),
            cell_coordinate(cy, g, uniform_f64(&mut rng)),
        );
        debug_assert_eq!((cell_index(p.x, g), cell_index(p.y, g)), (cx, cy));
        let neighbours = offsets.iter().filter_map(|&(dx, dy)| {
            let nx = (cx + dx) % g;
            let ny = (cy + dy) % g;
            let q = grid[ny * g + nx];
            (q != u32::MAX).then(|| points[q as usize])
        });
        let mut conflict = false;
        let mut covered = false;
        for q in neighbours {
            if toroidal_distance(p, q) < r {
                conflict = true;
                covered = covered || covers_cell(q, cx, cy, side, r);
            }
        }
        if !conflict {
            grid[cell] = points.len() as u32;
            points.push(p);
            active.swap_remove(slot);
        } else if covered {
            active.swap_remove(slot);
        }
    }
    DartThrowing {
        points,
        attempts,
        exhausted: active.is_empty(),
    }
}

/// A uniform index in 0..len (Lemire's multiply-shift; the bias is below 2^-32).
fn pick(rng: &mut IndependentSampler, len: usize) -> usize {
    ((rng.next_u64() as u128 * len as u128) >> 64) as usize
}

/// The cell offsets (taken modulo g, all non-negative) whose cells may hold a point closer
/// than r to a point of the centre cell. When the neighbourhood wraps around the torus every
/// cell is listed once.
fn neighbour_offsets(g: usize, r: f64) -> Vec<(usize, usize)> {
    let reach = (r * g as f64).ceil().min(g as f64) as usize;
    if 2 * reach + 1 >= g {
        return (0..g).flat_map(|y| (0..g).map(move |x| (x, y))).collect();
    }
    let side = 1.0 / g as f64;
    let mut offsets = Vec::new();
    for dy in -(reach as i64)..=reach as i64 {
        for dx in -(reach as i64)..=reach as i64 {
            // Closest approach of two cells |dx|, |dy| apart.
            let gx = (dx.unsigned_abs().saturating_sub(1)) as f64 * side;
            let gy = (dy.unsigned_abs().saturating_sub(1)) as f64 * side;
            if gx * gx + gy * gy < r * r {
                let wrap = |d: i64| d.rem_euclid(g as i64) as usize;
                offsets.push((wrap(dx), wrap(dy)));
            }
        }
    }
    offsets
}

/// Whether the disk of radius r about q contains the whole cell (cx, cy) (all four
/// corners, on the torus; a disk is convex).
fn covers_cell(q: Vec2, cx: usize, cy: usize, side: f64, r: f64) -> bool {
    let axis = |p: f64, c: f64| {
        let d = (p - c).abs();
        d.min(1.0 - d)
    };
    [(0, 0), (1, 0), (0, 1), (1, 1)].iter().all(|&(i, j)| {
        let dx = axis(q.x as f64, (cx + i) as f64 * side);
        let dy = axis(q.y as f64, (cy + j) as f64 * side);
        dx * dx + dy * dy < r * r
    })
}
