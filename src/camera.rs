//! Mitsuba 3's `perspective` sensor: a pinhole camera looking down +z in camera space,
//! +y up, pixel (0, 0) at the top left of the image.

use glam::{Vec2, Vec3};

use crate::geometry::Ray;
use crate::scene::SensorDesc;

pub struct Camera {}

impl Camera {
    pub fn new(sensor: &SensorDesc) -> Camera {
        let _ = sensor;
        todo!("camera")
    }

    /// The primary ray through raster position `raster` (continuous pixel coordinates:
    /// x in [0, width), y in [0, height), (0, 0) = top-left corner of the top-left pixel).
    /// Its direction is unit length and it starts at the near clip plane.
    pub fn generate_ray(&self, raster: Vec2) -> Ray {
        let _ = raster;
        todo!("camera")
    }

    /// The raster position a world point projects to, or None when it is behind the
    /// camera, outside the image or outside the clip range.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let _ = p;
        todo!("camera")
    }
}
