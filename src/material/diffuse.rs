//! Lambertian reflection (Mitsuba `diffuse`): f = R/π on the front side, zero behind.

use glam::{Vec2, Vec3};

use crate::material::{BsdfFlags, BsdfModel, BsdfSample, TransportMode};
use crate::math::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use crate::math::{INV_PI, Rgb};

#[derive(Clone, Debug, PartialEq)]
pub struct Diffuse {
    pub reflectance: Rgb,
}

impl Diffuse {
    pub fn new(reflectance: Rgb) -> Self {
        Diffuse { reflectance }
    }
}

impl BsdfModel for Diffuse {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.reflectance * INV_PI
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 {
            cosine_hemisphere_pdf(wi)
        } else {
            0.0
        }
    }

    fn eval_with_pdfs(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> (Rgb, f32, f32) {
        if wo.z > 0.0 && wi.z > 0.0 {
            (
                self.reflectance * INV_PI,
                cosine_hemisphere_pdf(wi),
                cosine_hemisphere_pdf(wo),
            )
        } else {
            (Rgb::BLACK, self.pdf(wo, wi), self.pdf(wi, wo))
        }
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = square_to_cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi);
        if pdf <= 0.0 {
            return None;
        }
        // f cos θ / pdf = (R/π) cos θ / (cos θ/π) = R.
        Some(BsdfSample::non_delta(wi, self.reflectance, pdf))
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}
