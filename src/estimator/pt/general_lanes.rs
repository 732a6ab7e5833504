//! `PathSample::scatter` in lanes for every other BSDF (rough conductors and plastics,
//! dielectrics the specular lanes do not take, Phong, Ward, textured ones...): the lane
//! code draws the vertex's numbers, samples the light, casts the shadow ray in the queue and
//! plays Russian roulette, as at a diffuse surface; only the BSDF's own evaluations (f and
//! its density towards the light sample, and the sample of the next direction) run one lane
//! at a time, through the same `Bsdf` calls as the scalar code. The path's state stays in
//! its lanes: before, each such vertex moved the whole path out to the scalar code and back,
//! with its light sample and shadow ray cast alone.

use std::borrow::Cow;

use glam::{Vec2, Vec3};

use super::PathSample;
use super::hit_lanes::HitLanes;
use super::next_event_lanes::{NeeLanes, queue_light_sample};
use super::path_lanes::{PathLanes, lane, lane3, put3, with_lane};
use super::shadow_queue::ShadowQueue;
use super::walk_lanes::SampleLanes;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::math::frame::LaneFrame;
use crate::math::lanes::{F32x16, Mask16, V3};
use crate::scene::Scene;

/// An `Rgb` as the three channels of a lane vector.
fn channels(c: Rgb) -> Vec3 {
    Vec3::new(c.r(), c.g(), c.b())
}

impl PathSample {
    /// `scatter` for the lanes of `m` (live, at a surface whose BSDF is not `null`). Returns
    /// the lanes whose path ends here.
    pub(super) fn scatter_general(
        &self,
        scene: &Scene,
        lanes: &mut PathLanes,
        hits: &HitLanes,
        m: Mask16,
        shadows: &mut ShadowQueue,
    ) -> Mask16 {
        let zero = F32x16::splat(0.0);
        let zero3 = V3::new(zero, zero, zero);
        // `Vertex::surface`: the shading frame and wo in it.
        let frame = LaneFrame::from_normal(hits.ns);
        let wo = frame.to_local(-lanes.direction.normalize());

        // The vertex's numbers, in the scalar code's order: next-event estimation's three
        // (`sample_light`), then the walk's four (`Walk::scatter`).
        let u_light = lanes.streams.next_1d(m);
        let u = lanes.streams.next_2d(m);
        let ls = NeeLanes::sample(scene, &hits.p, u_light, u, m);
        let wi_light = frame.to_local(ls.wi);
        let u_lobe = lanes.streams.next_1d(m);
        let (ux, uy) = lanes.streams.next_2d(m);
        let u_roulette = lanes.streams.next_1d(m);

        // The BSDF's part, lane by lane (`light_contribution`'s f and density, then
        // `Walk::scatter`'s sample).
        let mut f = zero3;
        let mut bsdf_pdf = zero;
        // Lanes where the scalar code adds a light contribution: a light sample at a vertex a
        // connection may end at.
        let mut adds = Mask16::NONE;
        let mut sampled = Mask16::NONE;
        let mut sample = SampleLanes {
            wi: zero3,
            weight: zero3,
            pdf: zero,
            delta: Mask16::NONE,
            eta: F32x16::splat(1.0),
        };
        let shapes = hits.shape.to_array();
        for i in m.lanes() {
            let bsdf = match scene.untextured_bsdf(shapes[i] as usize) {
                Some(b) => Cow::Borrowed(b),
                None => scene.bsdf_at_uv(
                    shapes[i],
                    hits.uv(scene, i).expect("a lane that scatters has a hit"),
                ),
            };
            let wo_i = lane3(&wo, i);
            // `Vertex::is_connectible`: next-event estimation only where a connection may
            // end.
            if bsdf.has_non_delta() && ls.ok.get(i) {
                adds.set(i, true);
                let wi = lane3(&wi_light, i);
                let fi = bsdf.eval(wo_i, wi, TransportMode::Radiance) * wi.z.abs();
                put3(&mut f, i, channels(fi));
                // The density only weighs a contribution that is not black (and is pure).
                if !fi.is_black() && !ls.delta.get(i) {
                    bsdf_pdf = with_lane(bsdf_pdf, i, bsdf.pdf(wo_i, wi));
                }
            }
            let u = Vec2::new(lane(ux, i), lane(uy, i));
            if let Some(s) = bsdf.sample(wo_i, lane(u_lobe, i), u, TransportMode::Radiance) {
                sampled.set(i, true);
                put3(&mut sample.wi, i, s.wi);
                put3(&mut sample.weight, i, channels(s.weight));
                sample.pdf = with_lane(sample.pdf, i, s.pdf);
                sample.delta.set(i, s.delta);
                sample.eta = with_lane(sample.eta, i, s.eta);
            }
        }
        queue_light_sample(lanes, hits, &ls, f, bsdf_pdf, adds, shadows);
        (m & !sampled) | self.leave_lanes(lanes, hits, &frame, sampled, &sample, u_roulette)
    }
}
