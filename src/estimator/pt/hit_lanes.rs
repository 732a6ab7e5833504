//! The closest hits of the sixteen lanes' rays: the surface data the lane code reads, as
//! lanes, and each lane's whole `SurfaceInteraction` on demand for the scalar code.

use super::path_lanes::PathLanes;
use crate::geometry::SurfaceInteraction;
use crate::geometry::packet::{ClosestLanes, RayLanes, SurfaceLanes};
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::scene::Scene;

/// Kept by the wavefront from round to round and filled in place (`trace`): it holds a
/// few kilobytes, which a value returned each round would copy.
pub(super) struct HitLanes {
    /// Lanes whose ray hit a surface.
    pub hit: Mask16,
    pub p: V3<F32x16>,
    pub p_error: V3<F32x16>,
    pub ng: V3<F32x16>,
    pub ns: V3<F32x16>,
    pub shape: U32x16,
    rays: RayLanes,
    closest: ClosestLanes,
}

impl Default for HitLanes {
    fn default() -> Self {
        let zero = F32x16::splat(0.0);
        let zero3 = V3::new(zero, zero, zero);
        HitLanes {
            hit: Mask16::NONE,
            p: zero3,
            p_error: zero3,
            ng: zero3,
            ns: zero3,
            shape: U32x16::splat(0),
            rays: RayLanes {
                o: zero3,
                d: zero3,
                t_max: zero,
            },
            closest: ClosestLanes::default(),
        }
    }
}

impl HitLanes {
    /// Casts the ray of every live lane of `lanes`.
    pub fn trace(&mut self, scene: &Scene, lanes: &PathLanes) {
        self.rays = RayLanes {
            o: lanes.origin,
            d: lanes.direction,
            t_max: lanes.t_max,
        };
        scene
            .geometry
            .closest_hits_lanes(&self.rays, lanes.live, &mut self.closest);
        let SurfaceLanes {
            hit,
            p,
            p_error,
            ng,
            ns,
            shape,
            ..
        } = scene.geometry.surface_lanes(&self.closest, &self.rays);
        (self.hit, self.p, self.p_error, self.ng, self.ns, self.shape) =
            (hit, p, p_error, ng, ns, shape);
    }

    /// The (u, v) of lane `i`'s hit (as `interaction` would report it), if it hit.
    pub fn uv(&self, scene: &Scene, i: usize) -> Option<glam::Vec2> {
        self.closest
            .closest_hit(&scene.geometry, &self.rays, i)
            .map(|h| scene.geometry.uv(&h))
    }

    /// The surface lane `i`'s ray hit, if any, as `Geometry::intersect` returns it.
    pub fn interaction(&self, scene: &Scene, i: usize) -> Option<SurfaceInteraction> {
        self.closest
            .closest_hit(&scene.geometry, &self.rays, i)
            .map(|h| scene.geometry.interaction(&h))
    }
}
