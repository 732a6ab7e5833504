//! Comparing a generated camera ray with one recorded from Mitsuba 3.9.1.

use glam::Vec3;
use mltbench::geometry::Ray;

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
