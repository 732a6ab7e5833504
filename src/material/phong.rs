//! Modified Phong (mltbench extension `phong`; Lafortune & Willems 1994, "Using the
//! Modified Phong Reflectance Model for Physically Based Rendering"):
//!
//!   f = ρ_d/π + ρ_s (n + 2)/(2π) cosⁿα,   α = angle between wi and the mirror direction of wo,
//!
//! energy-normalised so that ρ_d + ρ_s ≤ 1 keeps the albedo ≤ 1. One-sided. Sampling picks
//! the glossy lobe with probability s̄/(s̄ + d̄) (the lobes' albedos at normal incidence),
//! drawing wi ∝ cosⁿα about the mirror direction, and the diffuse lobe otherwise (cosine
//! weighted).

use glam::{Vec2, Vec3};

use crate::material::glossy_mix::{diffuse_plus_glossy, mixture_pdf, sample_mixture};
use crate::material::plastic::lobe_weight;
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode, reflect_z};
use crate::math::warp::{cosine_power_pdf, square_to_cosine_power};
use crate::math::{Frame, INV_PI, Rgb};

#[derive(Clone, Debug, PartialEq)]
pub struct Phong {
    pub exponent: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    specular_weight: f32,
}

impl Phong {
    pub fn new(exponent: f32, diffuse: Rgb, specular: Rgb) -> Self {
        let exponent = if exponent.is_finite() {
            exponent.max(0.0)
        } else {
            1.0
        };
        Phong {
            exponent,
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            specular_weight: lobe_weight(specular, diffuse),
        }
    }

    /// cos α between wi and the mirror direction of wo, clamped at 0.
    fn cos_alpha(wo: Vec3, wi: Vec3) -> f32 {
        reflect_z(wo).dot(wi).clamp(0.0, 1.0)
    }
}

impl BsdfModel for Phong {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let c = Self::cos_alpha(wo, wi);
        let n = self.exponent;
        let spec = if c > 0.0 {
            (n + 2.0) * 0.5 * INV_PI * c.powf(n)
        } else {
            0.0
        };
        diffuse_plus_glossy(self.diffuse_reflectance, self.specular_reflectance, spec)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let c = Self::cos_alpha(wo, wi);
        let lobe = cosine_power_pdf(Vec3::new(0.0, 0.0, c), self.exponent);
        mixture_pdf(self.specular_weight, lobe, wi)
    }

    /// cosⁿα once for f and both densities: α is symmetric in wo and wi.
    fn eval_with_pdfs(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> (Rgb, f32, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::BLACK, 0.0, 0.0);
        }
        let c = Self::cos_alpha(wo, wi);
        let n = self.exponent;
        let cos_n = if c > 0.0 { c.powf(n) } else { 0.0 };
        let spec = (n + 2.0) * 0.5 * INV_PI * cos_n;
        // `cosine_power_pdf` of (0, 0, c), whose cosine is 0 at c = 0.
        let lobe = if c > 0.0 {
            (n + 1.0) * 0.5 * INV_PI * cos_n
        } else {
            0.0
        };
        (
            diffuse_plus_glossy(self.diffuse_reflectance, self.specular_reflectance, spec),
            mixture_pdf(self.specular_weight, lobe, wi),
            mixture_pdf(self.specular_weight, lobe, wo),
        )
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        sample_mixture(self, wo, u_lobe, u, mode, self.specular_weight, |u| {
            let local = square_to_cosine_power(u, self.exponent);
            Some(
                Frame::from_normal(reflect_z(wo))
                    .to_world(local)
                    .normalize_or_zero(),
            )
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}
