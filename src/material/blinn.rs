//! Blinn–Phong (mltbench extension `blinn`; Blinn 1977, normalised as in Akenine-Möller et
//! al., "Real-Time Rendering"):
//!
//!   f = ρ_d/π + ρ_s (n + 2)/(8π) cosⁿθh,   h = (wo + wi)/|wo + wi|.
//!
//! One-sided. Sampling picks the glossy lobe with probability s̄/(s̄ + d̄), drawing the half
//! vector ∝ cosⁿθh (pdf (n + 1)/(2π) cosⁿθh) and reflecting wo about it (Jacobian
//! 1/(4 wo·h)); the diffuse lobe is cosine weighted.

use glam::{Vec2, Vec3};

use crate::material::plastic::lobe_weight;
use crate::material::{
    BsdfFlags, BsdfModel, BsdfSample, TransportMode, reflect_about, reflection_sample, valid_weight,
};
use crate::math::warp::{
    cosine_hemisphere_pdf, cosine_power_pdf, square_to_cosine_hemisphere, square_to_cosine_power,
};
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
        let value = self.diffuse_reflectance * INV_PI + self.specular_reflectance * spec;
        if valid_weight(value) {
            value
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_weight;
        let mut p = (1.0 - ps) * cosine_hemisphere_pdf(wi);
        let h = (wo + wi).normalize_or_zero();
        let wo_h = wo.dot(h);
        if h.z > 0.0 && wo_h > 0.0 {
            let spec = cosine_power_pdf(h, self.exponent) / (4.0 * wo_h);
            if spec.is_finite() {
                p += ps * spec;
            }
        }
        p
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 || !wo.is_finite() {
            return None;
        }
        let wi = if u_lobe < self.specular_weight {
            let h = square_to_cosine_power(u, self.exponent);
            // Half vectors facing away from wo would reflect it into a direction whose own
            // half vector is −h: not a direction this lobe produces.
            if wo.dot(h) <= 0.0 {
                return None;
            }
            reflect_about(wo, h).normalize_or_zero()
        } else {
            square_to_cosine_hemisphere(u)
        };
        reflection_sample(self, wo, wi, mode)
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            non_delta: true,
            ..Default::default()
        }
    }
}
