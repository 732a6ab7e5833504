//! Isotropic point lights (Mitsuba 3's `point`): radiant intensity I in every direction.

use glam::{Vec2, Vec3};

use crate::light::{EmissionSample, LightSample, LightSampleLanes, towards_point};
use crate::math::lanes::{F32x16, Mask16, V3};
use crate::math::{PI, Rgb, warp};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    /// Radiant intensity I (W/sr).
    pub intensity: Rgb,
}

impl PointLight {
    pub fn new(position: Vec3, intensity: Rgb) -> Self {
        PointLight {
            position,
            intensity,
        }
    }

    /// Φ = 4π Ī (exact).
    pub fn power(&self) -> f32 {
        4.0 * PI * self.intensity.mean()
    }

    /// The only direction: towards the light, carrying I/d² (a delta sample, pdf 1).
    pub fn sample_li(&self, r: Vec3) -> Option<LightSample> {
        let (wi, dist, dist2) = towards_point(self.position, r)?;
        let radiance = self.intensity / dist2;
        Some(LightSample::from_point_light(
            self.position,
            wi,
            dist,
            radiance,
        ))
    }

    /// A uniform direction on the sphere (pdf 1/4π) from the light's position.
    /// `sample_li` for the lanes of `m` (reference points `r`), lane by lane the same bits.
    #[inline]
    pub fn sample_li_lanes(&self, r: V3<F32x16>, m: Mask16) -> LightSampleLanes {
        let c = F32x16::splat;
        let zero = V3::new(c(0.0), c(0.0), c(0.0));
        let position = V3::new(c(self.position.x), c(self.position.y), c(self.position.z));
        // `towards_point`.
        let d = position - r;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        let i = self.intensity;
        LightSampleLanes {
            ok: m & dist2.gt(c(0.0)) & dist2.is_finite(),
            p: position,
            n: zero,
            p_error: zero,
            wi: d.div_scalar(dist),
            radiance: V3::new(c(i.r()) / dist2, c(i.g()) / dist2, c(i.b()) / dist2),
            pdf_solid_angle: c(1.0),
            pdf_area: 1.0,
            delta: true,
            at_infinity: false,
        }
    }

    pub fn sample_le(&self, u2: Vec2) -> Option<EmissionSample> {
        Some(EmissionSample {
            origin: self.position,
            direction: warp::square_to_sphere(u2),
            n: Vec3::ZERO,
            front: Vec3::ZERO,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance: self.intensity,
            pdf_pos: 1.0,
            pdf_dir: warp::sphere_pdf(),
            delta_pos: true,
            delta_dir: false,
        })
    }

    pub fn pdf_le(&self) -> (f32, f32) {
        (1.0, warp::sphere_pdf())
    }
}
