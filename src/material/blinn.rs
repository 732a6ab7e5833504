//! Blinn–Phong (mltbench extension `blinn`; Blinn 1977, normalised as in Akenine-Möller et
//! al., "Real-Time Rendering"):
//!
//!   f = ρ_d/π + ρ_s (n + 2)/(8π) cosⁿθh,   h = (wo + wi)/|wo + wi|.
//!
//! One-sided. Sampling picks the glossy lobe with probability s̄/(s̄ + d̄), drawing the half
//! vector ∝ cosⁿθh (pdf (n + 1)/(2π) cosⁿθh) and reflecting wo about it (Jacobian
//! 1/(4 wo·h)); the diffuse lobe is cosine weighted.

use glam::{Vec2, Vec3};

use crate::material::glossy_mix::{
    diffuse_plus_glossy, half_vector_pdf_to_wi, mixture_pdf, reflect_about_half_vector,
    sample_mixture,
};
use crate::material::plastic::lobe_weight;
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode};
use crate::math::warp::{cosine_power_pdf, square_to_cosine_power};
use crate::math::{INV_PI, Rgb};

#[derive(Clone, Debug, PartialEq)]
pub struct Blinn {
    pub exponent: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    specular_weight: f32,
}

impl Blinn {
    pub fn new(exponent: f32, diffuse: Rgb, specular: Rgb) -> Self {
        let exponent = if exponent.is_finite() {
            exponent.max(0.0)
        } else {
            1.0
        };
        Blinn {
            exponent,
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            specular_weight: lobe_weight(specular, diffuse),
        }
    }
}

impl BsdfModel for Blinn {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let h = (wo + wi).normalize_or_zero();
        let n = self.exponent;
        let spec = if h.z > 0.0 {
            (n + 2.0) * 0.125 * INV_PI * h.z.powf(n)
        } else {
            0.0
        };
        diffuse_plus_glossy(self.diffuse_reflectance, self.specular_reflectance, spec)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let lobe = half_vector_pdf_to_wi(wo, wi, |h| cosine_power_pdf(h, self.exponent));
        mixture_pdf(self.specular_weight, lobe, wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        sample_mixture(self, wo, u_lobe, u, mode, self.specular_weight, |u| {
            reflect_about_half_vector(wo, square_to_cosine_power(u, self.exponent))
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}
