//! The closest hits of the sixteen lanes' rays: the surface data the lane code reads, as
//! lanes, and each lane's whole `SurfaceInteraction` on demand for the scalar code.

use super::path_lanes::PathLanes;
use crate::geometry::SurfaceInteraction;
use crate::geometry::packet::{ClosestLanes, RayLanes, SurfaceLanes};
use crate::math::lanes::{F32x16, Mask16, U32x16, V3};
use crate::scene::Scene;

pub(super) struct HitLanes {
    /// Lanes whose ray hit a surface.
    pub hit: Mask16,
    pub p: V3<F32x16>,
    pub p_error: V3<F32x16>,
    pub ng: V3<F32x16>,
    pub ns: V3<F32x16>,
    pub shape: U32x16,
    closest: ClosestLanes,
}

impl HitLanes {
    /// Casts the ray of every live lane of `lanes`.
    pub fn trace(scene: &Scene, lanes: &PathLanes) -> HitLanes {
        let rays = RayLanes {
            o: lanes.origin,
            d: lanes.direction,
            t_max: lanes.t_max,
        };
        let closest = scene.geometry.closest_hits_lanes(&rays, lanes.live);
        let SurfaceLanes {
            hit,
            p,
            p_error,
            ng,
            ns,
            shape,
            ..
        } = scene.geometry.surface_lanes(&closest);
        HitLanes {
            hit,
            p,
            p_error,
            ng,
            ns,
            shape,
            closest,
        }
    }

    /// The surface lane `i`'s ray hit, if any, as `Geometry::intersect` returns it.
    pub fn interaction(&self, scene: &Scene, i: usize) -> Option<SurfaceInteraction> {
        self.closest
            .closest_hit(&scene.geometry, i)
            .map(|h| scene.geometry.interaction(&h))
    }
}
