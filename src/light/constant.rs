//! Constant environment lights (Mitsuba 3's `constant`): the same radiance L arriving from
//! every direction at infinity.

use glam::{Vec2, Vec3};

use crate::light::{EmissionSample, LightSample, SceneSphere};
use crate::math::{PI, Rgb, warp};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantLight {
    pub radiance: Rgb,
    pub sphere: SceneSphere,
}

impl ConstantLight {
    pub fn new(radiance: Rgb, sphere: SceneSphere) -> Self {
        ConstantLight { radiance, sphere }
    }

    /// Φ = π R² ∫ L dω = 4π² R² L̄: the flux entering the scene's bounding sphere.
    pub fn power(&self) -> f32 {
        4.0 * PI * PI * self.sphere.radius * self.sphere.radius * self.radiance.mean()
    }

    /// A uniform direction on the sphere (pdf 1/4π), as Mitsuba.
    pub fn sample_li(&self, u: Vec2) -> Option<LightSample> {
        let wi = warp::square_to_sphere(u);
        let pdf = warp::sphere_pdf();
        Some(LightSample::at_infinity(wi, self.radiance, pdf))
    }

    pub fn pdf_li(&self) -> f32 {
        warp::sphere_pdf()
    }

    /// A uniform direction of travel (pdf 1/4π) and a uniform point of the disk of radius R
    /// perpendicular to it, R before the scene's centre.
    pub fn sample_le(&self, u1: Vec2, u2: Vec2) -> Option<EmissionSample> {
        let direction = warp::square_to_sphere(u2);
        let (origin, pdf_pos) = self.sphere.sample_disk(direction, u1);
        Some(EmissionSample {
            origin,
            direction,
            n: direction,
            front: direction,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance: self.radiance,
            pdf_pos,
            pdf_dir: warp::sphere_pdf(),
            delta_pos: false,
            delta_dir: false,
        })
    }

    pub fn pdf_le(&self, _dir: Vec3) -> (f32, f32) {
        (self.sphere.disk_pdf(), warp::sphere_pdf())
    }
}
