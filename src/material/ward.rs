//! Anisotropic Ward (mltbench extension `ward`; Ward 1992, "Measuring and Modeling
//! Anisotropic Reflection"):
//!
//!   f = ρ_d/π + ρ_s exp(−tan²θh (cos²φh/α_u² + sin²φh/α_v²)) / (4π α_u α_v √(cos θo cos θi)),
//!
//! sampled with Ward's half-vector warp and the correct density of Walter 2005 ("Notes on
//! the Ward BRDF", eq. 9): p(h) = exp(…)/(π α_u α_v cos³θh), p(wi) = p(h)/(4 wo·h).
//! The glossy lobe is chosen with probability s̄/(s̄ + d̄). One-sided. (Ward's lobe is not
//! exactly energy conserving at grazing angles for large α; see the tests.)

use glam::{Vec2, Vec3};

use crate::material::glossy_mix::{
    diffuse_plus_glossy, half_vector_pdf_to_wi, mixture_pdf, reflect_about_half_vector,
    sample_mixture,
};
use crate::material::plastic::lobe_weight;
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode};
use crate::math::{PI, Rgb};

#[derive(Clone, Debug, PartialEq)]
pub struct Ward {
    pub alpha_u: f32,
    pub alpha_v: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    specular_weight: f32,
}

impl Ward {
    pub fn new(alpha_u: f32, alpha_v: f32, diffuse: Rgb, specular: Rgb) -> Self {
        let clamp = |a: f32| if a.is_finite() { a.max(1e-4) } else { 1.0 };
        Ward {
            alpha_u: clamp(alpha_u),
            alpha_v: clamp(alpha_v),
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            specular_weight: lobe_weight(specular, diffuse),
        }
    }

    /// exp(−tan²θh (cos²φh/α_u² + sin²φh/α_v²)) for a half vector h above the surface.
    fn exponential(&self, h: Vec3) -> f32 {
        let e = ((h.x / self.alpha_u).powi(2) + (h.y / self.alpha_v).powi(2)) / (h.z * h.z);
        (-e).exp()
    }

    /// Walter 2005's density of the sampled half vector (solid angle of h).
    fn half_vector_pdf(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let p = self.exponential(h) / (PI * self.alpha_u * self.alpha_v * h.z * h.z * h.z);
        if p.is_finite() { p } else { 0.0 }
    }

    /// Ward's warp: φh with tan φh = (α_v/α_u) tan 2πu₂ (quadrant kept), and
    /// tan²θh = −ln u₁ / (cos²φh/α_u² + sin²φh/α_v²).
    fn sample_half_vector(&self, u: Vec2) -> Vec3 {
        let psi = 2.0 * PI * u.y;
        let phi = (self.alpha_v * psi.sin()).atan2(self.alpha_u * psi.cos());
        let (s, c) = phi.sin_cos();
        let denom = (c / self.alpha_u).powi(2) + (s / self.alpha_v).powi(2);
        // 1 − u.x ∈ (0, 1]: the logarithm is finite.
        let tan2 = -(1.0 - u.x).ln() / denom;
        let cos_theta = 1.0 / (1.0 + tan2).sqrt();
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Vec3::new(sin_theta * c, sin_theta * s, cos_theta)
    }
}

impl BsdfModel for Ward {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let h = (wo + wi).normalize_or_zero();
        let spec = if h.z > 0.0 {
            self.exponential(h) / (4.0 * PI * self.alpha_u * self.alpha_v * (wo.z * wi.z).sqrt())
        } else {
            0.0
        };
        diffuse_plus_glossy(self.diffuse_reflectance, self.specular_reflectance, spec)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let lobe = half_vector_pdf_to_wi(wo, wi, |h| self.half_vector_pdf(h));
        mixture_pdf(self.specular_weight, lobe, wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        sample_mixture(self, wo, u_lobe, u, mode, self.specular_weight, |u| {
            reflect_about_half_vector(wo, self.sample_half_vector(u))
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}
