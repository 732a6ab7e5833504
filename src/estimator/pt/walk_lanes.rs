//! The second half of `Walk::scatter` (and of `PathSample::scatter`) in lanes, shared by
//! every BSDF the lanes sample: the path takes the sampled direction, its throughput and
//! the weights of the next emission, then plays Russian roulette. Operation for operation
//! the scalar code's (see `wavefront.rs`).

use super::PathSample;
use super::hit_lanes::HitLanes;
use super::path_lanes::PathLanes;
use crate::geometry::offset::offset_origin;
use crate::math::frame::LaneFrame;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};

/// A BSDF sample per lane (`BsdfSample`): the direction in the vertex's shading frame,
/// weight f·|cos θ|/p, solid-angle density, whether it is a delta component, and the
/// relative IOR it crossed (1 for a reflection).
pub(super) struct SampleLanes {
    pub wi: V3<F32x16>,
    pub weight: V3<F32x16>,
    pub pdf: F32x16,
    pub delta: Mask16,
    pub eta: F32x16,
}

/// Rust's `f32::max` per lane (a NaN operand gives the other one).
#[inline(always)]
pub(super) fn max_num(a: F32x16, b: F32x16) -> F32x16 {
    F32x16::select(a.is_nan(), b, F32x16::select(b.is_nan(), a, a.max_gt(b)))
}

/// Rust's `f32::min` per lane (a NaN operand gives the other one).
#[inline(always)]
pub(super) fn min_num(a: F32x16, b: F32x16) -> F32x16 {
    F32x16::select(a.is_nan(), b, F32x16::select(b.is_nan(), a, a.min_lt(b)))
}

impl PathSample {
    /// The lanes of `c` leave their hit (a surface that is not `null`) by sample `s`, drawn
    /// in shading frame `frame`; `u_roulette` is the walk's fourth number. Returns the lanes
    /// of `c` whose path ends here: a throughput of 0 or not finite, or Russian roulette
    /// (Mitsuba 3's rule, `Walk::scatter`).
    #[inline(always)]
    pub(super) fn leave_lanes(
        &self,
        lanes: &mut PathLanes,
        hits: &HitLanes,
        frame: &LaneFrame<F32x16>,
        c: Mask16,
        s: &SampleLanes,
        u_roulette: F32x16,
    ) -> Mask16 {
        let zero = F32x16::splat(0.0);
        lanes.throughput = V3::select(c, lanes.throughput.mul_v(s.weight), lanes.throughput);
        lanes.eta = F32x16::select(c, lanes.eta * s.eta, lanes.eta);
        // `scatter`'s `PreviousVertex`.
        lanes.shows_emitters |= c;
        lanes.shows_environment |= c;
        lanes.prev_specular = (lanes.prev_specular & !c) | (s.delta & c);
        lanes.prev_p = V3::select(c, hits.p, lanes.prev_p);
        lanes.prev_pdf = F32x16::select(c, s.pdf, lanes.prev_pdf);
        // `SurfaceInteraction::spawn_ray`.
        let d = frame.to_world(s.wi);
        lanes.origin = V3::select(
            c,
            offset_origin(hits.p, hits.p_error, hits.ng, d),
            lanes.origin,
        );
        lanes.direction = V3::select(c, d, lanes.direction);
        lanes.t_max = F32x16::select(c, F32x16::splat(f32::INFINITY), lanes.t_max);
        lanes.depth = lanes.depth + U32x16::select(c, U32x16::splat(1), U32x16::splat(0));

        // Russian roulette.
        let t = lanes.throughput;
        let max_throughput = max_num(max_num(t.x, t.y), t.z);
        let dark = c & !(max_throughput.gt(zero) & max_throughput.is_finite());
        let rr_depth = U32x16::splat(self.settings.path.rr_depth);
        let roulette = c & !dark & !lanes.depth.lt(rr_depth);
        let q = min_num(max_throughput * lanes.eta * lanes.eta, F32x16::splat(0.95));
        let killed = roulette & u_roulette.ge(q);
        let survived = roulette & !killed;
        lanes.throughput = V3::select(survived, t.div_scalar(q), t);
        dark | killed
    }
}
