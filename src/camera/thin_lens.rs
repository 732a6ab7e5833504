//! The lens of Mitsuba 3's `thinlens` sensor: an ideal thin lens of radius r in the plane
//! z = 0 of camera space, focused on the plane z = F (`focus_distance`).
//!
//! A ray for a normalised image position and a lens sample u ∈ [0, 1)² (Mitsuba 3's
//! `thinlens` documentation and sensor interface, "aperture sample"):
//!
//! ```text
//! a = r · concentric(u)           the lens point, (a.x, a.y, 0)   (Shirley & Chiu 1997)
//! f = F · (x, y, 1)               the point in focus, with (x, y, 1) the pinhole's
//!                                 direction for that image position on the plane z = 1
//! ray: from a towards f           direction (f − a) / |f − a|
//! ```
//!
//! So every ray of one image position meets the others on the focus plane, and the ray
//! through the lens centre is the pinhole's. The ray then starts on the near clip plane and
//! ends on the far one (both z = const in camera space), as the pinhole's does. Its weight is
//! 1: with the image position uniform over a pixel and u uniform over the square, the
//! estimate of a pixel is the mean radiance over the pixel and the aperture.
//!
//! Light tracing through the lens inverts this: a camera-space point q seen from a lens
//! point a is in focus at the point where the line a → q crosses z = F, and lands where the
//! pinhole would put that focus-plane point.

use glam::{Vec2, Vec3};

use crate::math::warp::square_to_disk_concentric;
use crate::scene::ThinLensDesc;

/// A thin lens: aperture radius and focus distance, in scene units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    radius: f32,
    focus_distance: f32,
}

impl ThinLens {
    /// The lens of `desc`; the loader has checked radius ≥ 0 and focus_distance > 0.
    pub fn new(desc: &ThinLensDesc) -> ThinLens {
        ThinLens {
            radius: desc.aperture_radius,
            focus_distance: desc.focus_distance,
        }
    }

    /// The aperture radius r.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The distance F of the plane in focus (camera space z = F).
    pub fn focus_distance(&self) -> f32 {
        self.focus_distance
    }

    /// The camera-space lens point of lens sample `u`: r times Shirley & Chiu's concentric
    /// map of `u` onto the unit disk, on the plane z = 0. Uniform over the aperture when `u`
    /// is uniform over the square.
    pub fn point(&self, u: Vec2) -> Vec3 {
        (self.radius * square_to_disk_concentric(u)).extend(0.0)
    }

    /// The unit camera-space direction from lens point `a` towards the point in focus for
    /// the pinhole direction `on_plane` (a point of the plane z = 1).
    pub fn direction(&self, a: Vec3, on_plane: Vec3) -> Vec3 {
        (on_plane * self.focus_distance - a).normalize()
    }

    /// The point of the plane z = 1 whose image position a camera-space point `q` (q.z > 0)
    /// lands at when seen from lens point `a`: the line a → q crosses the focus plane at
    /// a + (q − a) · F / q.z, which the pinhole projects to that point over F.
    pub fn on_plane(&self, a: Vec3, q: Vec3) -> Vec3 {
        let focus = a + (q - a) * (self.focus_distance / q.z);
        focus / self.focus_distance
    }
}
