//! `PathSample::scatter` in lanes, for paths at a `diffuse` surface: next-event
//! estimation (`next_event_lanes.rs`), cosine-weighted sampling of the next direction,
//! Russian roulette. Every operation is the scalar code's, in its order (see
//! `wavefront.rs`), with the scalar code's early returns turned into lane masks.

use super::PathSample;
use super::hit_lanes::HitLanes;
use super::lane_scene::LaneScene;
use super::next_event_lanes::{NeeLanes, queue_light_sample};
use super::path_lanes::PathLanes;
use super::shadow_queue::ShadowQueue;
use super::walk_lanes::SampleLanes;
use crate::math::INV_PI;
use crate::math::frame::LaneFrame;
use crate::math::lanes::{F32x16, Mask16, V3};
use crate::math::warp::cosine_hemisphere;
use crate::scene::Scene;

impl PathSample {
    /// `scatter` for the lanes of `m` (live, at a `diffuse` surface, textured or not). Returns
    /// the lanes whose path ends here.
    pub(super) fn scatter_diffuse(
        &self,
        scene: &Scene,
        tables: &LaneScene,
        lanes: &mut PathLanes,
        hits: &HitLanes,
        m: Mask16,
        shadows: &mut ShadowQueue,
    ) -> Mask16 {
        let zero = F32x16::splat(0.0);
        let zero3 = V3::new(zero, zero, zero);
        let frame = LaneFrame::from_normal(hits.ns);
        let mut wo = frame.to_local(-lanes.direction.normalize());
        // `TwoSided` seen from behind: the back side's reflectance, both directions
        // mirrored through the surface (a negated z, exact: the scalar code's bits).
        let sides = tables.reflectances(scene, hits, m);
        let back = sides.two_sided & wo.z.lt(zero);
        let rho = V3::select(back, sides.back, sides.front);
        let mirror = |z: F32x16| F32x16::select(back, -z, z);
        wo.z = mirror(wo.z);

        // Next-event estimation (`sample_light`).
        let u_light = lanes.streams.next_1d(m);
        let u = lanes.streams.next_2d(m);
        let ls = NeeLanes::sample(scene, &hits.p, u_light, u, m);
        let mut wi = frame.to_local(ls.wi);
        wi.z = mirror(wi.z);
        let inv_pi = F32x16::splat(INV_PI);
        // Diffuse::eval: R/π where both directions are above the surface, black elsewhere.
        let above = wo.z.gt(zero) & wi.z.gt(zero);
        let f = V3::select(above, rho * inv_pi, zero3) * wi.z.abs();
        // Diffuse::pdf: the cosine density where wo is above the surface.
        let bsdf_pdf = F32x16::select(
            wo.z.gt(zero),
            F32x16::select(wi.z.gt(zero), wi.z * inv_pi, zero),
            zero,
        );
        queue_light_sample(lanes, hits, &ls, f, bsdf_pdf, m & ls.ok, shadows);

        // BSDF sampling (`Diffuse::sample`): the next segment.
        // The walk's four numbers (`Walk::scatter`): component, direction, roulette.
        let _u_lobe = lanes.streams.next_1d(m);
        let (ux, uy) = lanes.streams.next_2d(m);
        let u_roulette = lanes.streams.next_1d(m);
        let mut wi = cosine_hemisphere(ux, uy);
        let pdf = F32x16::select(wi.z.gt(zero), wi.z * inv_pi, zero);
        wi.z = mirror(wi.z);
        let sampled = m & !wo.z.le(zero) & !pdf.le(zero);
        let sample = SampleLanes {
            wi,
            weight: rho,
            pdf,
            delta: Mask16::NONE,
            eta: F32x16::splat(1.0),
        };
        (m & !sampled) | self.leave_lanes(lanes, hits, &frame, sampled, &sample, u_roulette)
    }
}
