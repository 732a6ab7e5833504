//! Smooth conductor (Mitsuba `conductor`): a perfect mirror weighted by the conductor
//! Fresnel term with complex IOR η + iκ per channel, times `specular_reflectance`. With no
//! IOR (`material="none"`) it is an ideal mirror: reflectance exactly `specular_reflectance`.
//! One-sided.

use glam::{Vec2, Vec3};

use crate::material::fresnel::fresnel_conductor;
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode, reflect_z};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct Conductor {
    /// Complex relative IOR (η, κ) per channel; None: no Fresnel term.
    pub eta_k: Option<(Rgb, Rgb)>,
    pub specular_reflectance: Rgb,
}

impl Conductor {
    pub fn new(eta_k: Option<(Rgb, Rgb)>, specular_reflectance: Rgb) -> Self {
        Conductor {
            eta_k,
            specular_reflectance,
        }
    }

    /// Reflectance at incidence cosine `cos_theta` (Fresnel × specular_reflectance).
    pub fn reflectance(&self, cos_theta: f32) -> Rgb {
        match self.eta_k {
            Some((eta, k)) => self.specular_reflectance * fresnel_conductor(cos_theta, eta, k),
            None => self.specular_reflectance,
        }
    }
}

impl BsdfModel for Conductor {
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, _u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 || !wo.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: reflect_z(wo),
            weight: self.reflectance(wo.z),
            pdf: 1.0,
            delta: true,
            eta: 1.0,
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            delta: true,
            ..Default::default()
        }
    }
}
