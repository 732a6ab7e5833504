//! Camera test helpers: Mitsuba's look-at frame, and comparing a generated camera ray with
//! one recorded from Mitsuba 3.9.1.

use glam::{Mat4, Vec3};
use mltbench::geometry::Ray;
use mltbench::math::Transform;

/// Mitsuba's `lookat`: columns (left, up, dir, origin) with left = up × dir.
pub fn lookat(origin: Vec3, target: Vec3, up: Vec3) -> Transform {
    let dir = (target - origin).normalize();
    let left = up.normalize().cross(dir).normalize();
    let new_up = dir.cross(left);
    Transform::new(Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
    .unwrap()
}

/// Asserts `ray` has Mitsuba's origin `o` and direction `d` (to 2e-6) and segment length
/// `maxt` (to 1e-5 relative); `what` names the case in the message.
pub fn assert_matches_recorded_ray(ray: &Ray, o: [f32; 3], d: [f32; 3], maxt: f32, what: &str) {
    assert!(
        (ray.d - Vec3::from(d)).length() < 2e-6,
        "{what}: d {} vs {d:?}",
        ray.d
    );
    assert!(
        (ray.o - Vec3::from(o)).length() < 2e-6,
        "{what}: o {} vs {o:?}",
        ray.o
    );
    assert!(
        (ray.t_max / maxt - 1.0).abs() < 1e-5,
        "{what}: t_max {} vs {maxt}",
        ray.t_max
    );
}
