//! Camera test helpers: Mitsuba's look-at frame, and comparing a generated camera ray with
//! one recorded from Mitsuba 3.9.1.

use glam::{Mat4, Vec3};
use mltbench::geometry::Ray;
use mltbench::math::Transform;
use mltbench::scene::FovAxis;

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

/// A sensor that rays were recorded from in Mitsuba 3.9.1: (fov, fov_axis, W, H, lookat
/// origin, target, up).
pub type RecordedSensor = (f32, FovAxis, u32, u32, [f32; 3], [f32; 3], [f32; 3]);

/// The recorded sensors: the pinhole rays use all five, the thin-lens rays the first three
/// with an aperture and focus distance added.
#[rustfmt::skip]
pub const RECORDED_SENSORS: [RecordedSensor; 5] = [
    (90.0, FovAxis::X, 200, 100, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
    (45.0, FovAxis::Y, 64, 48, [0.0, 1.0, -4.0], [0.0, 0.5, 0.0], [0.0, 1.0, 0.0]),
    (60.0, FovAxis::Diagonal, 37, 91, [3.0, -2.0, 5.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
    (30.0, FovAxis::Smaller, 200, 100, [1.0, 2.0, 3.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    (70.0, FovAxis::Larger, 100, 200, [1.0, 2.0, 3.0], [-1.0, 0.0, 0.0], [0.3, 1.0, 0.0]),
];

/// Solid angle of the spherical triangle (a, b, c) (Van Oosterom & Strackee 1983).
pub fn triangle_solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let (a, b, c) = (
        a.normalize().as_dvec3(),
        b.normalize().as_dvec3(),
        c.normalize().as_dvec3(),
    );
    let num = a.dot(b.cross(c)).abs();
    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * num.atan2(den)
}
