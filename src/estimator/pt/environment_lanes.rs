//! `PathSample::arrive` in lanes for paths whose ray escaped the scene: the emission of
//! each light at infinity (`constant`, `envmap`) from the ray's direction, weighted as
//! `emission_weight` weights it, in the scalar code's order (see `wavefront.rs`).

use glam::Vec3;

use super::PathSample;
use super::next_event_lanes::power_heuristic_lanes;
use super::path_lanes::{PathLanes, lane3, put3, with_lane};
use super::shadow_queue::ShadowQueue;
use crate::geometry::packet::RayLanes;
use crate::light::{Light, LightPoint};
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::scene::Scene;

impl PathSample {
    /// Adds, for the lanes of `m` (rays that escaped, the environment shown), what `arrive`
    /// adds there: for each light at infinity in turn, throughput × Le × w, queued in order
    /// with the shadow rays (`ShadowQueue`, a term without a ray). A `constant` light's
    /// radiance and density are the same in every lane; an `envmap` is looked up in lanes.
    pub(super) fn environment_in_lanes(
        &self,
        scene: &Scene,
        lanes: &PathLanes,
        m: Mask16,
        shadows: &mut ShadowQueue,
    ) {
        if m.none() {
            return;
        }
        let zero = F32x16::splat(0.0);
        let towards_light = lanes.direction.normalize();
        let weighted = m & !lanes.prev_specular;
        let no_ray = RayLanes {
            o: lanes.origin,
            d: lanes.direction,
            t_max: zero,
        };
        for &index in scene.lights.environment() {
            let light = scene.lights.get(index);
            let (le, pdf_li) = match light {
                Light::Constant(c) => {
                    // Neither depends on the direction (nor on where the ray started).
                    let pdf = light.pdf_li(Vec3::ZERO, &LightPoint::direction(Vec3::Z));
                    let r = c.radiance;
                    let le = V3::new(
                        F32x16::splat(r.r()),
                        F32x16::splat(r.g()),
                        F32x16::splat(r.b()),
                    );
                    (le, F32x16::splat(pdf))
                }
                Light::Envmap(e) => e.le_and_pdf_lanes(towards_light, m, weighted),
                _ => {
                    let (mut le, mut pdf) = (V3::new(zero, zero, zero), zero);
                    for i in m.lanes() {
                        let d = lane3(&towards_light, i);
                        let point = LightPoint::direction(d);
                        let r = light.le(&point, -d);
                        put3(&mut le, i, Vec3::new(r.r(), r.g(), r.b()));
                        if weighted.get(i) {
                            pdf = with_lane(pdf, i, light.pdf_li(lane3(&lanes.prev_p, i), &point));
                        }
                    }
                    (le, pdf)
                }
            };
            // `emission_weight`: 1 after a camera ray or a delta component, else the power
            // heuristic against choosing this light and sampling the direction.
            let pdf_light = F32x16::splat(scene.lights.pmf(index)) * pdf_li;
            let weight = F32x16::select(
                lanes.prev_specular,
                F32x16::splat(1.0),
                power_heuristic_lanes(lanes.prev_pdf, pdf_light, weighted),
            );
            let term = lanes.throughput.mul_v(le) * weight;
            shadows.push(m, &no_ray, &term, &term, U32x16::from_array(lanes.sample));
        }
    }
}
