//! The light tracer `lt` against closed forms and against `pt` (fixed seeds; tolerances in
//! standard deviations measured from independent runs):
//!
//! * furnace: inside a closed, uniformly emitting diffuse enclosure of albedo a every pixel
//!   is Le·Σ_{j<d} a^j for `max_depth` d, Le/(1 − a) unbounded, and Le·Σ_{1≤j<d} a^j
//!   under `hide_emitters` (the emitter seen directly is the s = 1 connection);
//! * direct illumination of a floor by the Cornell box light matches Lambert's polygon
//!   formula, also through a crop window (the camera's importance is normalised over the
//!   window); under a point light and a directional light it follows E = I cos θ / d² and
//!   E cos θ; point and spot lights are invisible to the camera, as in `pt`;
//! * on the Cornell box, with a pinhole and with a thin lens, every 4×4-pixel block agrees
//!   with `pt` (Welch's t over 16 runs each, Šidák-corrected over all blocks and channels);
//! * the image does not depend on the thread count.

mod render_support;

use std::path::Path;

use glam::Vec3;
use mltbench::image::Image;
use mltbench::scene::{CropWindow, Scene};
use render_support::*;

fn render_lt(scene: &Scene, params: &[&str], passes: u32, seed: u64) -> Image {
    render_with("lt", scene, params, passes, seed)
}

/// `runs` light-tracing renders of `scene` with `passes` passes each, seeds from `seed`.
fn lt_runs(scene: &Scene, params: &[&str], runs: u64, passes: u32, seed: u64) -> Vec<Image> {
    (0..runs)
        .map(|k| render_lt(scene, params, passes, seed + k))
        .collect()
}

#[test]
fn furnace_truncated_sums_for_each_max_depth() {
    let (a, le) = (0.8f64, 1.0f64);
    for shape in ["cube", "sphere"] {
        for depth in [1, 2, 3, 5, -1] {
            let scene = furnace(shape, "0.8", "1", depth, "");
            let runs = lt_runs(&scene, &[], 8, 32, 40 + depth as u64);
            let expected: f64 = if depth < 0 {
                le / (1.0 - a)
            } else {
                (0..depth).map(|j| le * a.powi(j)).sum()
            };
            for c in 0..3 {
                assert_within_sigmas(
                    &format!("{shape} furnace, max_depth {depth}, channel {c}"),
                    image_mean_over_runs(&runs, c),
                    expected,
                );
            }
        }
    }
}

#[test]
fn hide_emitters_leaves_out_the_emitter_seen_directly() {
    let (a, le) = (0.5f64, 2.0f64);
    for depth in [1, 2, 4] {
        let scene = furnace("sphere", "0.5", "2", depth, "");
        let runs = lt_runs(&scene, &["hide_emitters=true"], 8, 8, 70 + depth as u64);
        let expected: f64 = (1..depth).map(|j| le * a.powi(j)).sum();
        let (mean, se) = image_mean_over_runs(&runs, 1);
        if depth == 1 {
            assert_eq!((mean, se), (0.0, 0.0), "nothing but the emitter at depth 1");
            continue;
        }
        assert_within_sigmas(
            &format!("hidden emitter, max_depth {depth}"),
            (mean, se),
            expected,
        );
    }
}

/// `lt` renders the floor under the Cornell box light with 1024 passes per run (a 16×16
/// film: 256 light paths a pass).
const LT_FLOOR: (&str, u32) = ("lt", 1024);

#[test]
fn floor_irradiance_under_a_rectangle_light_matches_lamberts_formula() {
    assert_floor_under_the_cbox_light(
        LT_FLOOR,
        CBOX_LIGHT_RECTANGLE,
        Path::new("test-scene.xml"),
        None,
    );
}

#[test]
fn a_crop_window_shows_the_floor_where_the_full_film_does() {
    // Light paths per pass follow the window's pixel count, and the camera's importance is
    // normalised over the window: both must hold for the cropped pixels to match.
    assert_floor_under_the_cbox_light(
        LT_FLOOR,
        CBOX_LIGHT_RECTANGLE,
        Path::new("test-scene.xml"),
        Some(CropWindow {
            x: 2,
            y: 3,
            width: 12,
            height: 10,
        }),
    );
}

/// Floor pixels (`floor_camera`) of albedo `rho` against ρ/π · E(p) averaged over each
/// pixel's footprint, with pixel means over 16 runs.
fn assert_floor_follows(scene: &Scene, rho: f64, irradiance: impl Fn(Vec3) -> f64, seed: u64) {
    let runs = lt_runs(scene, &[], 16, 512, seed);
    for (x, y) in [(8, 8), (2, 3), (14, 12), (5, 13)] {
        let expected = floor_pixel_average(scene, x, y, &irradiance) * rho / std::f64::consts::PI;
        assert_within_sigmas(
            &format!("floor pixel ({x},{y})"),
            mean_over_runs(&runs, x, y, 0),
            expected,
        );
    }
}

#[test]
fn floor_under_a_point_light_follows_the_inverse_square_law() {
    let (scene, rho, irradiance) = point_light_floor();
    assert_floor_follows(&scene, rho, irradiance, 300);
}

#[test]
fn point_and_spot_lights_are_invisible_to_the_camera() {
    // As in pt (camera rays never hit a delta light) and Mitsuba 3: a lamp in front of the
    // camera, lighting only a wall behind the camera, leaves the image black.
    for emitter in [
        r#"<emitter type="point"><point name="position" x="0" y="0" z="-2"/>
            <rgb name="intensity" value="5"/></emitter>"#,
        r#"<emitter type="spot"><transform name="to_world">
            <lookat origin="0,0,-2" target="0,0,0" up="0,1,0"/></transform>
            <rgb name="intensity" value="5"/></emitter>"#,
    ] {
        let scene = scene(&format!(
            r#"<scene version="3.0.0">{camera}{emitter}{behind}</scene>"#,
            camera = camera(),
            // Something to light, out of the camera's view.
            behind = r#"<shape type="rectangle"><transform name="to_world">
                <translate z="5"/></transform></shape>"#
        ));
        for name in ["lt", "pt"] {
            let image = render_with(name, &scene, &[], 4, 3);
            assert!(
                image.pixels.iter().all(|p| p.is_black()),
                "{name}: {emitter}"
            );
        }
    }
}

#[test]
fn floor_under_a_directional_light_receives_e_cos_theta() {
    // A light at infinity: paths start on a disk outside the scene (density 1/πR²).
    let (rho, e) = (0.7f64, 3.0f64);
    let towards = Vec3::new(0.3, -1.0, 0.2).normalize();
    let scene = scene(&format!(
        r#"<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="2"/></integrator>
            {floor_camera}
            <emitter type="directional"><vector name="direction" x="0.3" y="-1" z="0.2"/>
                <rgb name="irradiance" value="3"/></emitter>
            {floor}
        </scene>"#,
        floor_camera = floor_camera(),
        floor = floor(0.7)
    ));
    assert_floor_follows(&scene, rho, |_| e * (-towards.y) as f64, 500);
}

#[test]
fn agrees_with_pt_on_the_cornell_box_block_by_block() {
    // Every block and channel is one test; at family-wise significance 10⁻³ (Šidák over
    // all 192 of them) none may differ. Diffuse walls only, so both estimators see the
    // same paths: the emitter seen directly, and every bounce up to max_depth 8.
    for (file, seed) in [("cbox.xml", 1000), ("cbox-dof.xml", 2000)] {
        let scene = shipped_scene(file, 32);
        let lt: Vec<Image> = lt_runs(&scene, &[], 16, 64, seed);
        let pt: Vec<Image> = (0..16)
            .map(|k| render_with("pt", &scene, &[], 16, seed + 100 + k))
            .collect();
        assert_blocks_agree(file, &lt, &pt);
        // And the whole image: both means within 4 σ.
        for c in 0..3 {
            let (a, sa) = image_mean_over_runs(&lt, c);
            let (b, sb) = image_mean_over_runs(&pt, c);
            let z = (a - b) / sa.hypot(sb);
            assert!(
                z.abs() < SIGMAS,
                "{file} channel {c}: {a} against {b}, {z:.2} σ"
            );
        }
    }
}

#[test]
fn leaning_vertex_normals_on_the_receiver_give_what_pt_gives() {
    // A floor whose interpolated normals lean away from its geometric normal, under the
    // Cornell box light (direct lighting). Light tracing reaches the same pixel values as
    // path tracing only through the adjoint BSDF's shading-normal factor (Veach 1997,
    // eq. 5.19); without it the floor is off by |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|).
    let scene = leaning_floor_scene("lt-lean", 2, 0.0);
    let lt = lt_runs(&scene, &[], 16, 512, 800);
    let pt: Vec<Image> = (0..16)
        .map(|k| render_with("pt", &scene, &[], 16, 900 + k))
        .collect();
    assert_blocks_agree("leaning normals", &lt, &pt);
}

#[test]
fn one_and_two_threads_give_bit_identical_images() {
    assert_thread_count_does_not_matter("lt", 3);
}
