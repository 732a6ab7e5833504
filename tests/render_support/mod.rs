//! Scenes, renders and statistics shared by the estimator tests (`pt.rs`, `lt.rs`): small
//! scene pieces with closed-form answers (furnaces, a floor under the Cornell box light),
//! Lambert's polygon formula, and the σ-based comparisons.
#![allow(dead_code)]

use std::path::Path;

use glam::{Vec2, Vec3};
use mltbench::camera::raster_in_pixel;
use mltbench::estimator::{self, Params};
use mltbench::image::Image;
use mltbench::render::{Budget, render};
use mltbench::scene::{CropWindow, Scene, mitsuba};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Standard deviations allowed before a test fails.
pub const SIGMAS: f64 = 4.0;

pub fn scene(xml: &str) -> Scene {
    let desc = mitsuba::load_str(xml, Path::new("test-scene.xml")).expect("scene loads");
    Scene::build(desc).expect("scene builds")
}

/// Mean and standard error of channel `c` over the pixels `keep` selects (pixels are
/// independent estimates under a box filter).
pub fn pixel_mean(image: &Image, c: usize, keep: impl Fn(u32, u32) -> bool) -> (f64, f64) {
    let mut values = Vec::new();
    for y in 0..image.height {
        for x in 0..image.width {
            if keep(x, y) {
                values.push(image.get(x, y)[c] as f64);
            }
        }
    }
    let n = values.len() as f64;
    assert!(n >= 16.0, "too few pixels selected ({n})");
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Relative rounding error of an f32 film accumulating thousands of samples: added to the
/// statistical error, so that zero-variance cases (a lossless sphere in a uniform field)
/// compare to float precision instead of to zero.
pub const ROUNDING: f64 = 2e-5;

pub fn assert_within_sigmas(what: &str, measured: (f64, f64), expected: f64) {
    let (mean, se) = measured;
    let se = se.hypot(ROUNDING * expected.abs());
    let z = (mean - expected) / se.max(1e-12);
    eprintln!("{what}: {mean:.5} ± {se:.5} (expected {expected:.5}, {z:+.2} σ)");
    assert!(
        z.abs() <= SIGMAS,
        "{what}: {mean} differs from {expected} by {z:.2} σ (σ = {se})"
    );
}

/// A perspective sensor with a box filter (pixels are then independent estimates).
pub fn sensor(fov: f32, origin: &str, target: &str, res: u32) -> String {
    format!(
        r#"<sensor type="perspective">
            <float name="fov" value="{fov}"/>
            <transform name="to_world"><lookat origin="{origin}" target="{target}" up="0,1,0"/></transform>
            <film type="hdrfilm">
                <integer name="width" value="{res}"/><integer name="height" value="{res}"/>
                <rfilter type="box"/>
            </film>
        </sensor>"#
    )
}

/// A camera at the origin looking down −z, 32×32 pixels.
pub fn camera() -> String {
    sensor(60.0, "0,0,0", "0,0,-1", 32)
}

/// A closed enclosure around the camera, normals inward, emitting `le` with albedo `albedo`.
pub fn enclosure(shape: &str, albedo: &str, le: &str) -> String {
    let placement = match shape {
        "sphere" => r#"<float name="radius" value="5"/>"#,
        "cube" => r#"<transform name="to_world"><scale value="4"/></transform>"#,
        _ => unreachable!(),
    };
    format!(
        r#"<shape type="{shape}">{placement}
            <boolean name="flip_normals" value="true"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="{albedo}"/></bsdf>
            <emitter type="area"><rgb name="radiance" value="{le}"/></emitter>
        </shape>"#
    )
}

/// The Cornell box's floor (y = −1, [−1, 1]² in x and z), diffuse with `reflectance`.
pub fn floor(reflectance: f64) -> String {
    format!(
        r#"<shape type="rectangle">
            <transform name="to_world"><rotate x="1" angle="-90"/><translate y="-1"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="{reflectance}"/></bsdf>
        </shape>"#
    )
}

/// A camera looking down at the floor y = −1 from under the Cornell box light, 16×16 pixels.
pub fn floor_camera() -> String {
    sensor(28.0, "0,0.9,1.2", "0,-1,-0.1", 16)
}

/// Mean and standard error of pixel (x, y), channel c, over independent runs.
pub fn mean_over_runs(runs: &[Image], x: u32, y: u32, c: usize) -> (f64, f64) {
    let values: Vec<f64> = runs.iter().map(|im| im.get(x, y)[c] as f64).collect();
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (var / k).sqrt())
}

/// The average of `f` over the points of the floor plane y = −1 that pixel (x, y) sees
/// (16×16 stratified camera rays): what a box-filtered pixel converges to when the floor's
/// radiance is `f`.
pub fn floor_pixel_average(scene: &Scene, x: u32, y: u32, f: impl Fn(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for j in 0..16 {
        for i in 0..16 {
            let u = Vec2::new((i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
            let ray = scene.camera.generate_ray(raster_in_pixel(x, y, u));
            let t = (-1.0 - ray.o.y) / ray.d.y;
            let p = ray.at(t);
            assert!(
                t > 0.0 && p.x.abs() < 1.0 && p.z.abs() < 1.0,
                "pixel sees the floor"
            );
            sum += f(p);
        }
    }
    sum / 256.0
}

/// Irradiance at `p` (normal `n`) from a uniform Lambertian polygon of unit radiance:
/// Lambert's formula E = ½ Σ_i Θ_i (n · γ̂_i), Θ_i the angle the edge v_i v_{i+1} subtends
/// at p and γ̂_i the unit normal of the plane through p and that edge (Arvo 1995, eq. 2).
pub fn polygon_irradiance(p: Vec3, n: Vec3, vertices: &[Vec3]) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..vertices.len() {
        let a = (vertices[i] - p).as_dvec3().normalize();
        let b = (vertices[(i + 1) % vertices.len()] - p)
            .as_dvec3()
            .normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.as_dvec3().dot(a.cross(b).normalize());
    }
    0.5 * sum.abs()
}

/// The Cornell box light's rectangle, emitting downwards (the `<shape>` left open for its
/// BSDF and emitter).
pub const CBOX_LIGHT_RECTANGLE: &str = r#"<shape type="rectangle">
    <transform name="to_world">
        <scale x="0.23" y="0.19"/><rotate x="1" angle="90"/><translate y="0.99"/>
    </transform>"#;

/// Renders `scene` with estimator `name` for `passes` passes; no sample may be dropped.
pub fn render_with(name: &str, scene: &Scene, params: &[&str], passes: u32, seed: u64) -> Image {
    let params = Params::parse(params).unwrap();
    let mut e = estimator::create(name, &params, scene, seed).unwrap();
    let out = render(scene, e.as_mut(), Budget::Passes(passes), |_, _| {});
    assert_eq!(
        out.stats.invalid_samples, 0,
        "no sample may be NaN or negative"
    );
    out.image
}

/// Direct lighting only, from the shape opened by `light_shape` (the Cornell box light's
/// rectangle, emitting downwards), on the floor, rendered by `estimator` with `passes`
/// passes per run: pixel means over 16 runs against
/// ρ/π · Le · E_unit (Lambert's formula), within `SIGMAS`. With `crop`, the film renders
/// only that window, and each of its pixels is held to the formula for the full film's
/// pixel it stands for (the expectation comes from the uncropped camera).
pub fn assert_floor_under_the_cbox_light(
    (estimator, passes): (&str, u32),
    light_shape: &str,
    scene_path: &Path,
    crop: Option<CropWindow>,
) {
    let (rho, le) = (0.6f64, [18.387f64, 13.9873, 6.75357]);
    let xml = format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="2"/></integrator>
            {floor_camera}
            {light_shape}
                <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
                <emitter type="area"><rgb name="radiance" value="18.387, 13.9873, 6.75357"/></emitter>
            </shape>
            {floor}
        </scene>"#,
        floor_camera = floor_camera(),
        floor = floor(0.6)
    );
    let desc = mitsuba::load_str(&xml, scene_path).expect("scene loads");
    let full = Scene::build(desc.clone()).expect("scene builds");
    let mut cropped = desc;
    cropped.sensor.film.crop = crop;
    let scene = Scene::build(cropped).expect("cropped scene builds");
    let window = scene.description.sensor.film.window();
    assert_eq!(
        (scene.width(), scene.height()),
        (window.width, window.height)
    );
    let light = [
        Vec3::new(-0.23, 0.99, -0.19),
        Vec3::new(0.23, 0.99, -0.19),
        Vec3::new(0.23, 0.99, 0.19),
        Vec3::new(-0.23, 0.99, 0.19),
    ];
    // Independent runs give each pixel's mean and standard error.
    let runs: Vec<Image> = (0..16)
        .map(|k| render_with(estimator, &scene, &[], passes, 100 + k))
        .collect();
    assert_eq!(
        (runs[0].width, runs[0].height),
        (window.width, window.height)
    );
    let pixels: [(u32, u32); 6] = [(8, 8), (4, 4), (12, 5), (3, 12), (8, 14), (13, 13)];
    let mut checked = 0;
    for (x, y) in pixels {
        let (Some(cx), Some(cy)) = (x.checked_sub(window.x), y.checked_sub(window.y)) else {
            continue;
        };
        if cx >= window.width || cy >= window.height {
            continue;
        }
        checked += 1;
        let e = floor_pixel_average(&full, x, y, |p| polygon_irradiance(p, Vec3::Y, &light));
        for (c, le) in le.into_iter().enumerate() {
            assert_within_sigmas(
                &format!("floor pixel ({x},{y}) channel {c}"),
                mean_over_runs(&runs, cx, cy, c),
                rho / std::f64::consts::PI * le * e,
            );
        }
    }
    assert!(checked >= 4, "{checked} pixels inside the window");
}

pub fn furnace(shape: &str, albedo: &str, le: &str, max_depth: i32, inside: &str) -> Scene {
    scene(&format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="{max_depth}"/></integrator>
            {camera}
            {}
            {inside}
        </scene>"#,
        enclosure(shape, albedo, le),
        camera = camera()
    ))
}

/// Mean over all pixels of channel `c` in each run: their mean and standard error.
pub fn image_mean_over_runs(runs: &[Image], c: usize) -> (f64, f64) {
    let means: Vec<f64> = runs
        .iter()
        .map(|im| im.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / im.pixels.len() as f64)
        .collect();
    mean_and_standard_error(&means)
}

pub fn mean_and_standard_error(values: &[f64]) -> (f64, f64) {
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (var / k).sqrt())
}

/// A shipped scene at `res` × `res` pixels.
pub fn shipped_scene(file: &str, res: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("experiments/scenes")
        .join(file);
    let params = [("res".to_string(), res.to_string())];
    Scene::build(mitsuba::load_file_with(&path, &params).unwrap()).unwrap()
}

/// Per run, the mean of each `BLOCK`×`BLOCK` block of pixels, per channel:
/// `[block][channel]`.
pub fn block_means(image: &Image) -> Vec<[f64; 3]> {
    block_means_of(image, 4)
}

/// `block_means` with blocks of `BLOCK` × `BLOCK` pixels.
#[allow(non_snake_case)]
pub fn block_means_of(image: &Image, BLOCK: u32) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for by in 0..image.height / BLOCK {
        for bx in 0..image.width / BLOCK {
            let mut sum = [0.0f64; 3];
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    let p = image.get(x, y);
                    for (c, s) in sum.iter_mut().enumerate() {
                        *s += p[c] as f64;
                    }
                }
            }
            out.push(sum.map(|s| s / (BLOCK * BLOCK) as f64));
        }
    }
    out
}

/// Welch's t-test of every block and channel between the runs of two estimators: the
/// smallest two-sided p-value and how many tests there were.
pub fn smallest_block_p_value(a: &[Image], b: &[Image]) -> (f64, usize, String) {
    smallest_block_p_value_of(a, b, 4)
}

/// `smallest_block_p_value` over blocks of `block` × `block` pixels.
pub fn smallest_block_p_value_of(a: &[Image], b: &[Image], block: u32) -> (f64, usize, String) {
    let (ma, mb): (Vec<_>, Vec<_>) = (
        a.iter().map(|im| block_means_of(im, block)).collect(),
        b.iter().map(|im| block_means_of(im, block)).collect(),
    );
    let mut smallest = (1.0f64, String::new());
    let blocks = ma[0].len();
    for k in 0..blocks {
        for c in 0..3 {
            let xa: Vec<f64> = ma.iter().map(|r| r[k][c]).collect();
            let xb: Vec<f64> = mb.iter().map(|r| r[k][c]).collect();
            let ((mean_a, se_a), (mean_b, se_b)) =
                (mean_and_standard_error(&xa), mean_and_standard_error(&xb));
            let (va, vb) = (se_a * se_a, se_b * se_b);
            if va + vb == 0.0 {
                assert_eq!(mean_a, mean_b, "block {k} channel {c}: both exact");
                continue;
            }
            let t = (mean_a - mean_b) / (va + vb).sqrt();
            // Welch–Satterthwaite degrees of freedom.
            let (na, nb) = (xa.len() as f64 - 1.0, xb.len() as f64 - 1.0);
            let dof = (va + vb).powi(2) / (va * va / na + vb * vb / nb);
            let p = 2.0 * StudentsT::new(0.0, 1.0, dof).unwrap().cdf(-t.abs());
            if p < smallest.0 {
                smallest = (
                    p,
                    format!("block {k} channel {c}: {mean_a:.5} against {mean_b:.5} (t = {t:.2})"),
                );
            }
        }
    }
    (smallest.0, blocks * 3, smallest.1)
}

/// Asserts that no 4×4 block and channel differs between the runs `a` and `b` of two
/// estimators at family-wise significance 10⁻³ (Šidák over all blocks and channels).
pub fn assert_blocks_agree(what: &str, a: &[Image], b: &[Image]) {
    assert_blocks_agree_of(what, a, b, 4);
}

/// `assert_blocks_agree` over blocks of `block` × `block` pixels.
pub fn assert_blocks_agree_of(what: &str, a: &[Image], b: &[Image], block: u32) {
    let (p, tests, worst) = smallest_block_p_value_of(a, b, block);
    let per_test = 1.0 - (1.0f64 - 1e-3).powf(1.0 / tests as f64);
    eprintln!("{what}: smallest p {p:.2e} over {tests} tests (threshold {per_test:.2e}); {worst}");
    assert!(
        p > per_test,
        "{what}: {worst}, p = {p:.2e} < {per_test:.2e}"
    );
}

/// The floor y = −1 as an OBJ quad whose vertex normals lean away from its geometric normal
/// (diffuse, ρ = 0.6), under the Cornell box light (radiance 10, reflectance
/// `light_albedo`), seen by `floor_camera`, with `max_depth`. The OBJ goes to a folder named
/// after `name`.
pub fn leaning_floor_scene(name: &str, max_depth: u32, light_albedo: f64) -> Scene {
    let dir = std::env::temp_dir().join(format!("mltbench-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("floor.obj"),
        "v -1 -1 1\nv 1 -1 1\nv 1 -1 -1\nv -1 -1 -1\n\
         vn -0.6 1 0.3\nvn 0.5 1 0.6\nvn 0.4 1 -0.5\nvn -0.3 1 -0.6\n\
         f 1//1 2//2 3//3\nf 1//1 3//3 4//4\n",
    )
    .unwrap();
    let xml = format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="{max_depth}"/></integrator>
            {floor_camera}
            {CBOX_LIGHT_RECTANGLE}
                <bsdf type="diffuse"><rgb name="reflectance" value="{light_albedo}"/></bsdf>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter>
            </shape>
            <shape type="obj"><string name="filename" value="floor.obj"/>
                <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>
            </shape>
        </scene>"#,
        floor_camera = floor_camera()
    );
    let desc = mitsuba::load_str(&xml, &dir.join("scene.xml")).expect("scene loads");
    let scene = Scene::build(desc).expect("scene builds");
    let _ = std::fs::remove_dir_all(&dir);
    scene
}

/// A floor of albedo 0.5 (`floor`, seen by `floor_camera`) under a point light of
/// intensity 4 at (0.3, 0.5, −0.2), direct lighting only (`max_depth` 2): the scene, the
/// albedo, and the irradiance E(p) = I cos θ / d² on the floor.
pub fn point_light_floor() -> (Scene, f64, impl Fn(Vec3) -> f64) {
    let (rho, intensity, light) = (0.5f64, 4.0f64, Vec3::new(0.3, 0.5, -0.2));
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="2"/></integrator>
            {floor_camera}
            <emitter type="point"><point name="position" x="0.3" y="0.5" z="-0.2"/>
                <rgb name="intensity" value="4"/></emitter>
            {floor}
        </scene>"#,
        floor_camera = floor_camera(),
        floor = floor(rho)
    ));
    let irradiance = move |p: Vec3| {
        let d = light - p;
        intensity * (d.y / d.length()) as f64 / d.length_squared() as f64
    };
    (scene, rho, irradiance)
}

/// Asserts that `estimator` renders the same bits on 1 and 2 threads (`cbox-spheres.xml` at
/// 40×40, a film whose tiles do not divide it evenly), and another image for another seed.
pub fn assert_thread_count_does_not_matter(estimator: &str, passes: u32) {
    let scene = shipped_scene("cbox-spheres.xml", 40);
    let with_threads = |threads: usize, seed: u64| -> Vec<u32> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut e = estimator::create(estimator, &Params::default(), &scene, seed).unwrap();
        let image = pool
            .install(|| render(&scene, e.as_mut(), Budget::Passes(passes), |_, _| {}))
            .image;
        assert!(image.pixels.iter().any(|p| !p.is_black()), "{estimator}");
        image
            .pixels
            .iter()
            .flat_map(|p| p.0.map(f32::to_bits))
            .collect()
    };
    let one = with_threads(1, 5);
    assert_eq!(one, with_threads(2, 5), "{estimator}: 1 and 2 threads");
    assert_ne!(
        one,
        with_threads(2, 6),
        "{estimator}: another seed, another image"
    );
}
