//! The closest hits of the sixteen lanes' rays, with the surface data the lane code reads
//! (position and its error bound, normals, shape) as lanes, and each lane's whole
//! `SurfaceInteraction` for the scalar code.

use super::path_lanes::PathLanes;
use crate::geometry::SurfaceInteraction;
use crate::geometry::packet::RayLanes;
use crate::math::lanes::{F32x16, LANES, Mask16, U32x16, V3};
use crate::scene::Scene;

pub(super) struct HitLanes {
    /// Lanes whose ray hit a surface.
    pub hit: Mask16,
    pub p: V3<F32x16>,
    pub p_error: V3<F32x16>,
    pub ng: V3<F32x16>,
    pub ns: V3<F32x16>,
    pub shape: U32x16,
    interactions: [Option<SurfaceInteraction>; LANES],
}

/// Sixteen 3-vectors gathered lane by lane into a lane vector.
fn to_lanes(v: &[[f32; 3]; LANES]) -> V3<F32x16> {
    V3::new(
        F32x16::from_array(std::array::from_fn(|i| v[i][0])),
        F32x16::from_array(std::array::from_fn(|i| v[i][1])),
        F32x16::from_array(std::array::from_fn(|i| v[i][2])),
    )
}

impl HitLanes {
    /// Casts the ray of every live lane of `lanes`.
    pub fn trace(scene: &Scene, lanes: &PathLanes) -> HitLanes {
        let mut interactions = [None; LANES];
        let (mut p, mut p_error, mut ng, mut ns) = (
            [[0.0f32; 3]; LANES],
            [[0.0; 3]; LANES],
            [[0.0; 3]; LANES],
            [[0.0; 3]; LANES],
        );
        let mut shape = [0u32; LANES];
        let mut hit = Mask16::NONE;
        let rays = RayLanes {
            o: lanes.origin,
            d: lanes.direction,
            t_max: lanes.t_max,
        };
        let found = scene.geometry.closest_hits_lanes(&rays, lanes.live);
        for i in lanes.live.lanes() {
            if let Some(closest) = &found[i] {
                let si = scene.geometry.interaction(closest);
                hit.set(i, true);
                p[i] = si.p.to_array();
                p_error[i] = si.p_error.to_array();
                ng[i] = si.ng.to_array();
                ns[i] = si.ns.to_array();
                shape[i] = si.shape;
                interactions[i] = Some(si);
            }
        }
        HitLanes {
            hit,
            p: to_lanes(&p),
            p_error: to_lanes(&p_error),
            ng: to_lanes(&ng),
            ns: to_lanes(&ns),
            shape: U32x16::from_array(shape),
            interactions,
        }
    }

    /// The surface lane `i`'s ray hit, if any.
    pub fn interaction(&self, i: usize) -> Option<&SurfaceInteraction> {
        self.interactions[i].as_ref()
    }
}
