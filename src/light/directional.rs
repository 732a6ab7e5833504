//! Directional lights (Mitsuba 3's `directional`): irradiance E arriving along one
//! direction from infinitely far away.

use glam::{Vec2, Vec3};

use crate::light::{EmissionSample, LightSample, SceneSphere};
use crate::math::{PI, Rgb};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction light travels in.
    pub direction: Vec3,
    /// Irradiance on a surface facing the light (W/m²).
    pub irradiance: Rgb,
    pub sphere: SceneSphere,
}

impl DirectionalLight {
    pub fn new(direction: Vec3, irradiance: Rgb, sphere: SceneSphere) -> Option<Self> {
        let direction = direction.normalize();
        direction.is_finite().then_some(DirectionalLight {
            direction,
            irradiance,
            sphere,
        })
    }

    /// Φ = π R² Ē: the flux crossing the scene's bounding sphere (exact for that sphere).
    pub fn power(&self) -> f32 {
        PI * self.sphere.radius * self.sphere.radius * self.irradiance.mean()
    }

    /// The only direction, −direction, carrying E (a delta sample, pdf 1).
    pub fn sample_li(&self) -> Option<LightSample> {
        let wi = -self.direction;
        Some(LightSample {
            p: wi,
            n: self.direction,
            front: self.direction,
            p_error: Vec3::ZERO,
            primitive: 0,
            wi,
            dist: f32::INFINITY,
            radiance: self.irradiance,
            pdf_solid_angle: 1.0,
            pdf_area: 1.0,
            delta: true,
        })
    }

    /// A ray along the light's direction through a uniform point of the disk of radius R
    /// perpendicular to it, placed R before the scene's centre (outside the scene).
    pub fn sample_le(&self, u1: Vec2) -> Option<EmissionSample> {
        let (origin, pdf_pos) = self.sphere.sample_disk(self.direction, u1);
        Some(EmissionSample {
            origin,
            direction: self.direction,
            n: self.direction,
            front: self.direction,
            p_error: Vec3::ZERO,
            primitive: 0,
            radiance: self.irradiance,
            pdf_pos,
            pdf_dir: 1.0,
            delta_pos: false,
            delta_dir: true,
        })
    }

    pub fn pdf_le(&self) -> (f32, f32) {
        (self.sphere.disk_pdf(), 1.0)
    }
}
