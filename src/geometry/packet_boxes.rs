//! Boxes around runs of a packet's records, so that sixteen rays skip the runs none of them
//! can hit.
//!
//! The sixteen-ray queries (`packet.rs`) test every record against every lane. Records are
//! in the tree's leaf order, so a run of `RUN` consecutive records is usually one small
//! part of the scene (a face of a block, a patch of a mesh). Coherent rays, such as the
//! camera rays of a tile, miss most runs together; one slab test per run and lane then
//! replaces `RUN` triangle tests. A lane whose box test fails cannot hit any triangle of
//! the run: the test is the tree's conservative one (`WideNode::hitmask`: Ize 2013's
//! allowance for rounding, zero direction components as ±∞ reciprocals, the segment
//! extended by `TriangleBvh::hit_pad`'s allowance for the triangle test's own rounding), so
//! the queries' answers, bit for bit, do not change.

use super::wide_node::EXIT_SCALE;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};

/// Records per box.
pub const RUN: usize = 4;

/// One box per run of `RUN` records (the last run may be shorter): its lower and upper
/// corner, the exact extremes of the runs' vertex coordinates.
#[derive(Clone, Default)]
pub struct RunBoxes {
    boxes: Vec<[[f32; 3]; 2]>,
    /// The box around every record, for the segment's extension (`BoxRays::pad`).
    bounds: [[f32; 3]; 2],
}

impl RunBoxes {
    /// The boxes of `vertices(i)`, the three vertices of record i, for `n` records.
    pub fn new(n: usize, vertices: impl Fn(usize) -> [[f32; 3]; 3]) -> RunBoxes {
        let empty = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
        let grow = |b: &mut [[f32; 3]; 2], p: [f32; 3]| {
            for k in 0..3 {
                b[0][k] = b[0][k].min(p[k]);
                b[1][k] = b[1][k].max(p[k]);
            }
        };
        let mut bounds = empty;
        let boxes = (0..n)
            .step_by(RUN)
            .map(|first| {
                let mut b = empty;
                for i in first..(first + RUN).min(n) {
                    for p in vertices(i) {
                        grow(&mut b, p);
                        grow(&mut bounds, p);
                    }
                }
                b
            })
            .collect();
        RunBoxes { boxes, bounds }
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.boxes.len()
    }

    /// The lanes of `m` whose segment (0, t_max), extended by `rays.pad`, may meet the
    /// box of run `run`.
    #[inline(always)]
    pub fn hits(&self, run: usize, rays: &BoxRays, t_max: F32x16, m: Mask16) -> Mask16 {
        let [lo, hi] = self.boxes[run];
        let splat = F32x16::splat;
        let o = [rays.o.x, rays.o.y, rays.o.z];
        let inv = [rays.inv_d.x, rays.inv_d.y, rays.inv_d.z];
        // Per axis, the distances to the near and far planes: the lower plane is the near
        // one unless the direction's sign bit is set.
        let slab = |k: usize| {
            let to_lo = (splat(lo[k]) - o[k]) * inv[k];
            let to_hi = (splat(hi[k]) - o[k]) * inv[k];
            (
                F32x16::select(rays.negative[k], to_hi, to_lo),
                F32x16::select(rays.negative[k], to_lo, to_hi),
            )
        };
        let ((near_x, far_x), (near_y, far_y), (near_z, far_z)) = (slab(0), slab(1), slab(2));
        // `WideNode::hitmask_scalar`'s chains, operand for operand (a NaN distance drops
        // out as it does there).
        let t_enter = near_x.max_gt(near_y).max_gt(near_z.max_gt(splat(0.0)));
        let t_exit = far_x.min_lt(far_y).min_lt(far_z.min_lt(t_max + rays.pad));
        m & t_enter.le(t_exit * splat(EXIT_SCALE))
    }
}

/// Sixteen rays prepared for `RunBoxes::hits`.
pub struct BoxRays {
    o: V3<F32x16>,
    /// 1/d per component (±∞ for ±0).
    inv_d: V3<F32x16>,
    /// Lanes whose direction component has its sign bit set (−0 included, whose
    /// reciprocal is −∞).
    negative: [Mask16; 3],
    /// How far beyond t_max the boxes are tested: `TriangleBvh::hit_pad`'s 2⁻¹² of the
    /// largest distance from the origin to the records' box, in units of t.
    pad: F32x16,
}

impl BoxRays {
    /// The rays with origins `o` and directions `d` (those of the triangle tests).
    #[inline(always)]
    pub fn new(boxes: &RunBoxes, o: &V3<F32x16>, d: &V3<F32x16>) -> BoxRays {
        let one = F32x16::splat(1.0);
        let sign = U32x16::splat(0x8000_0000);
        let negative = [d.x, d.y, d.z].map(|c| !(c.to_bits() & sign).eq(U32x16::splat(0)));
        let [lo, hi] = boxes.bounds;
        let reach = |k: usize, o: F32x16| {
            (F32x16::splat(lo[k]) - o)
                .abs()
                .max_gt((F32x16::splat(hi[k]) - o).abs())
        };
        let reach = reach(0, o.x).max_gt(reach(1, o.y)).max_gt(reach(2, o.z));
        let a = d.abs();
        let largest = a.x.max_gt(a.y).max_gt(a.z);
        BoxRays {
            o: *o,
            inv_d: V3::new(one / d.x, one / d.y, one / d.z),
            negative,
            pad: reach * F32x16::splat(1.0 / 4096.0) / largest,
        }
    }
}
