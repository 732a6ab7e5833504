//! Thin dielectric slab (Mitsuba `thindielectric`), e.g. a window pane modelled as one
//! surface: light either reflects specularly or passes straight through without being
//! displaced or bent. Inter-reflections inside the slab are summed in closed form:
//! R' = R + T²R/(1 − R²) = 2R/(1 + R), T' = 1 − R' (with T = 1 − R, the Fresnel reflectance
//! R at the outer interface; the inner one has the same R by reciprocity).

use glam::{Vec2, Vec3};

use crate::material::fresnel::fresnel_dielectric;
use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode, reflect_z};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct ThinDielectric {
    pub eta: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl ThinDielectric {
    pub fn new(eta: f32, specular_reflectance: Rgb, specular_transmittance: Rgb) -> Self {
        let eta = if eta.is_finite() && eta > 0.0 {
            eta
        } else {
            1.0
        };
        ThinDielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
        }
    }

    /// Total reflectance R' of the slab at incidence cosine `cos_theta` (either side).
    pub fn slab_reflectance(&self, cos_theta: f32) -> f32 {
        let r = fresnel_dielectric(cos_theta.abs(), self.eta).f;
        2.0 * r / (1.0 + r)
    }
}

impl BsdfModel for ThinDielectric {
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let r = self.slab_reflectance(wo.z);
        if u_lobe < r {
            Some(BsdfSample {
                wi: reflect_z(wo),
                weight: self.specular_reflectance,
                pdf: r,
                delta: true,
                eta: 1.0,
            })
        } else {
            // Straight through: same medium on both sides, no radiance scaling.
            Some(BsdfSample {
                wi: -wo,
                weight: self.specular_transmittance,
                pdf: 1.0 - r,
                delta: true,
                eta: 1.0,
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
