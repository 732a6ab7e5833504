//! Warps from the unit square to other domains, each with its pdf.
//! (Filled in with the materials and lights: cosine hemisphere, sphere, cone, triangle, disk.)

use glam::{Vec2, Vec3};

/// Uniform point on a triangle as barycentrics (b1, b2) (Shirley & Chiu 1997 square-root map).
pub fn square_to_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// Uniform direction on the unit sphere; pdf 1/(4π).
pub fn square_to_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}
