//! The perspective camera against Mitsuba 3's model, computed by hand:
//! camera space looks down +z with +y up; a camera-space point (x, y, z) lands at
//! u = ½ − x / (2 z tan(fov_x/2)), v = ½ − aspect · y / (2 z tan(fov_x/2)), raster = (u W, v H).

mod camera_support;

use camera_support::{RECORDED_SENSORS, assert_matches_recorded_ray, lookat, triangle_solid_angle};

use glam::{Mat4, Vec2, Vec3};
use mltbench::camera::{Camera, horizontal_fov_degrees, raster_in_pixel};
use mltbench::math::Transform;
use mltbench::scene::{CropWindow, FilmDesc, FilterDesc, FovAxis, SensorDesc};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn sensor(to_world: Transform, fov: f32, axis: FovAxis, width: u32, height: u32) -> SensorDesc {
    SensorDesc {
        to_world,
        fov_degrees: fov,
        fov_axis: axis,
        near_clip: 0.01,
        far_clip: 1000.0,
        lens: None,
        film: FilmDesc {
            width,
            height,
            filter: FilterDesc::Box,
            crop: None,
        },
        sample_count: 1,
    }
}

fn assert_close(a: Vec2, b: Vec2, tol: f32, what: &str) {
    assert!((a - b).abs().max_element() <= tol, "{what}: {a} vs {b}");
}

#[test]
fn hand_computed_projection_has_no_mirroring_and_top_left_origin() {
    // lookat (0,0,0) → (0,0,1), up (0,1,0): dir = +z, left = up × dir = +x, so the camera
    // frame is the world frame. fov 90° along x on 200×100: tan(45°) = 1, aspect = 2.
    // World point (1, 0.25, 2):
    //   u = ½ − 1 / (2·2·1)       = 0.25  → x = 0.25 · 200 = 50   (left half: +x is left)
    //   v = ½ − 2 · 0.25 / (2·2·1) = 0.375 → y = 0.375 · 100 = 37.5 (upper half: +y is up)
    let cam = Camera::new(&sensor(
        lookat(Vec3::ZERO, Vec3::Z, Vec3::Y),
        90.0,
        FovAxis::X,
        200,
        100,
    ));
    assert_close(
        cam.project(Vec3::new(1.0, 0.25, 2.0)).unwrap(),
        Vec2::new(50.0, 37.5),
        1e-4,
        "p",
    );
    // (−1, −0.25, 2): the mirror point lands at (150, 62.5).
    assert_close(
        cam.project(Vec3::new(-1.0, -0.25, 2.0)).unwrap(),
        Vec2::new(150.0, 62.5),
        1e-4,
        "mirror",
    );
    // The ray through (50, 37.5) heads for (1, 0.25, 2).
    let ray = cam.generate_ray(Vec2::new(50.0, 37.5));
    let expected = Vec3::new(1.0, 0.25, 2.0).normalize();
    assert!(
        (ray.d - expected).length() < 1e-6,
        "{} vs {expected}",
        ray.d
    );
    // The image centre is the viewing axis, the corner (0, 0) the direction (1, 0.5, 1).
    let centre = cam.generate_ray(Vec2::new(100.0, 50.0));
    assert!((centre.d - Vec3::Z).length() < 1e-6);
    let corner = cam.generate_ray(Vec2::ZERO);
    assert!((corner.d - Vec3::new(1.0, 0.5, 1.0).normalize()).length() < 1e-6);

    // Looking down −z instead: dir = −z, left = (0,1,0) × (0,0,−1) = (−1,0,0): world +x is
    // now on the image's right. (1, 0.25, −2) → (200 − 50, 37.5).
    let back = Camera::new(&sensor(
        lookat(Vec3::ZERO, -Vec3::Z, Vec3::Y),
        90.0,
        FovAxis::X,
        200,
        100,
    ));
    assert_close(
        back.project(Vec3::new(1.0, 0.25, -2.0)).unwrap(),
        Vec2::new(150.0, 37.5),
        1e-4,
        "looking down -z",
    );
}

#[test]
fn fov_axis_variants_give_the_hand_computed_focal_scale() {
    // fov = 90°, so tan(fov/2) = 1 along the named axis. tan_x = half-width on z = 1.
    // 200×100 (aspect 2): x → 1; y → 1 · aspect = 2; diagonal: the half-diagonal is 1, so
    // tan_x² (1 + 1/4) = 1, tan_x = 2/√5; smaller = y (height is smaller) → 2; larger = x → 1.
    // 100×200 (aspect ½): x → 1; y → ½; diagonal: tan_x² (1 + 4) = 1, tan_x = 1/√5;
    // smaller = x → 1; larger = y → ½.
    let s5 = 5f32.sqrt();
    let cases = [
        (200, 100, FovAxis::X, 1.0),
        (200, 100, FovAxis::Y, 2.0),
        (200, 100, FovAxis::Diagonal, 2.0 / s5),
        (200, 100, FovAxis::Smaller, 2.0),
        (200, 100, FovAxis::Larger, 1.0),
        (100, 200, FovAxis::X, 1.0),
        (100, 200, FovAxis::Y, 0.5),
        (100, 200, FovAxis::Diagonal, 1.0 / s5),
        (100, 200, FovAxis::Smaller, 1.0),
        (100, 200, FovAxis::Larger, 0.5),
    ];
    for (w, h, axis, tan_x) in cases {
        let cam = Camera::new(&sensor(Transform::IDENTITY, 90.0, axis, w, h));
        assert!(
            (cam.tan_half_fov_x() - tan_x).abs() < 1e-5,
            "{w}x{h} {axis:?}"
        );
        let aspect = w as f32 / h as f32;
        // The point at the top-left corner of the image on z = 1 (+x is left, +y up).
        let corner = Vec3::new(tan_x, tan_x / aspect, 1.0);
        assert_close(
            cam.project(corner * 3.0).unwrap(),
            Vec2::ZERO,
            1e-3,
            "corner",
        );
        // Half-way to the right edge along the horizontal axis.
        let p = Vec3::new(-0.5 * tan_x, 0.0, 1.0);
        assert_close(
            cam.project(p).unwrap(),
            Vec2::new(0.75 * w as f32, 0.5 * h as f32),
            1e-3,
            "half-right",
        );
        let fov_x = horizontal_fov_degrees(90.0, axis, w as f64 / h as f64);
        assert!(((0.5 * fov_x).to_radians().tan() as f32 - tan_x).abs() < 1e-6);
    }
    // Diagonal: the corner direction is 45° off the axis.
    let cam = Camera::new(&sensor(
        Transform::IDENTITY,
        90.0,
        FovAxis::Diagonal,
        200,
        100,
    ));
    let d = cam.generate_ray(Vec2::ZERO).d;
    assert!((d.z - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
}

fn test_sensors() -> Vec<SensorDesc> {
    let rotated = Transform::new(
        Mat4::from_translation(Vec3::new(0.5, -2.0, 7.0))
            * Mat4::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 1.1),
    )
    .unwrap();
    let mut sensors = Vec::new();
    for (i, axis) in [
        FovAxis::X,
        FovAxis::Y,
        FovAxis::Diagonal,
        FovAxis::Smaller,
        FovAxis::Larger,
    ]
    .into_iter()
    .enumerate()
    {
        for (w, h) in [(64, 64), (200, 100), (37, 91)] {
            for to_world in [
                Transform::IDENTITY,
                lookat(Vec3::new(3.0, -2.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y),
                rotated,
            ] {
                let fov = 20.0 + 25.0 * i as f32;
                let mut s = sensor(to_world, fov, axis, w, h);
                s.near_clip = 0.05;
                s.far_clip = 500.0;
                sensors.push(s);
            }
        }
    }
    sensors
}

#[test]
fn project_inverts_generate_ray() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for s in test_sensors() {
        let cam = Camera::new(&s);
        let forward = s.to_world.vector(Vec3::Z).normalize();
        let origin = s.to_world.point(Vec3::ZERO);
        for _ in 0..200 {
            let raster = Vec2::new(
                rng.random::<f32>() * s.film.width as f32,
                rng.random::<f32>() * s.film.height as f32,
            );
            let ray = cam.generate_ray(raster);
            assert!((ray.d.length() - 1.0).abs() < 1e-5);
            // The ray starts on the near plane and ends on the far plane.
            assert!(((ray.o - origin).dot(forward) - s.near_clip).abs() < 1e-4);
            let end = ray.at(ray.t_max);
            assert!(((end - origin).dot(forward) - s.far_clip).abs() < 0.05);
            // The origin lies on the line from the pinhole along d.
            assert!((ray.o - origin).cross(ray.d).length() < 1e-5);
            let t = 0.1 + rng.random::<f32>() * 50.0;
            let back = cam
                .project(ray.at(t))
                .expect("a point on a camera ray is visible");
            assert_close(back, raster, 2e-3, "round trip");
        }
    }
}

#[test]
fn project_rejects_points_outside_the_view() {
    let s = sensor(
        lookat(Vec3::ZERO, Vec3::Z, Vec3::Y),
        90.0,
        FovAxis::X,
        200,
        100,
    );
    let cam = Camera::new(&s);
    assert!(cam.project(Vec3::new(0.0, 0.0, -1.0)).is_none(), "behind");
    assert!(
        cam.project(Vec3::new(0.0, 0.0, 0.005)).is_none(),
        "before the near plane"
    );
    assert!(
        cam.project(Vec3::new(0.0, 0.0, 2000.0)).is_none(),
        "beyond the far plane"
    );
    assert!(
        cam.project(Vec3::new(1.1, 0.0, 1.0)).is_none(),
        "left of the image"
    );
    assert!(
        cam.project(Vec3::new(0.0, 0.6, 1.0)).is_none(),
        "above the image"
    );
    assert!(cam.project(Vec3::new(0.0, 0.0, f32::NAN)).is_none(), "NaN");
    assert!(cam.project(Vec3::new(0.0, 0.0, 0.02)).is_some());
}

/// pdf_direction at each raster cell's centre times the cell's solid angle (from its corner
/// rays only, independently of the cos³ formula), against the cell's probability under
/// uniform raster sampling: (sum over the cells, worst relative error of one cell).
fn direction_pdf_over_cells(cam: &Camera) -> (f64, f64) {
    let cell = 0.5f32;
    let mut total = 0.0f64;
    let mut worst = 0.0f64;
    let (w, h) = (cam.width() as f32, cam.height() as f32);
    let mut y = 0.0;
    while y < h {
        let mut x = 0.0;
        while x < w {
            let d = |dx: f32, dy: f32| cam.generate_ray(Vec2::new(x + dx, y + dy)).d;
            let omega = triangle_solid_angle(d(0.0, 0.0), d(cell, 0.0), d(cell, cell))
                + triangle_solid_angle(d(0.0, 0.0), d(cell, cell), d(0.0, cell));
            let p = cam.pdf_direction(d(0.5 * cell, 0.5 * cell)) as f64;
            let prob = (cell * cell / (w * h)) as f64;
            worst = worst.max((p * omega / prob - 1.0).abs());
            total += p * omega;
            x += cell;
        }
        y += cell;
    }
    (total, worst)
}

#[test]
fn direction_pdf_matches_the_solid_angle_of_raster_cells() {
    // Uniform raster sampling gives each of the W·H/cells² cells probability cells²/(W·H);
    // pdf_direction(centre) · solid angle(cell) must agree.
    let s = sensor(
        lookat(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 0.0), Vec3::Y),
        70.0,
        FovAxis::X,
        48,
        30,
    );
    let cam = Camera::new(&s);
    let (total, worst) = direction_pdf_over_cells(&cam);
    assert!(worst < 1e-3, "worst relative error {worst}");
    assert!((total - 1.0).abs() < 1e-4, "total {total}");
    // We = pdf / cos θ for the pinhole, and 0 outside the image.
    let d = cam.generate_ray(Vec2::new(3.0, 27.0)).d;
    let cos = d.dot(cam.forward());
    assert!((cam.importance(d) * cos / cam.pdf_direction(d) - 1.0).abs() < 1e-5);
    assert_eq!(cam.importance(-cam.forward()), 0.0);
    assert_eq!(cam.pdf_direction(-cam.forward()), 0.0);
}

#[test]
fn connect_gives_raster_and_importance_over_distance_squared() {
    let s = sensor(
        lookat(Vec3::new(0.0, 1.0, -4.0), Vec3::new(0.0, 0.5, 0.0), Vec3::Y),
        45.0,
        FovAxis::Y,
        64,
        48,
    );
    let cam = Camera::new(&s);
    let raster = Vec2::new(10.25, 40.5);
    let ray = cam.generate_ray(raster);
    let p = ray.at(3.0);
    let c = cam.connect(p).unwrap();
    assert_close(c.raster, raster, 1e-3, "connect raster");
    let dist = (p - cam.position()).length();
    assert!((c.distance - dist).abs() < 1e-5);
    assert!((c.direction_to_camera + ray.d).length() < 1e-5);
    // importance = 1 / (A cos³θ d²) = pdf_direction / d²
    let expected = cam.pdf_direction(ray.d) / (dist * dist);
    assert!((c.importance / expected - 1.0).abs() < 1e-5);
    assert!(cam.connect(cam.position() - cam.forward()).is_none());
}

#[test]
fn raster_in_pixel_never_rounds_into_the_next_pixel() {
    let just_below_one = 1.0f32.next_down();
    for x in [0u32, 1, 7, 1023, 4095, 65535] {
        let r = raster_in_pixel(x, x, Vec2::splat(just_below_one));
        assert_eq!(r.x.floor() as u32, x, "x = {x}");
        assert_eq!(r.y.floor() as u32, x);
        let r = raster_in_pixel(x, x, Vec2::splat(0.25));
        assert_eq!(r, Vec2::splat(x as f32 + 0.25));
    }
    // Without the clamp, 1023 + (1 − 2⁻²⁴) rounds to 1024 in f32.
    assert_eq!(1023.0f32 + just_below_one, 1024.0);
}

/// Rays recorded from Mitsuba 3.9.1 (`scalar_rgb`): for each sensor, `sensor.sample_ray(0,
/// 0.5, (x / W, y / H), (0.5, 0.5))` with near_clip 0.05, far_clip 500 and a box-filtered
/// hdrfilm, printing `ray.o`, `ray.d` and `ray.maxt`. The sensors are `RECORDED_SENSORS`.
#[test]
#[allow(clippy::excessive_precision)] // the digits Mitsuba printed
fn matches_rays_recorded_from_mitsuba_3() {
    // (case, raster x, raster y, o, d, maxt)
    type Record = (usize, f32, f32, [f32; 3], [f32; 3], f32);
    let records: [Record; 10] = [
        (
            0,
            10.25,
            40.5,
            [0.04487501, 0.004750004, 0.05],
            [0.666273, 0.07052475, 0.74236536],
            673.4555,
        ),
        (
            0,
            198.5,
            99.75,
            [-0.0492500, -0.024875, 0.05],
            [-0.66142672, -0.33407086, 0.67149925],
            744.52795,
        ),
        (
            1,
            10.25,
            40.5,
            [0.01876905, 0.97966963, -3.95215225],
            [0.339575, -0.36782286, 0.8656761],
            552.66656,
        ),
        (
            1,
            62.5,
            47.75,
            [-0.02631981, 0.97346157, -3.95292830],
            [-0.43788731, -0.44152412, 0.78314179],
            601.00354,
        ),
        (
            2,
            10.25,
            40.5,
            [2.97365904, -1.9745121, 4.96552277],
            [-0.52346247, 0.50651109, -0.68515223],
            503.15402,
        ),
        (
            2,
            35.5,
            90.75,
            [2.97943282, -2.00077343, 4.94630194],
            [-0.35764265, -0.01345027, -0.93376172],
            575.0166,
        ),
        (
            3,
            10.25,
            40.5,
            [0.99144161, 1.95743191, 2.96536589],
            [-0.15409161, -0.76642483, -0.6235773],
            555.3549,
        ),
        (
            3,
            0.0,
            0.0,
            [0.98780036, 1.94990659, 2.97281027],
            [-0.20930019, -0.85941523, -0.46647492],
            582.81897,
        ),
        (
            4,
            10.25,
            40.5,
            [0.96342981, 1.99677455, 2.95781207],
            [-0.65391397, -0.05767417, -0.75436747],
            559.19452,
        ),
        (
            4,
            98.5,
            199.75,
            [0.99084145, 1.94215941, 2.97594762],
            [-0.14466625, -0.91363508, -0.37992463],
            633.01855,
        ),
    ];
    for (case, x, y, o, d, maxt) in records {
        let (fov, axis, w, h, origin, target, up) = RECORDED_SENSORS[case];
        let mut s = sensor(
            lookat(Vec3::from(origin), Vec3::from(target), Vec3::from(up)),
            fov,
            axis,
            w,
            h,
        );
        s.near_clip = 0.05;
        s.far_clip = 500.0;
        let ray = Camera::new(&s).generate_ray(Vec2::new(x, y));
        let what = format!("case {case} raster ({x}, {y})");
        assert_matches_recorded_ray(&ray, o, d, maxt, &what);
    }
}

#[test]
fn a_crop_window_renders_part_of_the_same_projection() {
    // Mitsuba's crop_offset/crop_width/crop_height: the rays of the window's pixels are the
    // full film's rays at the offset pixels; the direction density and importance are
    // normalised over the window alone.
    let full = sensor(
        lookat(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 0.0), Vec3::Y),
        70.0,
        FovAxis::X,
        48,
        30,
    );
    let mut cropped = full.clone();
    cropped.film.crop = Some(CropWindow {
        x: 10,
        y: 5,
        width: 20,
        height: 12,
    });
    let (big, cam) = (Camera::new(&full), Camera::new(&cropped));
    assert_eq!((cam.width(), cam.height()), (20, 12));
    let offset = Vec2::new(10.0, 5.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for _ in 0..500 {
        let raster = Vec2::new(rng.random::<f32>() * 20.0, rng.random::<f32>() * 12.0);
        let (a, b) = (cam.generate_ray(raster), big.generate_ray(raster + offset));
        assert_eq!((a.o, a.d, a.t_max), (b.o, b.d, b.t_max));
        let p = a.at(1.0 + 5.0 * rng.random::<f32>());
        assert_close(cam.project(p).unwrap(), raster, 2e-3, "cropped round trip");
        let ratio = cam.pdf_direction(a.d) / big.pdf_direction(a.d);
        assert!(
            (ratio - (48.0 * 30.0) / (20.0 * 12.0)).abs() < 1e-5,
            "{ratio}"
        );
    }
    // Points the full film sees outside the window are outside the cropped image.
    for raster in [
        Vec2::new(5.0, 10.0),
        Vec2::new(40.0, 10.0),
        Vec2::new(20.0, 2.0),
    ] {
        let p = big.generate_ray(raster).at(2.0);
        assert!(
            big.project(p).is_some() && cam.project(p).is_none(),
            "{raster}"
        );
        assert_eq!(cam.pdf_direction(big.generate_ray(raster).d), 0.0);
    }
    let (total, worst) = direction_pdf_over_cells(&cam);
    assert!(worst < 1e-3, "worst relative error {worst}");
    assert!((total - 1.0).abs() < 1e-4, "total {total}");
}
