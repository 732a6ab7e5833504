//! The reference path tracer `pt` against closed forms (fixed seeds; tolerances in standard
//! deviations measured from the renders themselves):
//!
//! * furnace: inside a closed, uniformly emitting diffuse enclosure of albedo a the radiance
//!   is Le·Σ_{j<d} a^j for `max_depth` d, and Le/(1 − a) unbounded;
//! * specular objects (mirror, glass, thin glass) inside such an enclosure are invisible;
//! * an emitter seen directly shows exactly its radiance, from the front only;
//! * direct illumination of a floor by a rectangular light matches Lambert's polygon formula;
//! * a lamp without a BSDF reflects nothing (Mitsuba's default), also inside a glass sphere;
//! * `hide_emitters` removes exactly the emission camera rays find: Le·Σ_{1≤j<d} a^j in the
//!   furnace; lamps seen through `null` surfaces and anything in mirrors stay.

mod render_support;

use std::path::Path;

use glam::{Vec2, Vec3};
use mltbench::camera::raster_in_pixel;
use mltbench::estimator::{self, Params, Stats};
use mltbench::image::Image;
use mltbench::math::Rgb;
use mltbench::render::{Budget, render};
use mltbench::scene::{CropWindow, Scene};
use render_support::*;

/// `pt` renders the floor under the Cornell box light with 16 passes per run.
const PT_FLOOR: (&str, u32) = ("pt", 16);

fn render_pt(scene: &Scene, params: &[&str], passes: u32, seed: u64) -> Image {
    render_with("pt", scene, params, passes, seed)
}

/// True when all of pixel (x, y) (its four corners) sees shape `shape` first.
fn pixel_sees_only(scene: &Scene, x: u32, y: u32, shape: u32) -> bool {
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .iter()
        .all(|&(u, v)| {
            let raster = raster_in_pixel(x, y, Vec2::new(u, v) * 0.999 + 0.0005);
            let ray = scene.camera.generate_ray(raster);
            scene
                .geometry
                .intersect(&ray)
                .is_some_and(|h| h.shape == shape)
        })
}

#[test]
fn furnace_truncated_sums_for_each_max_depth() {
    let (a, le) = (0.8f64, 1.0f64);
    for shape in ["cube", "sphere"] {
        for depth in [1, 2, 3, 5, 8] {
            let scene = furnace(shape, "0.8", "1", depth, "");
            let image = render_pt(&scene, &[], 16, 11 + depth as u64);
            let expected: f64 = (0..depth).map(|j| le * a.powi(j)).sum();
            for c in 0..3 {
                assert_within_sigmas(
                    &format!("{shape} furnace, max_depth {depth}, channel {c}"),
                    pixel_mean(&image, c, |_, _| true),
                    expected,
                );
            }
        }
    }
}

#[test]
fn furnace_unbounded_depth_gives_le_over_one_minus_albedo() {
    let albedo = [0.3f64, 0.6, 0.85];
    let le = [1.0f64, 0.5, 2.0];
    for shape in ["sphere", "cube"] {
        let scene = furnace(shape, "0.3, 0.6, 0.85", "1, 0.5, 2", -1, "");
        // Russian roulette from the first bounce too: it must not bias the estimate.
        for rr_depth in ["rr_depth=5", "rr_depth=1"] {
            let image = render_pt(&scene, &[rr_depth], 32, 5);
            for c in 0..3 {
                assert_within_sigmas(
                    &format!("{shape} furnace, unbounded, {rr_depth}, channel {c}"),
                    pixel_mean(&image, c, |_, _| true),
                    le[c] / (1.0 - albedo[c]),
                );
            }
        }
    }
}

#[test]
fn specular_objects_vanish_in_a_uniform_enclosure() {
    // Le = 1, albedo 0.5: the radiance is 2 everywhere, through any lossless specular object.
    let objects = [
        (
            "mirror",
            r#"<bsdf type="conductor"><string name="material" value="none"/></bsdf>"#,
        ),
        (
            "glass",
            r#"<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>"#,
        ),
        (
            "dense glass",
            r#"<bsdf type="dielectric"><string name="int_ior" value="diamond"/></bsdf>"#,
        ),
        ("thin glass", r#"<bsdf type="thindielectric"/>"#),
    ];
    for (name, bsdf) in objects {
        for shape in ["sphere", "cube"] {
            let inside = format!(
                r#"<shape type="sphere"><point name="center" x="0" y="0" z="-2.5"/>
                       <float name="radius" value="1.2"/>{bsdf}</shape>"#
            );
            let scene = furnace(shape, "0.5", "1", -1, &inside);
            let image = render_pt(&scene, &[], 32, 3);
            for c in 0..3 {
                assert_within_sigmas(
                    &format!("{name} in a {shape} furnace, channel {c}"),
                    pixel_mean(&image, c, |x, y| pixel_sees_only(&scene, x, y, 1)),
                    2.0,
                );
            }
        }
    }
}

#[test]
fn emitters_seen_directly_show_their_radiance_from_the_front_only() {
    // A black emitter facing the camera on the left, one facing away on the right.
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            {camera}
            <bsdf type="diffuse" id="black"><rgb name="reflectance" value="0"/></bsdf>
            <shape type="rectangle">
                <transform name="to_world"><translate x="-1.1" z="-2"/></transform>
                <ref id="black"/>
                <emitter type="area"><rgb name="radiance" value="3, 2, 0.5"/></emitter>
            </shape>
            <shape type="rectangle">
                <transform name="to_world"><rotate y="1" angle="180"/><translate x="1.1" z="-2"/></transform>
                <ref id="black"/>
                <emitter type="area"><rgb name="radiance" value="7"/></emitter>
            </shape>
            <emitter type="point"><point name="position" x="0" y="0" z="-1"/>
                <rgb name="intensity" value="5"/></emitter>
        </scene>"#,
        camera = camera()
    ));
    let image = render_pt(&scene, &[], 4, 1);
    let (mut front, mut back) = (0, 0);
    for y in 0..32 {
        for x in 0..32 {
            let v = image.get(x, y);
            if pixel_sees_only(&scene, x, y, 0) {
                front += 1;
                for (c, le) in [3.0f32, 2.0, 0.5].into_iter().enumerate() {
                    assert!((v[c] - le).abs() <= 1e-5 * le, "pixel ({x},{y}) = {v:?}");
                }
            } else if pixel_sees_only(&scene, x, y, 1) {
                back += 1;
                assert_eq!(v, Rgb::BLACK, "the back of an emitter is dark at ({x},{y})");
            }
        }
    }
    assert!(
        front > 20 && back > 20,
        "{front} front and {back} back pixels"
    );
}

#[test]
fn floor_irradiance_under_a_rectangle_light_matches_lamberts_formula() {
    // The Cornell box's floor and light (experiments/scenes/cbox.xml), nothing else.
    assert_floor_under_the_cbox_light(
        PT_FLOOR,
        CBOX_LIGHT_RECTANGLE,
        Path::new("test-scene.xml"),
        None,
    );
}

/// A crop window renders its part of the film: the cropped image's pixels against
/// Lambert's formula over the full film's pixels they stand for.
#[test]
fn a_crop_window_shows_the_floor_where_the_full_film_does() {
    assert_floor_under_the_cbox_light(
        PT_FLOOR,
        CBOX_LIGHT_RECTANGLE,
        Path::new("test-scene.xml"),
        Some(CropWindow {
            x: 3,
            y: 4,
            width: 10,
            height: 11,
        }),
    );
}

/// The side a mesh emits from is its shading normal's (Mitsuba 3's convention): the same
/// light as a quad wound to face up, with vertex normals pointing down, lights the floor.
#[test]
fn a_mesh_light_emits_towards_its_vertex_normals() {
    assert_floor_under_the_cbox_light_as_obj(
        "vn",
        "vn 0 -1 0\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\n",
    );
}

/// Densities convert between area and solid angle with the geometric normal, whatever the
/// vertex normals say: a quad light whose four vertex normals lean 25–35° apart (all still
/// facing the floor) lights it by Lambert's formula like the flat quad. Mitsuba 3 converts
/// with the shading normal, and its light sampling then disagrees with its own BSDF sampling
/// (experiments/tools/CROSSCHECK.md); this pins mltbench to the physically right answer.
#[test]
fn a_mesh_lights_densities_ignore_its_leaning_vertex_normals() {
    assert_floor_under_the_cbox_light_as_obj(
        "lean",
        "vn -0.5 -1 -0.4\nvn 0.5 -1 -0.3\nvn 0.3 -1 0.5\nvn -0.4 -1 0.4\n\
         f 1//1 2//2 3//3\nf 1//1 3//3 4//4\n",
    );
}

/// `assert_floor_under_the_cbox_light` for the Cornell box light's four corners written as
/// an OBJ, followed by `normals_and_faces` (its `vn` and `f` lines).
fn assert_floor_under_the_cbox_light_as_obj(name: &str, normals_and_faces: &str) {
    let dir = std::env::temp_dir().join(format!("mltbench-pt-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("light.obj"),
        format!(
            "v -0.23 0.99 -0.19\nv 0.23 0.99 -0.19\nv 0.23 0.99 0.19\nv -0.23 0.99 0.19\n\
             {normals_and_faces}"
        ),
    )
    .unwrap();
    assert_floor_under_the_cbox_light(
        PT_FLOOR,
        r#"<shape type="obj"><string name="filename" value="light.obj"/>"#,
        &dir.join("scene.xml"),
        None,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A closed box of diffuse walls (reflectance 0.6) lit by a small ceiling light, all moved
/// up by `dy`; direct lighting only. The camera (32×32, 20°) sees only the back wall, up to
/// 0.13 below the light's plane, where shadow rays graze it.
fn lit_box(dy: f64) -> Scene {
    let wall = |ops: &str, extra: &str| {
        format!(
            r#"<shape type="rectangle">
                <transform name="to_world">{ops}<translate y="{dy}"/></transform>
                <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>{extra}
            </shape>"#
        )
    };
    let walls = [
        r#"<rotate x="1" angle="-90"/><translate y="-1"/>"#,
        r#"<rotate x="1" angle="90"/><translate y="1"/>"#,
        r#"<translate z="-1"/>"#,
        r#"<rotate y="1" angle="90"/><translate x="-1"/>"#,
        r#"<rotate y="1" angle="-90"/><translate x="1"/>"#,
    ]
    .map(|ops| wall(ops, ""))
    .join("\n");
    let light = wall(
        r#"<scale x="0.23" y="0.19"/><rotate x="1" angle="90"/><translate y="0.99"/>"#,
        r#"<emitter type="area"><rgb name="radiance" value="10"/></emitter>"#,
    );
    scene(&format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="2"/></integrator>
            {camera}
            {walls}
            {light}
        </scene>"#,
        camera = sensor(20.0, &format!("0,{dy},3.9"), &format!("0,{dy},-1"), 32),
    ))
}

/// Moving a scene away from the origin along its light's normal changes nothing: shadow
/// rays stop short of the sampled light point by its rounding-error bound. Without that, at
/// y + 1000 light points a rounding error behind the light's plane blocked grazing shadow
/// rays (−0.8% on the image, −5% on the upper walls). Independent seeds; the mean per-pixel
/// difference within `SIGMAS` of its standard error.
#[test]
fn a_scene_far_from_the_origin_is_lit_as_at_the_origin() {
    let near = render_pt(&lit_box(0.0), &[], 256, 31);
    let far = render_pt(&lit_box(1000.0), &[], 256, 32);
    let diff: Vec<f64> = (0..near.height)
        .flat_map(|y| (0..near.width).map(move |x| (x, y)))
        .map(|(x, y)| far.get(x, y)[0] as f64 - near.get(x, y)[0] as f64)
        .collect();
    let n = diff.len() as f64;
    let mean = diff.iter().sum::<f64>() / n;
    let var = diff.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let (near_mean, _) = pixel_mean(&near, 0, |_, _| true);
    eprintln!("relative difference {:+.4}%", 100.0 * mean / near_mean);
    assert_within_sigmas("far minus near", (mean, (var / n).sqrt()), 0.0);
}

#[test]
fn floor_under_a_point_light_follows_the_inverse_square_law() {
    // E = I cos θ / d² (a delta light: next-event estimation only).
    let (rho, intensity, light) = (0.5f64, 4.0f64, Vec3::new(0.3, 0.5, -0.2));
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            {floor_camera}
            <emitter type="point"><point name="position" x="0.3" y="0.5" z="-0.2"/>
                <rgb name="intensity" value="4"/></emitter>
            {floor}
        </scene>"#,
        floor_camera = floor_camera(),
        floor = floor(0.5)
    ));
    assert_floor_lit_by_a_point(&scene, rho, intensity, light);
}

/// Pixels of the floor of albedo `rho` (`floor_camera`) under a point-like light of
/// `intensity` at `light` show ρ/π · E with E = I cos θ / d². The only randomness is the
/// position inside the pixel: within 1%.
fn assert_floor_lit_by_a_point(scene: &Scene, rho: f64, intensity: f64, light: Vec3) {
    let image = render_pt(scene, &[], 4, 9);
    for (x, y) in [(8, 8), (2, 3), (14, 12)] {
        let expected = floor_pixel_average(scene, x, y, |p| {
            let d = light - p;
            intensity * (d.y / d.length()) as f64 / d.length_squared() as f64
        }) * rho
            / std::f64::consts::PI;
        let v = image.get(x, y)[0] as f64;
        assert!(
            (v / expected - 1.0).abs() < 0.01,
            "pixel ({x},{y}) = {v}, expected {expected}"
        );
    }
}

#[test]
fn depth_parameters_are_bounded_as_in_the_scene() {
    // <integrator> refuses rr_depth 0 and max_depth below -1; so does --set.
    let scene = furnace("sphere", "0.5", "1", -1, "");
    for bad in ["rr_depth=0", "max_depth=-2"] {
        let params = Params::parse(&[bad]).unwrap();
        let error = estimator::create("pt", &params, &scene, 1)
            .err()
            .unwrap_or_else(|| panic!("{bad} accepted"))
            .to_string();
        assert!(error.contains(bad), "{error}");
    }
}

#[test]
fn a_tiny_sphere_light_is_a_point_light() {
    // A sphere of radius r and radiance L has intensity I = π r² L in every direction. At
    // r = 1e-10 its sampling densities (~1e20) square beyond f32: the MIS weight must hold.
    let (rho, intensity, light) = (0.5f64, 4.0f64, Vec3::new(0.3, 0.5, -0.2));
    let radius = 1e-10f64;
    let radiance = intensity / (std::f64::consts::PI * radius * radius);
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            {floor_camera}
            <shape type="sphere"><point name="center" x="0.3" y="0.5" z="-0.2"/>
                <float name="radius" value="{radius:e}"/>
                <emitter type="area"><rgb name="radiance" value="{radiance:e}"/></emitter></shape>
            {floor}
        </scene>"#,
        floor_camera = floor_camera(),
        floor = floor(0.5)
    ));
    assert_floor_lit_by_a_point(&scene, rho, intensity, light);
}

#[test]
fn uniform_environment_lights_a_convex_diffuse_object_to_its_albedo() {
    // A convex object never sees itself: under a constant environment L its radiance is
    // a·L for any depth ≥ 2. A glass sphere alone under the same sky is invisible.
    let sphere = |bsdf: &str| {
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                <emitter type="constant"><rgb name="radiance" value="1.5"/></emitter>
                <shape type="sphere"><point name="center" x="0.3" y="0" z="-3"/>
                    <float name="radius" value="1"/>{bsdf}</shape>
            </scene>"#,
            camera = camera()
        ))
    };
    let diffuse =
        sphere(r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.25, 0.5, 0.75"/></bsdf>"#);
    let glass = sphere(r#"<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>"#);
    let diffuse_image = render_pt(&diffuse, &[], 32, 4);
    let glass_image = render_pt(&glass, &[], 32, 4);
    for (c, a) in [0.25, 0.5, 0.75].into_iter().enumerate() {
        assert_within_sigmas(
            &format!("diffuse sphere under the sky, channel {c}"),
            pixel_mean(&diffuse_image, c, |x, y| pixel_sees_only(&diffuse, x, y, 0)),
            a * 1.5,
        );
        assert_within_sigmas(
            &format!("glass sphere under the sky, channel {c}"),
            pixel_mean(&glass_image, c, |x, y| pixel_sees_only(&glass, x, y, 0)),
            1.5,
        );
    }
}

#[test]
fn a_lamp_without_bsdf_reflects_nothing_even_inside_glass() {
    // A small sphere lamp at the centre of a glass sphere, nothing else. Mitsuba 3 gives an
    // emitting shape without a BSDF a black diffuse one. Internal reflections keep a ray's
    // distance to the centre, so a ray that misses the lamp on its first chord never hits
    // it: the image is complete at max_depth 2, and a longer depth may add only light
    // reflected by the lamp itself. A diffuse 0.5 lamp added 2% of the mean (0.47), 9 σ;
    // σ is about 0.13% of the mean with the black lamp.
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            {camera}
            <shape type="sphere"><point name="center" x="0" y="0" z="-3"/>
                <float name="radius" value="1"/>
                <bsdf type="dielectric"><float name="int_ior" value="1.5"/>
                    <float name="ext_ior" value="1"/></bsdf></shape>
            <shape type="sphere"><point name="center" x="0" y="0" z="-3"/>
                <float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
        </scene>"#,
        camera = sensor(30.0, "0,0,0", "0,0,-1", 32)
    ));
    let short = render_pt(&scene, &["max_depth=2"], 1024, 21);
    let long = render_pt(&scene, &["max_depth=8", "rr_depth=100"], 1024, 22);
    // Independent seeds, compared pixel by pixel (so that the picture itself cancels): the
    // mean difference has the standard error of the per-pixel differences.
    let diff: Vec<f64> = (0..32)
        .flat_map(|y| (0..32).map(move |x| (x, y)))
        .map(|(x, y)| (long.get(x, y)[0] - short.get(x, y)[0]) as f64)
        .collect();
    let n = diff.len() as f64;
    let mean = diff.iter().sum::<f64>() / n;
    let var = diff.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let (m_short, _) = pixel_mean(&short, 0, |_, _| true);
    assert!(
        m_short > 0.1,
        "the lamp is seen through the glass ({m_short})"
    );
    assert_within_sigmas(
        "lamp in glass, max_depth 8 minus max_depth 2",
        (mean, (var / n).sqrt()),
        0.0,
    );
}

#[test]
fn hide_emitters_removes_only_what_camera_rays_find() {
    // In the furnace the camera's first vertex adds Le; hidden, the image is
    // Le·Σ_{1≤j<d} a^j = Le·a·(1 − a^(d−1))/(1 − a), and Le·a/(1 − a) unbounded.
    let (a, le) = (0.6f64, 1.5f64);
    for (max_depth, seed) in [(1, 31), (2, 32), (4, 33), (-1, 34)] {
        let scene = furnace("sphere", "0.6", "1.5", max_depth, "");
        let image = render_pt(&scene, &["hide_emitters=true"], 64, seed);
        let expected = if max_depth < 0 {
            le * a / (1.0 - a)
        } else {
            le * a * (1.0 - a.powi(max_depth - 1)) / (1.0 - a)
        };
        assert_within_sigmas(
            &format!("hidden furnace, max_depth {max_depth}"),
            pixel_mean(&image, 1, |_, _| true),
            expected,
        );
    }

    // Under a sky of 1.5: a lamp (radiance 3, no BSDF: black), part of it behind a `null`
    // sheet, a mirror facing the camera (reflecting only sky), and a second null sheet with
    // only sky behind it. Every pixel below has
    // zero variance: what is hidden is exactly 0, what stays exactly its radiance.
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="3"/>
                <boolean name="hide_emitters" value="true"/></integrator>
            {camera}
            <emitter type="constant"><rgb name="radiance" value="1.5"/></emitter>
            <shape type="rectangle">
                <transform name="to_world"><translate x="-1" z="-3"/></transform>
                <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>
            <shape type="rectangle">
                <transform name="to_world"><scale value="0.3"/><translate x="-0.667" z="-2"/></transform>
                <bsdf type="null"/></shape>
            <shape type="rectangle">
                <transform name="to_world"><scale value="0.8"/><translate x="1.2" z="-3"/></transform>
                <bsdf type="conductor"/></shape>
            <shape type="rectangle">
                <transform name="to_world"><scale value="0.4"/><translate x="0.3" y="-1.3" z="-2"/></transform>
                <bsdf type="null"/></shape>
        </scene>"#,
        camera = sensor(90.0, "0,0,0", "0,0,-1", 32)
    ));
    let scene_ref = &scene;
    let sees = |shape: u32| move |x: u32, y: u32| pixel_sees_only(scene_ref, x, y, shape);
    let sky = |x: u32, y: u32| {
        [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .all(|&(u, v)| {
                let raster = raster_in_pixel(x, y, Vec2::new(u, v) * 0.999 + 0.0005);
                scene
                    .geometry
                    .intersect(&scene.camera.generate_ray(raster))
                    .is_none()
            })
    };
    // (what, which pixels, radiance shown, radiance with hide_emitters)
    type Case<'a> = (&'a str, &'a dyn Fn(u32, u32) -> bool, f64, f64);
    let cases: [Case; 5] = [
        ("sky seen directly", &sky, 1.5, 0.0),
        ("lamp seen directly", &sees(0), 3.0, 0.0),
        // Mitsuba 3.9 (llvm_ad_rgb) renders these two the same way: a lamp through a null
        // surface shows, the sky through one does not.
        ("lamp through a null sheet", &sees(1), 3.0, 3.0),
        ("sky in the mirror", &sees(2), 1.5, 1.5),
        ("sky through a null sheet", &sees(3), 1.5, 0.0),
    ];
    let shown = render_pt(&scene, &["hide_emitters=false"], 4, 35);
    let hidden = render_pt(&scene, &[], 4, 36);
    for (what, keep, visible, expected_hidden) in cases {
        assert_within_sigmas(what, pixel_mean(&shown, 0, keep), visible);
        assert_within_sigmas(
            &format!("{what}, hidden"),
            pixel_mean(&hidden, 0, keep),
            expected_hidden,
        );
    }
    // The preview hides them too: sky and lamp black, the lamp shaded as its black BSDF.
    let params = Params::parse::<&str>(&[]).unwrap();
    let mut eyelight = estimator::create("eyelight", &params, &scene, 37).unwrap();
    let preview = render(&scene, eyelight.as_mut(), Budget::Passes(1), |_, _| {}).image;
    for (what, keep, _, _) in &cases[..2] {
        assert_eq!(pixel_mean(&preview, 0, keep).0, 0.0, "eyelight, {what}");
    }
}

/// `pt`'s image bits and counts after `passes` passes with `params`.
fn pt_bits(scene: &Scene, params: &[&str], passes: u32, seed: u64) -> (Vec<u32>, Stats) {
    let params = Params::parse(params).unwrap();
    let mut e = estimator::create("pt", &params, scene, seed).unwrap();
    let out = render(scene, e.as_mut(), Budget::Passes(passes), |_, _| {});
    let bits = out
        .image
        .pixels
        .iter()
        .flat_map(|p| p.0.map(f32::to_bits))
        .collect();
    (bits, out.stats)
}

/// `pt` traced sixteen paths at a time in SIMD lanes (`wavefront=true`) and one at a time
/// (`wavefront=false`): the same image bits and the same counts, on every kind of scene the
/// lanes treat differently (diffuse surfaces, textured or not, and smooth mirrors and glass
/// in lanes, `twosided` diffuse ones from both sides, other BSDFs in lanes around their
/// scalar calls, `null` ones by the scalar code; small
/// scenes cast sixteen rays per test, spheres included, trees one ray at a time; mesh
/// lights sampled in lanes, other lights not; emitters hit, constant and envmap
/// environments reached, point lights, thin lenses, sample patterns, every depth rule,
/// `hide_emitters`).
#[test]
fn the_wavefront_renders_the_scalar_images_bit_for_bit() {
    let mut cases: Vec<(String, Scene, Vec<&str>)> = Vec::new();
    for file in [
        "cbox.xml",
        "cbox-dof.xml",
        "cbox-mm.xml",
        "cbox-point.xml",
        "cbox-smalllight.xml",
        "cbox-spheres.xml",
        "envmap-spheres.xml",
        "textures.xml",
        "textures-plastic.xml",
    ] {
        // 24 pixels: a full tile and a partial one per row.
        cases.push((file.to_string(), shipped_scene(file, 24), vec![]));
    }
    for params in [
        vec!["max_depth=1"],
        vec!["max_depth=2"],
        vec!["max_depth=-1", "rr_depth=1"],
        vec!["hide_emitters=true"],
        vec!["sampler=stratified", "sampler_size=16"],
    ] {
        cases.push((
            format!("cbox.xml {params:?}"),
            shipped_scene("cbox.xml", 24),
            params,
        ));
    }
    cases.push((
        "furnace".into(),
        furnace("cube", "0.8", "1", -1, ""),
        vec![],
    ));
    cases.push((
        "furnace with glass inside".into(),
        furnace(
            "sphere",
            "0.5",
            "1",
            6,
            r#"<shape type="cube"><transform name="to_world"><scale value="0.3"/></transform>
                <bsdf type="dielectric"/></shape>"#,
        ),
        vec![],
    ));
    cases.push((
        "diffuse cube under a uniform sky".into(),
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                <emitter type="constant"><rgb name="radiance" value="1.5"/></emitter>
                <shape type="cube"><transform name="to_world"><rotate y="1" angle="30"/>
                    <translate z="-3"/></transform>
                    <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></shape>
            </scene>"#,
            camera = camera()
        )),
        vec!["hide_emitters=true"],
    ));
    cases.push((
        "mesh light with vertex normals".into(),
        leaning_floor_scene("wavefront", 4, 0.5),
        vec![],
    ));
    cases.push(("point light".into(), point_light_floor().0, vec![]));
    // `twosided` diffuse panels, one seen from the front and one from behind, with
    // different front and back reflectances, lit from both sides.
    cases.push((
        "twosided panels".into(),
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                {enclosure}
                <shape type="rectangle"><transform name="to_world"><scale value="0.6"/>
                    <rotate y="1" angle="35"/><translate x="-0.5" z="-2"/></transform>
                    <bsdf type="twosided">
                        <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.5, 0.2"/></bsdf>
                        <bsdf type="diffuse"><rgb name="reflectance" value="0.1, 0.6, 0.9"/></bsdf>
                    </bsdf></shape>
                <shape type="rectangle"><transform name="to_world"><scale value="0.6"/>
                    <rotate y="1" angle="150"/><translate x="0.6" z="-2.5"/></transform>
                    <bsdf type="twosided">
                        <bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf>
                    </bsdf></shape>
            </scene>"#,
            camera = camera(),
            enclosure = enclosure("cube", "0.5", "0.8"),
        )),
        vec![],
    ));
    // Smooth specular BSDFs of every kind the lanes sample (a tinted mirror; tinted,
    // index-matched and inverted glass) beside a conductor with a complex IOR, which they
    // leave to the scalar code.
    cases.push((
        "mirrors and glass".into(),
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                {enclosure}
                {CBOX_LIGHT_RECTANGLE}<emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
                <shape type="sphere"><point name="center" x="-0.5" y="-0.5" z="-2.5"/>
                    <float name="radius" value="0.3"/>
                    <bsdf type="conductor"><string name="material" value="none"/>
                        <rgb name="specular_reflectance" value="0.9, 0.6, 0.3"/></bsdf></shape>
                <shape type="sphere"><point name="center" x="0.1" y="-0.5" z="-2.2"/>
                    <float name="radius" value="0.3"/>
                    <bsdf type="dielectric"><float name="int_ior" value="1.7"/>
                        <rgb name="specular_transmittance" value="0.5, 0.9, 0.7"/>
                        <rgb name="specular_reflectance" value="0.8"/></bsdf></shape>
                <shape type="cube"><transform name="to_world"><scale value="0.2"/>
                    <translate x="0.6" y="-0.5" z="-2.4"/></transform>
                    <bsdf type="dielectric"><float name="int_ior" value="1"/></bsdf></shape>
                <shape type="sphere"><point name="center" x="0.2" y="0.3" z="-2.6"/>
                    <float name="radius" value="0.25"/>
                    <bsdf type="dielectric"><float name="int_ior" value="1"/>
                        <float name="ext_ior" value="1.5"/></bsdf></shape>
                <shape type="sphere"><point name="center" x="-0.4" y="0.3" z="-2.7"/>
                    <float name="radius" value="0.25"/>
                    <bsdf type="conductor"><string name="material" value="Au"/></bsdf></shape>
            </scene>"#,
            camera = camera(),
            enclosure = enclosure("cube", "0.6", "0.1"),
        )),
        vec![],
    ));
    // Every other kind of BSDF, which the lanes scatter around the scalar BSDF calls
    // (`general_lanes.rs`): rough conductors (Beckmann, GGX), plastics smooth
    // and rough, a rough and a thin dielectric, Phong, Blinn and Ward, a `twosided` rough
    // conductor seen from behind; and a `null` cube, left to the scalar code.
    let general = [
        r#"<bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf>"#,
        r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>
            <float name="alpha" value="0.1"/></bsdf>"#,
        r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.5, 0.7"/></bsdf>"#,
        r#"<bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf>"#,
        r#"<bsdf type="roughdielectric"><float name="alpha" value="0.15"/></bsdf>"#,
        r#"<bsdf type="thindielectric"/>"#,
        r#"<bsdf type="phong"><float name="exponent" value="40"/></bsdf>"#,
        r#"<bsdf type="blinn"><float name="exponent" value="60"/></bsdf>"#,
        r#"<bsdf type="ward"><float name="alpha_u" value="0.2"/><float name="alpha_v" value="0.2"/></bsdf>"#,
        r#"<bsdf type="twosided"><bsdf type="roughconductor"><float name="alpha" value="0.1"/></bsdf>
            <bsdf type="diffuse"/></bsdf>"#,
        r#"<bsdf type="null"/>"#,
    ];
    let spheres: String = general
        .iter()
        .enumerate()
        .map(|(i, bsdf)| {
            let (x, y) = ((i % 4) as f32 * 0.45 - 0.7, (i / 4) as f32 * 0.45 - 0.5);
            // The twosided panel faces away from the camera.
            let (shape, place) = if bsdf.contains("twosided") {
                ("rectangle", format!(
                    r#"<transform name="to_world"><scale value="0.2"/><rotate y="1" angle="160"/>
                        <translate x="{x}" y="{y}" z="-2.5"/></transform>"#
                ))
            } else if bsdf.contains("null") {
                ("cube", format!(
                    r#"<transform name="to_world"><scale value="0.15"/>
                        <translate x="{x}" y="{y}" z="-2.5"/></transform>"#
                ))
            } else {
                ("sphere", format!(
                    r#"<point name="center" x="{x}" y="{y}" z="-2.5"/><float name="radius" value="0.2"/>"#
                ))
            };
            format!(r#"<shape type="{shape}">{place}{bsdf}</shape>"#)
        })
        .collect();
    cases.push((
        "rough and glossy BSDFs".into(),
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                {enclosure}
                {CBOX_LIGHT_RECTANGLE}<emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
                {spheres}
            </scene>"#,
            camera = camera(),
            enclosure = enclosure("cube", "0.6", "0.1"),
        )),
        vec![],
    ));
    // Sphere lights, sampled through their cones in lanes (`sphere_lanes.rs`): a small
    // and a large one seen from outside, and a third with a diffuse BSDF, so that paths
    // also scatter on an emitting sphere (sampled by area from there, by the scalar code).
    cases.push((
        "sphere lights".into(),
        scene(&format!(
            r#"<scene version="3.0.0">
                {camera}
                {enclosure}
                <shape type="sphere"><point name="center" x="-0.5" y="0.4" z="-2.5"/>
                    <float name="radius" value="0.05"/>
                    <emitter type="area"><rgb name="radiance" value="40"/></emitter></shape>
                <shape type="sphere"><point name="center" x="0.5" y="0.3" z="-2.8"/>
                    <float name="radius" value="0.3"/>
                    <emitter type="area"><rgb name="radiance" value="2, 3, 4"/></emitter></shape>
                <shape type="sphere"><point name="center" x="0" y="-0.4" z="-2.3"/>
                    <float name="radius" value="0.25"/>
                    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>
                    <emitter type="area"><rgb name="radiance" value="0.5"/></emitter></shape>
            </scene>"#,
            camera = camera(),
            enclosure = enclosure("cube", "0.6", "0"),
        )),
        vec![],
    ));
    // Cubes (12 triangles each) in the enclosure (12) with the light (2): more than a
    // small scene, cast through the tree; a glass sphere and a diffuse disk among them
    // (analytic hits beside the tree's triangles). With 6 cubes (86 triangles) the lanes
    // test full packets against every triangle and the scalar code walks the tree, which
    // must keep the same triangle wherever their edges meet (equal t); with 10 (134, more
    // than `PACKET_LIMIT`) the lanes walk the tree one ray at a time too.
    for count in [6, 10] {
        let cubes: String = (0..count)
            .map(|i| {
                format!(
                    r#"<shape type="cube"><transform name="to_world"><scale value="0.2"/>
                        <translate x="{}" y="{}" z="{}"/></transform>
                        <bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></shape>"#,
                    -0.6 + 0.25 * (i % 6) as f32,
                    -0.7 + 0.5 * (i / 6) as f32,
                    -0.5 + 0.1 * (i % 6) as f32
                )
            })
            .collect();
        cases.push((
            format!("{count} cubes in a box (a tree)"),
            scene(&format!(
                r#"<scene version="3.0.0">
                    {camera}
                    {enclosure}
                    {CBOX_LIGHT_RECTANGLE}<emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
                    {cubes}
                    <shape type="sphere"><point name="center" x="0.3" y="-0.2" z="-2.4"/>
                        <float name="radius" value="0.25"/>
                        <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf></shape>
                    <shape type="disk"><transform name="to_world"><scale value="0.3"/>
                        <rotate y="1" angle="20"/><translate x="-0.4" y="0.1" z="-2.8"/></transform>
                        <bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.6, 0.2"/></bsdf></shape>
                </scene>"#,
                camera = camera(),
                enclosure = enclosure("cube", "0.6", "0.1"),
            )),
            vec![],
        ));
    }
    for (name, scene, params) in &cases {
        let run = |wavefront: &str| {
            let mut all = params.clone();
            all.push(wavefront);
            pt_bits(scene, &all, 4, 9)
        };
        let (lanes, one_by_one) = (run("wavefront=true"), run("wavefront=false"));
        assert!(
            lanes.0.iter().any(|&b| b != 0),
            "{name}: a black image tests nothing"
        );
        assert_eq!(lanes.1, one_by_one.1, "{name}: counts");
        assert!(lanes.0 == one_by_one.0, "{name}: image bits differ");
    }
}

/// On a scene whose vertices the lanes mostly hand to the scalar code (every vertex on an
/// emitting sphere, whose emission the lanes leave to it), `pt` with `wavefront=true`
/// leaves the lanes after its first batches and goes on one path at a time: the image
/// keeps the scalar image's bits across the switch.
#[test]
fn leaving_the_lanes_part_way_keeps_the_image_bits() {
    let scene = furnace("sphere", "0.5", "1", -1, "");
    // 32 × 32 × 96 samples of about two vertices: past the 2^16 vertices after which the
    // lanes' share decides.
    let run = |wavefront: &str| pt_bits(&scene, &[wavefront], 96, 5);
    let (lanes, one_by_one) = (run("wavefront=true"), run("wavefront=false"));
    assert_eq!(lanes.1, one_by_one.1, "counts");
    assert!(lanes.0 == one_by_one.0, "image bits differ");
}
