//! Rough dielectric interface (Mitsuba `roughdielectric`): microfacet reflection and
//! refraction of Walter et al. 2007 (eqs. 20 and 21), both sides of the surface. `eta` =
//! int_ior/ext_ior with the normal pointing to the exterior.
//!
//! Sampling draws a microfacet normal m from the side `wo` is on (visible normals by
//! default), then reflects with probability F(wo·m) or refracts otherwise. Without
//! visible-normal sampling α is widened by 1.2 − 0.2 √|cos θo| for sampling only (Walter et
//! al. 2007, §5.3), as Mitsuba does.
//!
//! Transmission in radiance mode includes (η_wo/η_wi)² (Veach 1997, §5.2), in importance
//! mode not: the radiance-mode value obeys f(wo, wi)/η_wo² = f(wi, wo)/η_wi².

use glam::{Vec2, Vec3};

use crate::material::fresnel::{fresnel_dielectric, refract_about};
use crate::material::{
    BsdfFlags, BsdfModel, BsdfSample, Microfacet, TransportMode, reflect_about, valid_weight,
};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct RoughDielectric {
    pub eta: f32,
    pub distribution: Microfacet,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

/// The generalised half vector of (wo, wi) oriented to +z, for either reflection or
/// refraction (Walter et al. 2007, eqs. 13 and 16), or None when degenerate.
/// `eta` is the IOR on wi's side over the IOR on wo's side.
#[inline]
fn half_vector(wo: Vec3, wi: Vec3, reflect: bool, eta: f32) -> Option<Vec3> {
    let h = if reflect { wo + wi } else { wo + wi * eta };
    let h = h.normalize_or_zero();
    if h == Vec3::ZERO || h.z == 0.0 {
        return None;
    }
    Some(if h.z < 0.0 { -h } else { h })
}

impl RoughDielectric {
    pub fn new(
        eta: f32,
        distribution: Microfacet,
        specular_reflectance: Rgb,
        specular_transmittance: Rgb,
    ) -> Self {
        let eta = if eta.is_finite() && eta > 0.0 {
            eta
        } else {
            1.0
        };
        RoughDielectric {
            eta,
            distribution,
            specular_reflectance,
            specular_transmittance,
        }
    }

    /// The distribution used to sample normals for a `wo` with cosine `cos_o`.
    fn sampling_distribution(&self, cos_o: f32) -> Microfacet {
        if self.distribution.sample_visible {
            self.distribution
        } else {
            self.distribution.scaled(1.2 - 0.2 * cos_o.abs().sqrt())
        }
    }

    /// IOR on the far side over IOR on `wo`'s side.
    fn relative_eta(&self, cos_o: f32) -> f32 {
        if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }
}

impl BsdfModel for RoughDielectric {
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return Rgb::BLACK;
        }
        let reflect = co * ci > 0.0;
        let eta = self.relative_eta(co);
        let Some(m) = half_vector(wo, wi, reflect, eta) else {
            return Rgb::BLACK;
        };
        let dist = &self.distribution;
        let d = dist.d(m);
        if d == 0.0 {
            return Rgb::BLACK;
        }
        let g = dist.g(wo, wi, m);
        if g == 0.0 {
            return Rgb::BLACK;
        }
        let wo_m = wo.dot(m);
        let wi_m = wi.dot(m);
        let f = fresnel_dielectric(wo_m, self.eta).f;
        let value = if reflect {
            // Walter et al. 2007, eq. 20.
            self.specular_reflectance * (f * d * g / (4.0 * co.abs() * ci.abs()))
        } else {
            // Walter et al. 2007, eq. 21, with η = η_wi/η_wo; the radiance scale (1/η)²
            // turns η² into 1 in radiance mode.
            let denom = wo_m + eta * wi_m;
            let scale = match mode {
                TransportMode::Radiance => 1.0 / (eta * eta),
                TransportMode::Importance => 1.0,
            };
            let v = scale * (1.0 - f) * d * g * eta * eta * wo_m * wi_m / (co * ci * denom * denom);
            self.specular_transmittance * v.abs()
        };
        if valid_weight(value) {
            value
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 || !wo.is_finite() || !wi.is_finite() {
            return 0.0;
        }
        let reflect = co * ci > 0.0;
        let eta = self.relative_eta(co);
        let Some(m) = half_vector(wo, wi, reflect, eta) else {
            return 0.0;
        };
        let wo_m = wo.dot(m);
        let wi_m = wi.dot(m);
        // The sampler never produces a microfacet seen from its back.
        if wo_m * co <= 0.0 || wi_m * ci <= 0.0 {
            return 0.0;
        }
        let wo_up = if co > 0.0 { wo } else { -wo };
        let dist = self.sampling_distribution(co);
        let f = fresnel_dielectric(wo_m, self.eta).f;
        let p = if reflect {
            f * dist.reflection_pdf(wo_up, m, wi_m.abs())
        } else {
            // Jacobian of the refraction half-vector map (Walter et al. 2007, eq. 17).
            let denom = wo_m + eta * wi_m;
            (1.0 - f) * dist.pdf(wo_up, m) * eta * eta * wi_m.abs() / (denom * denom)
        };
        if p.is_finite() && p > 0.0 { p } else { 0.0 }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        let co = wo.z;
        if co == 0.0 || !wo.is_finite() {
            return None;
        }
        // Work with wo above the surface: the microfacet model is symmetric under z → −z.
        let wo_up = if co > 0.0 { wo } else { -wo };
        let sample_dist = self.sampling_distribution(co);
        let (m, pdf_m) = sample_dist.sample_normal(wo_up, u);
        if pdf_m <= 0.0 {
            return None;
        }
        let wo_m = wo.dot(m);
        let fr = fresnel_dielectric(wo_m, self.eta);
        let reflect = u_lobe < fr.f;
        let (wi, weight, pdf, eta_out) = if reflect {
            let wi = reflect_about(wo, m).normalize_or_zero();
            if wi.z * co <= 0.0 {
                return None;
            }
            let pdf = fr.f * sample_dist.reflection_pdf(wo_up, m, wi.dot(m).abs());
            (wi, self.specular_reflectance, pdf, 1.0)
        } else {
            let wi = refract_about(wo, m, fr.cos_theta_t, fr.eta_ti).normalize_or_zero();
            if wi.z * co >= 0.0 || wi == Vec3::ZERO {
                return None;
            }
            let wi_m = wi.dot(m);
            let scale = match mode {
                TransportMode::Radiance => fr.eta_ti * fr.eta_ti,
                TransportMode::Importance => 1.0,
            };
            let denom = wo_m + fr.eta_it * wi_m;
            let dh = fr.eta_it * fr.eta_it * wi_m.abs() / (denom * denom);
            (
                wi,
                self.specular_transmittance * scale,
                (1.0 - fr.f) * pdf_m * dh,
                fr.eta_it,
            )
        };
        let wi_m = wi.dot(m);
        if wi_m * wi.z <= 0.0 {
            return None;
        }
        let weight = if self.distribution.sample_visible {
            // f |cos θi| / pdf simplifies to G1(wi, m) times the lobe's colour (Heitz &
            // d'Eon 2014, eq. 8).
            weight * self.distribution.g1(wi, m)
        } else {
            // The sampling α differs from the model's, so nothing cancels (Walter et al.'s
            // eq. 41 assumes they are equal).
            self.eval(wo, wi, mode) * (wi.z.abs() / pdf)
        };
        if !(pdf.is_finite() && pdf > 0.0 && valid_weight(weight)) {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight,
            pdf,
            delta: false,
            eta: eta_out,
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            non_delta: true,
            transmission: true,
            ..Default::default()
        }
    }
}
