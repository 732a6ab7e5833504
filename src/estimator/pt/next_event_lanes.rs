//! Next-event estimation in lanes, shared by every BSDF the wavefront scatters at
//! (`diffuse_lanes.rs`, `general_lanes.rs`): the light's choice and its sample per lane
//! (`NeeLanes`), the shadow ray and the MIS-weighted contribution it carries, queued
//! (`queue_light_sample`), and the power heuristic in lanes. Operation for operation the
//! scalar code's (`PathSample::light_contribution`, see `wavefront.rs`).

use glam::{Vec2, Vec3};

use super::hit_lanes::HitLanes;
use super::path_lanes::{PathLanes, lane, lane3, put3, with_lane};
use super::shadow_queue::ShadowQueue;
use crate::geometry::SHADOW_EPSILON;
use crate::geometry::offset::offset_origin;
use crate::geometry::packet::RayLanes;
use crate::light::Light;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::path::mis::power_heuristic;
use crate::scene::Scene;

/// What next-event estimation drew per lane: the light's choice and `Light::sample_li`.
pub(super) struct NeeLanes {
    /// Lanes with a sample (a light was chosen and returned a point).
    pub(super) ok: Mask16,
    pub(super) p: V3<F32x16>,
    pub(super) n: V3<F32x16>,
    pub(super) p_error: V3<F32x16>,
    pub(super) wi: V3<F32x16>,
    /// The point is at a finite distance (not a light at infinity).
    pub(super) finite: Mask16,
    pub(super) radiance: V3<F32x16>,
    pub(super) pdf_solid_angle: F32x16,
    /// Probability of having chosen the light.
    pub(super) pmf: F32x16,
    pub(super) delta: Mask16,
}

impl NeeLanes {
    /// Chooses a light and a point on it for every lane of `m` (as `sample_light` does):
    /// in lanes for the lights that can (`Light::sample_li_lanes`), one lane at a time for
    /// the others.
    pub(super) fn sample(
        scene: &Scene,
        p: &V3<F32x16>,
        u_light: F32x16,
        u: (F32x16, F32x16),
        m: Mask16,
    ) -> NeeLanes {
        let zero = F32x16::splat(0.0);
        let zero3 = V3::new(zero, zero, zero);
        let mut out = NeeLanes {
            ok: Mask16::NONE,
            p: zero3,
            n: zero3,
            p_error: zero3,
            wi: zero3,
            finite: Mask16::NONE,
            radiance: zero3,
            pdf_solid_angle: zero,
            pmf: zero,
            delta: Mask16::NONE,
        };
        let Some((index, pmf)) = scene.lights.choose_lanes(u_light, m) else {
            return out;
        };
        out.pmf = pmf;
        // One light at a time: the lanes that chose it.
        let chosen = index.to_array();
        let mut todo = m;
        while let Some(first) = todo.lanes().next() {
            let light = scene.lights.get(chosen[first] as usize);
            let same = todo & index.eq(U32x16::splat(chosen[first]));
            todo &= !same;
            match light.sample_li_lanes(*p, u.0, u.1, same) {
                Some(s) => {
                    out.ok |= s.ok;
                    if !s.at_infinity {
                        out.finite |= same;
                    }
                    if s.delta {
                        out.delta |= same;
                    }
                    out.p = V3::select(same, s.p, out.p);
                    out.n = V3::select(same, s.n, out.n);
                    out.p_error = V3::select(same, s.p_error, out.p_error);
                    out.wi = V3::select(same, s.wi, out.wi);
                    out.radiance = V3::select(same, s.radiance, out.radiance);
                    out.pdf_solid_angle =
                        F32x16::select(same, s.pdf_solid_angle, out.pdf_solid_angle);
                }
                None => out.sample_one_by_one(light, p, u, same),
            }
        }
        out
    }

    /// `Light::sample_li` lane by lane, for the lanes of `m`.
    fn sample_one_by_one(&mut self, light: &Light, p: &V3<F32x16>, u: (F32x16, F32x16), m: Mask16) {
        for i in m.lanes() {
            let Some(ls) = light.sample_li(lane3(p, i), Vec2::new(lane(u.0, i), lane(u.1, i)))
            else {
                continue;
            };
            self.ok.set(i, true);
            self.finite.set(i, ls.dist.is_finite());
            self.delta.set(i, ls.delta);
            put3(&mut self.p, i, ls.p);
            put3(&mut self.n, i, ls.n);
            put3(&mut self.p_error, i, ls.p_error);
            put3(&mut self.wi, i, ls.wi);
            let rad = ls.radiance;
            put3(&mut self.radiance, i, Vec3::new(rad.r(), rad.g(), rad.b()));
            self.pdf_solid_angle = with_lane(self.pdf_solid_angle, i, ls.pdf_solid_angle);
        }
    }
}

/// `power_heuristic(a, b)` per lane: the f32 formula in lanes, and the scalar function
/// for the rare lanes where it overflows.
#[inline(always)]
pub(super) fn power_heuristic_lanes(pdf_a: F32x16, pdf_b: F32x16, m: Mask16) -> F32x16 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    let sum = a + b;
    let w = a / sum;
    let fine = sum.is_finite() & w.is_finite();
    let mut w = w;
    for i in (m & !fine).lanes() {
        let wi = power_heuristic(lane(pdf_a, i), lane(pdf_b, i));
        w = F32x16::select(Mask16(1 << i), F32x16::splat(wi), w);
    }
    w
}

/// The end of `PathSample::light_contribution` in lanes, for every BSDF the lanes scatter
/// at: the shadow ray of light sample `ls` and the MIS-weighted f · Le / p it carries,
/// queued (`ShadowQueue`), for the lanes of `adds` (those where the scalar code adds a
/// contribution: a light sample at a vertex a connection may end at). `f` is the BSDF's
/// value times |cos θi| towards the sample, `bsdf_pdf` its density of sampling that
/// direction.
pub(super) fn queue_light_sample(
    lanes: &mut PathLanes,
    hits: &HitLanes,
    ls: &NeeLanes,
    f: V3<F32x16>,
    bsdf_pdf: F32x16,
    adds: Mask16,
    shadows: &mut ShadowQueue,
) {
    let zero = F32x16::splat(0.0);
    let zero3 = V3::new(zero, zero, zero);
    let black = f.x.eq(zero) & f.y.eq(zero) & f.z.eq(zero);
    let shoot = adds & !black;
    // The shadow ray: to the light's point, both ends offset off their surfaces, or
    // towards a light at infinity.
    let to_point = ls.finite;
    let o_to_point = offset_origin(hits.p, hits.p_error, hits.ng, ls.p - hits.p);
    let target = offset_origin(ls.p, ls.p_error, ls.n, o_to_point - ls.p);
    let o_away = offset_origin(hits.p, hits.p_error, hits.ng, ls.wi);
    let origin = V3::select(to_point, o_to_point, o_away);
    let dir = V3::select(to_point, target - o_to_point, ls.wi);
    let t_max = F32x16::select(
        to_point,
        F32x16::splat(1.0 - SHADOW_EPSILON),
        F32x16::splat(f32::INFINITY),
    );
    lanes.rays = lanes.rays + U32x16::select(shoot, U32x16::splat(1), U32x16::splat(0));
    let pdf_light = ls.pmf * ls.pdf_solid_angle;
    let weight = F32x16::select(
        ls.delta,
        F32x16::splat(1.0),
        power_heuristic_lanes(pdf_light, bsdf_pdf, shoot & !ls.delta),
    );
    // What each lane adds: throughput × contribution if its shadow ray is unoccluded,
    // throughput × black otherwise (and without a shadow ray). The latter is +0, which
    // changes no sum, unless the throughput is not finite: those lanes queue it too,
    // with a shadow ray of no length (never occluded), so that it is added in order.
    let contribution = f.mul_v(ls.radiance) * (weight / pdf_light);
    let lit = lanes.throughput.mul_v(contribution);
    let dark = lanes.throughput.mul_v(zero3);
    let signed_zero = |v: F32x16| v.to_bits().eq(U32x16::splat(0));
    let no_op = signed_zero(dark.x) & signed_zero(dark.y) & signed_zero(dark.z);
    let odd = adds & !shoot & !no_op;
    let queued = shoot | odd;
    let shadow = RayLanes {
        o: origin,
        d: dir,
        t_max: F32x16::select(shoot, t_max, zero),
    };
    shadows.push(
        queued,
        &shadow,
        &V3::select(shoot, lit, dark),
        &dark,
        U32x16::from_array(lanes.sample),
    );
}
