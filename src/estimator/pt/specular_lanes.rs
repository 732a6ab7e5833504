//! `PathSample::scatter` in lanes for paths at a smooth specular surface: a mirror (an
//! untextured `conductor` without a complex IOR) or a smooth `dielectric`. No light can be
//! connected there, so next-event estimation only draws its three numbers; the walk then
//! samples the BSDF's delta component as `Conductor::sample` and `Dielectric::sample` do
//! (Fresnel by `fresnel_dielectric`, refraction by `refract_z`), operation for operation,
//! with the scalar code's early returns turned into lane masks (see `wavefront.rs`).

use super::PathSample;
use super::hit_lanes::HitLanes;
use super::lane_scene::{GLASS, MIRROR, SpecularTables};
use super::path_lanes::PathLanes;
use super::walk_lanes::SampleLanes;
use crate::math::frame::LaneFrame;
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};

/// `fresnel_dielectric(cos_theta_i, eta)` per lane: (F, cos θt, η_it, η_ti).
#[inline(always)]
fn fresnel_dielectric_lanes(cos_theta_i: F32x16, eta: F32x16) -> (F32x16, F32x16, F32x16, F32x16) {
    let zero = F32x16::splat(0.0);
    let one = F32x16::splat(1.0);
    let outside = cos_theta_i.ge(zero);
    let inv_eta = one / eta;
    let eta_it = F32x16::select(outside, eta, inv_eta);
    let eta_ti = F32x16::select(outside, inv_eta, eta);
    // `f32::min(1.0)`, for the finite cosines this is called with.
    let ci = cos_theta_i.abs().min_lt(one);
    // Snell: sin²θt = sin²θi (η_i/η_t)².
    let cos_t2 = one - (one - ci * ci) * eta_ti * eta_ti;
    let index_matched = eta.eq(one);
    // Total internal reflection, or exactly grazing incidence.
    let total = cos_t2.le(zero) | ci.eq(zero);
    let ct = cos_t2.sqrt();
    let r_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    let r_p = (eta_it * ci - ct) / (eta_it * ci + ct);
    let f = F32x16::splat(0.5) * (r_s * r_s + r_p * r_p);
    // `clamp(0.0, 1.0)`.
    let f = F32x16::select(f.lt(zero), zero, F32x16::select(f.gt(one), one, f));
    let cos_t = F32x16::select(outside, -ct, ct);
    let f = F32x16::select(index_matched, zero, F32x16::select(total, one, f));
    let cos_t = F32x16::select(
        index_matched,
        -cos_theta_i,
        F32x16::select(total, zero, cos_t),
    );
    (f, cos_t, eta_it, eta_ti)
}

impl PathSample {
    /// `scatter` for the lanes of `m` (live, at a `MIRROR` or `GLASS` shape). Returns the
    /// lanes whose path ends here.
    pub(super) fn scatter_specular(
        &self,
        tables: &SpecularTables,
        lanes: &mut PathLanes,
        hits: &HitLanes,
        m: Mask16,
    ) -> Mask16 {
        let zero = F32x16::splat(0.0);
        let one = F32x16::splat(1.0);
        let frame = LaneFrame::from_normal(hits.ns);
        let wo = frame.to_local(-lanes.direction.normalize());

        // Next-event estimation's three numbers (`sample_light`), unused: a delta BSDF
        // cannot be connected to a light.
        let _u_light = lanes.streams.next_1d(m);
        let _u = lanes.streams.next_2d(m);
        // The walk's four numbers (`Walk::scatter`): component, direction, roulette.
        let u_lobe = lanes.streams.next_1d(m);
        let _u_direction = lanes.streams.next_2d(m);
        let u_roulette = lanes.streams.next_1d(m);

        let kind = U32x16::gather(&tables.kind, hits.shape, m);
        let channels = |table: &[Vec<f32>; 3]| {
            let c = |k: usize| F32x16::gather(&table[k], hits.shape, m);
            V3::new(c(0), c(1), c(2))
        };
        let reflectance = channels(&tables.reflectance);
        let finite = wo.is_finite();
        let reflected = V3::new(-wo.x, -wo.y, wo.z);

        // `Conductor::sample`: the mirror direction above the surface.
        let mirror = m & kind.eq(U32x16::splat(MIRROR)) & wo.z.gt(zero) & finite;

        // `Dielectric::sample`: reflection with probability F, refraction otherwise.
        let glass = m & kind.eq(U32x16::splat(GLASS)) & wo.z.ne(zero) & finite;
        let (mut reflects, mut refracts) = (Mask16::NONE, Mask16::NONE);
        let (mut f, mut eta_it, mut eta_ti) = (zero, one, one);
        let mut refracted = reflected;
        if glass.any() {
            let eta = F32x16::gather(&tables.eta, hits.shape, glass);
            let cos_t;
            (f, cos_t, eta_it, eta_ti) = fresnel_dielectric_lanes(wo.z, eta);
            reflects = glass & u_lobe.lt(f);
            // `refract_z`, then `normalize_or_zero`.
            let raw = V3::new(-eta_ti * wo.x, -eta_ti * wo.y, cos_t);
            let rcp = one / raw.length();
            let normalizable = rcp.is_finite() & rcp.gt(zero);
            refracted = V3::select(normalizable, raw * rcp, V3::new(zero, zero, zero));
            let is_zero = refracted.x.eq(zero) & refracted.y.eq(zero) & refracted.z.eq(zero);
            // A refraction that stays on its side is dropped (`wi.z * wo.z >= 0`).
            refracts = glass & !reflects & !is_zero & !(refracted.z * wo.z).ge(zero);
        }
        let sampled = mirror | reflects | refracts;
        let weight = if refracts.any() {
            let transmittance = channels(&tables.transmittance);
            // Radiance transport: the η² refraction puts into radiance.
            V3::select(refracts, transmittance * (eta_ti * eta_ti), reflectance)
        } else {
            reflectance
        };
        let sample = SampleLanes {
            wi: V3::select(refracts, refracted, reflected),
            weight,
            pdf: F32x16::select(mirror, one, F32x16::select(reflects, f, one - f)),
            delta: sampled,
            eta: F32x16::select(refracts, eta_it, one),
        };
        (m & !sampled) | self.leave_lanes(lanes, hits, &frame, sampled, &sample, u_roulette)
    }
}
