//! Smooth dielectric interface (Mitsuba `dielectric`): specular reflection and refraction,
//! chosen with probability F and 1 − F (Fresnel), total internal reflection included.
//! `eta` = int_ior/ext_ior; the normal points to the exterior.
//!
//! In radiance transport a refracted sample's weight carries (η_wo/η_wi)² (Veach 1997,
//! §5.2): radiance leaving glass into air is divided by η². Importance transport omits it.

use glam::{Vec2, Vec3};

use crate::material::fresnel::{fresnel_dielectric, refract_z};
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode, reflect_z};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct Dielectric {
    /// Relative IOR int/ext.
    pub eta: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl Dielectric {
    pub fn new(eta: f32, specular_reflectance: Rgb, specular_transmittance: Rgb) -> Self {
        let eta = if eta.is_finite() && eta > 0.0 {
            eta
        } else {
            1.0
        };
        Dielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
        }
    }
}

impl BsdfModel for Dielectric {
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let fr = fresnel_dielectric(wo.z, self.eta);
        if u_lobe < fr.f {
            // Reflection with probability F: weight F·R/F = R.
            Some(BsdfSample {
                wi: reflect_z(wo),
                weight: self.specular_reflectance,
                pdf: fr.f,
                delta: true,
                eta: 1.0,
            })
        } else {
            let wi = refract_z(wo, fr.cos_theta_t, fr.eta_ti).normalize_or_zero();
            if wi == Vec3::ZERO || wi.z * wo.z >= 0.0 {
                return None;
            }
            // η_ti = η_wo/η_wi: the radiance scale of Veach 1997, eq. 5.13.
            let scale = match mode {
                TransportMode::Radiance => fr.eta_ti * fr.eta_ti,
                TransportMode::Importance => 1.0,
            };
            Some(BsdfSample {
                wi,
                weight: self.specular_transmittance * scale,
                pdf: 1.0 - fr.f,
                delta: true,
                eta: fr.eta_it,
            })
        }
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            delta: true,
            transmission: true,
            ..Default::default()
        }
    }
}
