//! A kd-tree over 3D points for photon mapping: photons are stored once per pass and every
//! hit point asks for those within its radius (`within_radius`); `nearest` answers
//! k-nearest queries (the `radius=auto` estimate and the benches).
//!
//! Layout (implicit, no child pointers): the points are permuted so that the node covering
//! the slots [lo, hi) holds its median point, on one axis, in slot mid = lo + (hi − lo)/2;
//! its children cover [lo, mid), coordinates ≤ the median's, and [mid + 1, hi),
//! coordinates ≥ it. A node of at most `LEAF_SIZE` points is a leaf, scanned linearly.
//! Each internal node's axis is one byte at its median slot, so the tree costs 16 bytes per
//! point (the position and its original index) plus one.
//!
//! The split axis is the longest side of the node's bounding box, and the median split
//! halves every node: the depth is ⌈log2(n / LEAF_SIZE)⌉ whatever the input (all points
//! equal, all on a plane), and the build is O(n log n). Queries compare squared distances
//! computed by `distance_squared` alone, so a brute-force scan with it finds exactly the
//! same points (the pruning test is exact under rounding: see `within_radius`).

use glam::Vec3;

/// Points a leaf holds at most.
pub const LEAF_SIZE: usize = 32;

/// Ranges larger than this build their two halves in parallel.
const PARALLEL_BUILD: usize = 1 << 15;

/// A point in the tree: its position and its index in the input.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
struct Entry {
    p: [f32; 3],
    id: u32,
}

/// The squared Euclidean distance, summed x, y, z in that order: the one formula every
/// query (and any brute-force check) uses.
#[inline]
pub fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    let d = a - b;
    d.x * d.x + d.y * d.y + d.z * d.z
}

/// A point that cannot be placed in the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonFinitePoint {
    pub index: usize,
}

impl std::fmt::Display for NonFinitePoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "point {} has a coordinate that is NaN or infinite",
            self.index
        )
    }
}

/// A balanced kd-tree over a fixed set of points.
#[derive(Clone, Debug, Default)]
pub struct KdTree {
    entries: Vec<Entry>,
    /// The split axis of the internal node whose median is slot i (unused elsewhere).
    axes: Vec<u8>,
}

impl KdTree {
    /// Builds the tree over `points` (indices refer to this slice); refuses a point with a
    /// NaN or infinite coordinate.
    pub fn build(points: &[Vec3]) -> Result<KdTree, NonFinitePoint> {
        assert!(
            points.len() <= u32::MAX as usize,
            "too many points for u32 ids"
        );
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(NonFinitePoint { index });
        }
        let mut entries: Vec<Entry> = points
            .iter()
            .enumerate()
            .map(|(i, p)| Entry {
                p: p.to_array(),
                id: i as u32,
            })
            .collect();
        let mut axes = vec![0u8; entries.len()];
        build_range(&mut entries, &mut axes);
        Ok(KdTree { entries, axes })
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Bytes the tree holds per point.
    pub const BYTES_PER_POINT: usize = std::mem::size_of::<Entry>() + 1;

    /// Calls `visit(index, d²)` for every point with d² = `distance_squared` ≤ radius², in
    /// tree order.
    ///
    /// A subtree is skipped when its cell lies beyond the sphere: the query's distance to
    /// the cell along each axis (the nearest split plane of that axis crossed to reach it,
    /// Arya and Mount 1993's incremental distance) gives a lower bound on d², summed as
    /// `distance_squared` sums. The test is exact in floating point: every point p in the
    /// cell has |q − p| ≥ that distance on each axis, rounding is monotone, and so is a
    /// rounded sum of non-negative terms, so the bound never exceeds p's own d².
    pub fn within_radius(&self, centre: Vec3, radius: f32, mut visit: impl FnMut(u32, f32)) {
        let r2 = radius * radius;
        if self.entries.is_empty() || r2.is_nan() || r2 < 0.0 {
            return;
        }
        let mut stack: [Cell; 64] = [Cell::default(); 64];
        let mut top = 1;
        stack[0] = Cell::root(self.entries.len());
        while top > 0 {
            top -= 1;
            let Cell { lo, hi, offset } = stack[top];
            let (mut lo, mut hi) = (lo as usize, hi as usize);
            // Descend towards the query point, pushing far sides that the sphere reaches.
            while hi - lo > LEAF_SIZE {
                let mid = lo + (hi - lo) / 2;
                let node = &self.entries[mid];
                let d2 = distance_squared(centre, Vec3::from_array(node.p));
                if d2 <= r2 {
                    visit(node.id, d2);
                }
                let split = self.split(lo, mid, hi, centre);
                let far = Cell::far(&split, self.axes[mid], offset);
                if far.bound() <= r2 {
                    stack[top] = far;
                    top += 1;
                }
                (lo, hi) = split.near;
            }
            for e in &self.entries[lo..hi] {
                let d2 = distance_squared(centre, Vec3::from_array(e.p));
                if d2 <= r2 {
                    visit(e.id, d2);
                }
            }
        }
    }

    /// The `k` points nearest `centre` as (d², index), nearest first; equal distances are
    /// ordered by index, so the answer is unique.
    pub fn nearest(&self, centre: Vec3, k: usize, out: &mut Vec<(f32, u32)>) {
        out.clear();
        if k == 0 || self.entries.is_empty() {
            return;
        }
        // Keys order by (d², index): d² ≥ 0 is finite, so its bits order as the value. The
        // best k are kept sorted (k is small: an insertion beats a heap).
        let key = |d2: f32, id: u32| ((d2.to_bits() as u64) << 32) | id as u64;
        let mut best: Vec<u64> = Vec::with_capacity(k + 1);
        let offer = |best: &mut Vec<u64>, e: &Entry| {
            let candidate = key(distance_squared(centre, Vec3::from_array(e.p)), e.id);
            if best.len() < k || candidate < best[k - 1] {
                let at = best.partition_point(|&b| b < candidate);
                best.insert(at, candidate);
                best.truncate(k);
            }
        };
        // The worst kept distance so far; a cell no nearer cannot improve (a tie at equal
        // distance may, by index: hence >, not ≥).
        let worst = |best: &Vec<u64>| {
            if best.len() < k {
                f32::INFINITY
            } else {
                f32::from_bits((best[k - 1] >> 32) as u32)
            }
        };
        let mut stack: [Cell; 64] = [Cell::default(); 64];
        let mut top = 1;
        stack[0] = Cell::root(self.entries.len());
        while top > 0 {
            top -= 1;
            let cell = stack[top];
            if cell.bound() > worst(&best) {
                continue;
            }
            let (mut lo, mut hi) = (cell.lo as usize, cell.hi as usize);
            while hi - lo > LEAF_SIZE {
                let mid = lo + (hi - lo) / 2;
                offer(&mut best, &self.entries[mid]);
                let split = self.split(lo, mid, hi, centre);
                let far = Cell::far(&split, self.axes[mid], cell.offset);
                if far.bound() <= worst(&best) {
                    stack[top] = far;
                    top += 1;
                }
                (lo, hi) = split.near;
            }
            for e in &self.entries[lo..hi] {
                offer(&mut best, e);
            }
        }
        out.extend(
            best.into_iter()
                .map(|c| (f32::from_bits((c >> 32) as u32), c as u32)),
        );
    }
}

/// A subtree waiting on a query's stack: its slots and the query's distance to its cell
/// along each axis (0 on an axis where the query lies within the cell's extent).
#[derive(Clone, Copy, Default)]
struct Cell {
    lo: u32,
    hi: u32,
    offset: [f32; 3],
}

impl Cell {
    fn root(len: usize) -> Cell {
        Cell {
            lo: 0,
            hi: len as u32,
            offset: [0.0; 3],
        }
    }

    /// The far child of a split on `axis`: beyond the split plane, so at least |diff| away
    /// along that axis, and no nearer than its parent along the others.
    #[inline]
    fn far(split: &Split, axis: u8, mut offset: [f32; 3]) -> Cell {
        offset[axis as usize] = split.diff.abs();
        Cell {
            lo: split.far.0 as u32,
            hi: split.far.1 as u32,
            offset,
        }
    }

    /// A lower bound on the squared distance from the query to any point in the cell,
    /// summed in `distance_squared`'s order.
    #[inline]
    fn bound(&self) -> f32 {
        let [x, y, z] = self.offset;
        x * x + y * y + z * z
    }
}

/// The children of an internal node, the one on the query's side first.
struct Split {
    near: (usize, usize),
    far: (usize, usize),
    /// The query's signed distance from the splitting plane.
    diff: f32,
}

impl KdTree {
    /// Splits the node of slots [lo, hi) with median `mid` for a query at `centre`.
    #[inline]
    fn split(&self, lo: usize, mid: usize, hi: usize, centre: Vec3) -> Split {
        let axis = self.axes[mid] as usize;
        let diff = centre[axis] - self.entries[mid].p[axis];
        let (near, far) = if diff < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        Split { near, far, diff }
    }
}

/// Arranges `entries` (a node's slots) into the implicit tree, writing each internal
/// node's axis into `axes` (the same slots).
fn build_range(entries: &mut [Entry], axes: &mut [u8]) {
    let n = entries.len();
    if n <= LEAF_SIZE {
        return;
    }
    let axis = longest_axis(entries);
    let mid = n / 2;
    entries.select_nth_unstable_by(mid, |a, b| {
        a.p[axis].total_cmp(&b.p[axis]).then(a.id.cmp(&b.id))
    });
    axes[mid] = axis as u8;
    let (left, rest) = entries.split_at_mut(mid);
    let right = &mut rest[1..];
    let (left_axes, rest_axes) = axes.split_at_mut(mid);
    let right_axes = &mut rest_axes[1..];
    if n > PARALLEL_BUILD {
        rayon::join(
            || build_range(left, left_axes),
            || build_range(right, right_axes),
        );
    } else {
        build_range(left, left_axes);
        build_range(right, right_axes);
    }
}

/// The axis along which `entries` spread widest.
fn longest_axis(entries: &[Entry]) -> usize {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for e in entries {
        for a in 0..3 {
            lo[a] = lo[a].min(e.p[a]);
            hi[a] = hi[a].max(e.p[a]);
        }
    }
    let extent = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    }
}
