//! The thin-lens camera (`<sensor type="thinlens">`) against Mitsuba 3's model: a lens of
//! radius r on the camera plane z = 0, the lens point r · concentric(u), rays from it through
//! the point the pinhole sees on the focus plane z = F, clipped to [near, far] in camera z.

mod camera_support;
mod chi2_support;

use camera_support::{RECORDED_SENSORS, assert_matches_recorded_ray, lookat, triangle_solid_angle};
use chi2_support::pearson_uniform;

use glam::{Vec2, Vec3};
use mltbench::camera::Camera;
use mltbench::math::Transform;
use mltbench::scene::{FilmDesc, FilterDesc, FovAxis, SensorDesc, ThinLensDesc};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[allow(clippy::too_many_arguments)]
fn sensor(
    to_world: Transform,
    fov: f32,
    axis: FovAxis,
    width: u32,
    height: u32,
    lens: Option<(f32, f32)>,
) -> SensorDesc {
    SensorDesc {
        to_world,
        fov_degrees: fov,
        fov_axis: axis,
        near_clip: 0.05,
        far_clip: 500.0,
        lens: lens.map(|(aperture_radius, focus_distance)| ThinLensDesc {
            aperture_radius,
            focus_distance,
        }),
        film: FilmDesc {
            width,
            height,
            filter: FilterDesc::Box,
            crop: None,
        },
        sample_count: 1,
    }
}

/// A camera away from the origin, turned off every axis.
fn tilted(lens: Option<(f32, f32)>) -> Camera {
    Camera::new(&sensor(
        lookat(
            Vec3::new(3.0, -2.0, 5.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.2, 1.0, 0.1),
        ),
        55.0,
        FovAxis::X,
        64,
        48,
        lens,
    ))
}

fn random_raster(rng: &mut Xoshiro256PlusPlus, camera: &Camera) -> Vec2 {
    Vec2::new(
        rng.random::<f32>() * camera.width() as f32,
        rng.random::<f32>() * camera.height() as f32,
    )
}

fn random_unit(rng: &mut Xoshiro256PlusPlus) -> Vec2 {
    Vec2::new(rng.random::<f32>(), rng.random::<f32>())
}

/// The lens point a ray came from: where its line crosses the camera plane z = 0.
fn lens_point(camera: &Camera, ray: &mltbench::geometry::Ray) -> Vec3 {
    let along = ray.o - camera.position();
    let t = along.dot(camera.forward()) / ray.d.dot(camera.forward());
    ray.o - ray.d * t
}

#[test]
fn a_vanishing_aperture_gives_the_perspective_rays() {
    let pinhole = tilted(None);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for radius in [0.0, 1e-7] {
        let lens = tilted(Some((radius, 2.5)));
        assert!(lens.has_lens() && !pinhole.has_lens());
        for _ in 0..2000 {
            let raster = random_raster(&mut rng, &pinhole);
            let u = random_unit(&mut rng);
            let a = pinhole.generate_ray(raster);
            let b = lens.sample_ray(raster, u);
            assert!(
                (a.d - b.d).length() < 1e-6,
                "{radius}: d {} vs {}",
                a.d,
                b.d
            );
            assert!(
                (a.o - b.o).length() < 1e-6,
                "{radius}: o {} vs {}",
                a.o,
                b.o
            );
            assert!((a.t_max / b.t_max - 1.0).abs() < 1e-5);
            // The pinhole's sample_ray ignores the lens sample: bit-identical to generate_ray.
            let c = pinhole.sample_ray(raster, u);
            assert_eq!((a.o, a.d, a.t_max), (c.o, c.d, c.t_max));
        }
    }
    // The chief ray (lens centre) of a real lens is the pinhole's too.
    let lens = tilted(Some((0.3, 2.5)));
    let raster = Vec2::new(10.5, 30.25);
    let (a, b) = (
        pinhole.generate_ray(raster),
        lens.sample_ray(raster, Vec2::splat(0.5)),
    );
    assert!((a.d - b.d).length() < 1e-6 && (a.o - b.o).length() < 1e-6);
}

#[test]
fn rays_of_one_raster_position_meet_on_the_focus_plane() {
    let focus = 3.25;
    let camera = tilted(Some((0.4, focus)));
    let pinhole = tilted(None);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
    let mut spread = 0.0f32;
    for _ in 0..200 {
        let raster = random_raster(&mut rng, &camera);
        // The pinhole's ray reaches the focus plane (camera z = F) at this point.
        let chief = pinhole.generate_ray(raster);
        let target = camera.position() + chief.d * (focus / chief.d.dot(camera.forward()));
        for _ in 0..20 {
            let u = random_unit(&mut rng);
            let ray = camera.sample_ray(raster, u);
            assert!((ray.d.length() - 1.0).abs() < 1e-5);
            // Starts on the near plane, ends on the far plane.
            let z = |p: Vec3| (p - camera.position()).dot(camera.forward());
            assert!((z(ray.o) - 0.05).abs() < 1e-4, "near {}", z(ray.o));
            assert!((z(ray.at(ray.t_max)) - 500.0).abs() < 0.05);
            // Reaches the point in focus.
            let t = (focus - z(ray.o)) / ray.d.dot(camera.forward());
            let miss = (ray.at(t) - target).length();
            assert!(miss < 2e-5 * focus, "missed the focus point by {miss}");
            // And a point in focus projects back to the same raster position from every
            // lens point, while an out-of-focus point does not.
            let back = camera.project_through_lens(target, u).unwrap();
            assert!((back - raster).length() < 2e-3, "{back} vs {raster}");
            let near_point = ray.at(0.5 * t);
            let seen = camera.project_through_lens(near_point, u).unwrap();
            assert!(
                (seen - raster).length() < 2e-3,
                "on the ray: {seen} vs {raster}"
            );
            if let Some(centre) = camera.project_through_lens(near_point, Vec2::splat(0.5)) {
                spread = spread.max((centre - raster).length());
            }
        }
    }
    // Half-way to the focus plane, lens points up to 0.4 off the axis shift the image by
    // pixels, not by rounding error: the test above can fail.
    assert!(spread > 1.0, "largest out-of-focus shift {spread} pixels");
}

#[test]
fn lens_points_are_uniform_on_the_aperture() {
    // Rays from uniform lens samples, traced back to the lens plane: rings of equal area
    // (r² in equal steps) times equal sectors are equally likely; Pearson's χ² at 1e-3.
    let radius = 0.35;
    let camera = tilted(Some((radius, 4.0)));
    let (rings, sectors) = (10usize, 16usize);
    let n = 200_000usize;
    let mut counts = vec![0u64; rings * sectors];
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(13);
    // The camera frame, from the lookat used by `tilted`.
    let frame = lookat(
        Vec3::new(3.0, -2.0, 5.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.2, 1.0, 0.1),
    );
    for _ in 0..n {
        let raster = random_raster(&mut rng, &camera);
        let ray = camera.sample_ray(raster, random_unit(&mut rng));
        let l = lens_point(&camera, &ray);
        let q = frame.inverse.transform_point3(l);
        assert!(q.z.abs() < 1e-4, "lens point off the lens plane: {q}");
        let r2 = (q.x * q.x + q.y * q.y) / (radius * radius);
        assert!(r2 <= 1.0 + 1e-4, "outside the aperture: r²/R² = {r2}");
        let ring = ((r2 as f64 * rings as f64) as usize).min(rings - 1);
        let phi = (q.y.atan2(q.x) as f64).rem_euclid(std::f64::consts::TAU);
        let sector = ((phi / std::f64::consts::TAU * sectors as f64) as usize).min(sectors - 1);
        counts[ring * sectors + sector] += 1;
    }
    let (chi2, dof, p) = pearson_uniform(&counts, n as f64);
    assert!(p > 1e-3, "χ² = {chi2:.1} with {dof} dof, p = {p:.2e}");
}

#[test]
fn connect_lens_inverts_sample_ray() {
    let camera = tilted(Some((0.3, 2.0)));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(14);
    for _ in 0..500 {
        let raster = random_raster(&mut rng, &camera);
        let u = random_unit(&mut rng);
        let ray = camera.sample_ray(raster, u);
        let p = ray.at(0.2 + rng.random::<f32>() * 20.0);
        let c = camera
            .connect_lens(p, u)
            .expect("a point on a camera ray is visible");
        assert!(
            (c.raster - raster).length() < 3e-3,
            "{} vs {raster}",
            c.raster
        );
        let l = lens_point(&camera, &ray);
        assert!((c.camera_position - l).length() < 1e-4);
        assert!((c.direction_to_camera + ray.d).length() < 1e-4);
        // 1 / (A cos³θ d²): the pinhole's formula from the lens point.
        let cos = ray.d.dot(camera.forward());
        let expected = 1.0 / (camera.image_plane_area() * cos.powi(3) * c.distance.powi(2));
        assert!((c.importance / expected - 1.0).abs() < 1e-4);
    }
    // `connect` needs a lens point for a thin lens; for a pinhole connect_lens = connect.
    let p = camera.position() + camera.forward() * 3.0;
    assert!(camera.connect(p).is_none());
    let pinhole = tilted(None);
    assert_eq!(
        pinhole.connect_lens(p, Vec2::new(0.1, 0.9)),
        pinhole.connect(p)
    );
}

/// Rays recorded from Mitsuba 3.9.1 (`scalar_rgb`): for each sensor,
/// `sensor.sample_ray(0, 0.5, (x / W, y / H), aperture_sample)` with near_clip 0.05,
/// far_clip 500 and a box-filtered hdrfilm, printing `ray.o`, `ray.d` and `ray.maxt` (the
/// weight was 1 in every case). The sensors are the first three of `RECORDED_SENSORS`, each
/// with a lens.
#[test]
#[allow(clippy::excessive_precision)] // the digits Mitsuba printed
fn matches_rays_recorded_from_mitsuba_3() {
    // (aperture_radius, focus_distance) added to the first three sensors.
    let lenses: [(f32, f32); 3] = [(0.1, 2.0), (0.25, 4.5), (0.05, 0.3)];
    // (case, raster x, raster y, aperture sample, o, d, maxt)
    type Record = (usize, f32, f32, [f32; 2], [f32; 3], [f32; 3], f32);
    let records: [Record; 12] = [
        (
            0,
            10.25,
            40.5,
            [0.1, 0.9],
            [-0.010279327, 0.059904333, 0.049999997],
            [0.6785394, 0.048898313, 0.73293459],
            682.12091,
        ),
        (
            0,
            0.0,
            0.0,
            [0.75, 0.2],
            [0.085612558, -0.021411169, 0.050000001],
            [0.65621817, 0.35012171, 0.66842544],
            747.95178,
        ),
        (
            0,
            30.5,
            20.75,
            [0.5, 0.5],
            [0.034750011, 0.014625004, 0.050000001],
            [0.55492121, 0.23354599, 0.79844761],
            626.15253,
        ),
        (
            0,
            5.0,
            7.0,
            [0.999, 0.001],
            [0.11630504, -0.047305033, 0.050000004],
            [0.63836783, 0.32471606, 0.69788677],
            716.37695,
        ),
        (
            1,
            10.25,
            40.5,
            [0.1, 0.9],
            [-0.12108096, 1.1184397, -3.9348059],
            [0.36162865, -0.38917136, 0.84721333],
            562.41028,
        ),
        (
            1,
            0.0,
            0.0,
            [0.75, 0.2],
            [0.11791386, 0.89757699, -3.9624138],
            [0.43771008, 0.2577104, 0.86139143],
            607.63904,
        ),
        (
            1,
            30.5,
            20.75,
            [0.5, 0.5],
            [0.0012944201, 0.9965812, -3.9500382],
            [0.025839143, -0.068246327, 0.99733382],
            500.90311,
        ),
        (
            1,
            5.0,
            7.0,
            [0.999, 0.001],
            [0.1977624, 0.83523935, -3.9702058],
            [0.37536019, 0.18118116, 0.90899837],
            568.44397,
        ),
        (
            2,
            10.25,
            40.5,
            [0.1, 0.9],
            [2.9994185, -1.9535533, 4.9626427],
            [-0.61826533, 0.41808483, -0.66554731],
            509.32111,
        ),
        (
            2,
            0.0,
            0.0,
            [0.75, 0.2],
            [2.9563775, -1.9709827, 4.9780092],
            [-0.3777228, 0.84769362, -0.37247959],
            591.91199,
        ),
        (
            2,
            30.5,
            20.75,
            [0.5, 0.5],
            [2.9865968, -1.9641905, 4.963953],
            [-0.25506461, 0.68145716, -0.68597251],
            525.4314,
        ),
        (
            2,
            5.0,
            7.0,
            [0.999, 0.001],
            [2.9435129, -1.9831507, 4.9784274],
            [-0.31124377, 0.83733761, -0.44943637],
            575.87109,
        ),
    ];
    for (case, x, y, u, o, d, maxt) in records {
        let (fov, axis, w, h, origin, target, up) = RECORDED_SENSORS[case];
        let (radius, focus) = lenses[case];
        let s = sensor(
            lookat(Vec3::from(origin), Vec3::from(target), Vec3::from(up)),
            fov,
            axis,
            w,
            h,
            Some((radius, focus)),
        );
        let ray = Camera::new(&s).sample_ray(Vec2::new(x, y), Vec2::from(u));
        let what = format!("case {case} raster ({x}, {y}) lens {u:?}");
        assert_matches_recorded_ray(&ray, o, d, maxt, &what);
    }
}

#[test]
fn importance_and_densities_follow_sample_ray() {
    let camera = tilted(Some((0.3, 2.0)));
    let pdf_position = camera
        .pdf_lens_position()
        .expect("a lens has an area density");
    assert!((pdf_position * std::f32::consts::PI * 0.09 - 1.0).abs() < 1e-6);
    let cell = 1.0f32;
    let (w, h) = (camera.width() as f32, camera.height() as f32);
    // From an off-centre lens point, raster cells of uniform probability cell²/(W·H): the
    // density at the cell's centre times the cell's solid angle (from its corner rays alone,
    // independently of the cos³ formula) must give that probability.
    for u in [
        Vec2::new(0.9, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.05, 0.7),
    ] {
        let origin = lens_point(&camera, &camera.sample_ray(Vec2::new(w, h) * 0.5, u));
        let (mut total, mut worst) = (0.0f64, 0.0f64);
        let mut y = 0.0;
        while y < h {
            let mut x = 0.0;
            while x < w {
                let d = |dx: f32, dy: f32| camera.sample_ray(Vec2::new(x + dx, y + dy), u).d;
                let omega = triangle_solid_angle(d(0.0, 0.0), d(cell, 0.0), d(cell, cell))
                    + triangle_solid_angle(d(0.0, 0.0), d(cell, cell), d(0.0, cell));
                let centre = d(0.5 * cell, 0.5 * cell);
                let p = camera.pdf_direction_from(origin, centre) as f64;
                worst = worst.max((p * omega / (cell * cell / (w * h)) as f64 - 1.0).abs());
                total += p * omega;
                // Mitsuba's weight of a sampled ray: We cos θ / (p_A p_ω) = 1.
                let cos = centre.dot(camera.forward());
                let we = camera.importance_from(origin, centre);
                let weight = we * cos / (pdf_position * p as f32);
                assert!((weight - 1.0).abs() < 1e-4, "weight {weight}");
                x += cell;
            }
            y += cell;
        }
        assert!(
            worst < 2e-3,
            "lens sample {u}: worst relative error {worst}"
        );
        assert!((total - 1.0).abs() < 1e-4, "lens sample {u}: total {total}");
    }
}

#[test]
fn importance_is_zero_where_no_camera_ray_goes() {
    let camera = tilted(Some((0.3, 2.0)));
    let u = Vec2::new(0.8, 0.3);
    let ray = camera.sample_ray(Vec2::new(2.0, 3.0), u);
    let origin = lens_point(&camera, &ray);
    assert!(camera.importance_from(origin, ray.d) > 0.0);
    // Backwards, or far outside the field of view.
    assert_eq!(camera.importance_from(origin, -ray.d), 0.0);
    let right = camera.forward().cross(Vec3::Y).normalize();
    let wide = (camera.forward() + right * 10.0).normalize();
    assert_eq!(camera.importance_from(origin, wide), 0.0);
    assert_eq!(camera.pdf_direction_from(origin, wide), 0.0);
    // From a point beyond the aperture, nothing.
    let outside = camera.position() + right * 0.5;
    assert_eq!(camera.importance_from(outside, camera.forward()), 0.0);
    // The lens centre: `importance` is the chief ray's.
    let d = camera.generate_ray(Vec2::new(10.0, 40.0)).d;
    assert_eq!(
        camera.importance(d),
        camera.importance_from(camera.position(), d)
    );
    // A pinhole's rays all start at the pinhole: no area density.
    assert_eq!(tilted(None).pdf_lens_position(), None);
}

#[test]
fn connections_are_importance_over_the_lens_density() {
    // A light-tracing connection from p to lens point a carries We(a, a → p) cos θ / d²,
    // divided by the density of the lens point: the two camera interfaces agree.
    let camera = tilted(Some((0.3, 2.0)));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(15);
    for _ in 0..200 {
        let u = random_unit(&mut rng);
        let ray = camera.sample_ray(random_raster(&mut rng, &camera), u);
        let p = ray.at(0.5 + rng.random::<f32>() * 10.0);
        let c = camera.connect_lens(p, u).expect("visible");
        let towards_p = -c.direction_to_camera;
        let cos = towards_p.dot(camera.forward());
        let we = camera.importance_from(c.camera_position, towards_p);
        let expected = we * cos / (c.distance * c.distance) / camera.pdf_lens_position().unwrap();
        assert!(
            (c.importance / expected - 1.0).abs() < 1e-4,
            "{} vs {expected}",
            c.importance
        );
    }
}
