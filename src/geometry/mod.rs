//! Ray casting: all triangles in one BVH (obvhs), analytic shapes beside it.

use glam::{Vec2, Vec3};

use crate::math::Frame;
use crate::scene::ShapeDesc;

/// A ray segment: points o + t·d for t in (0, t_max). Origins are already offset off
/// surfaces by `SurfaceInteraction::spawn_ray*`, so no epsilon is needed at t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    /// Direction; need not be unit length (t is in units of |d|).
    pub d: Vec3,
    pub t_max: f32,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// What a closest-hit query returns about the surface it hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// Hit position.
    pub p: Vec3,
    /// Conservative absolute error bound on each coordinate of `p`.
    pub p_error: Vec3,
    /// Ray parameter of the hit.
    pub t: f32,
    /// Geometric normal (unit), on the shape's front side (after `flip_normals`).
    pub ng: Vec3,
    /// Shading normal (unit): interpolated vertex normal, or `ng`. Same hemisphere as `ng`.
    pub ns: Vec3,
    /// Shading frame around `ns`.
    pub frame: Frame,
    pub uv: Vec2,
    /// Index of the shape in `SceneDescription::shapes`.
    pub shape: u32,
    /// Triangle index within the shape (0 for analytic shapes).
    pub primitive: u32,
}

impl SurfaceInteraction {
    /// A ray leaving the surface in direction `d`, origin offset to the side `d` points to.
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        let _ = d;
        todo!("geometry")
    }

    /// A ray from this surface towards point `target`, stopping just short of it.
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let _ = target;
        todo!("geometry")
    }
}

/// The acceleration structure over all shapes of a scene.
pub struct Geometry {}

impl Geometry {
    pub fn build(shapes: &[ShapeDesc]) -> Geometry {
        let _ = shapes;
        todo!("geometry")
    }

    /// Closest hit along the ray, if any, with t < ray.t_max.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let _ = ray;
        todo!("geometry")
    }

    /// True when anything lies on the ray with t < ray.t_max (any-hit shadow query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let _ = ray;
        todo!("geometry")
    }
}
