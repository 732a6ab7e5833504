//! Progressive photon mapping (`ppm`, and SPPM with `stochastic=true`), fixed seeds:
//!
//! * inside an emitting diffuse sphere (the furnace), the radiance is known for every
//!   `max_depth` (Le·Σ ρ^j), and density estimation is exact there: the part of a sphere
//!   within distance R of a point on it has area πR² (Archimedes), so with the uniform
//!   photon density of the furnace the estimate's mean is the radiance at every pass. The
//!   image mean over 8 runs lies within 4 σ, for PPM and SPPM, with and without
//!   `hide_emitters`;
//! * on the Cornell box SPPM converges to a long `pt` image: its relMSE falls with passes
//!   at a log-log slope between −0.9 and −0.45 (theory −2/3 for α = 2/3, Knaus and
//!   Zwicker 2011), and its bias (the mean of 4 runs' error) falls too;
//! * bit-identical images for 1 and 2 threads; bad parameters and a scene without a light
//!   are errors naming them.

mod render_support;

use mltbench::estimator::{self, Params};
use mltbench::experiment::metrics::metrics;
use mltbench::image::Image;
use mltbench::scene::Scene;
use render_support::*;

const PHOTONS: &str = "photons=20000";

fn ppm_runs(scene: &Scene, params: &[&str], runs: u64, passes: u32, seed: u64) -> Vec<Image> {
    (0..runs)
        .map(|k| render_with("ppm", scene, params, passes, seed + k))
        .collect()
}

#[test]
fn furnace_radiance_for_each_max_depth() {
    let (a, le) = (0.5f64, 2.0f64);
    for stochastic in ["stochastic=false", "stochastic=true"] {
        for depth in [1, 2, 3, -1] {
            let scene = furnace("sphere", "0.5", "2", depth, "");
            let runs = ppm_runs(&scene, &[PHOTONS, stochastic], 8, 4, 10 + depth as u64);
            let expected: f64 = if depth < 0 {
                le / (1.0 - a)
            } else {
                (0..depth).map(|j| le * a.powi(j)).sum()
            };
            for c in 0..3 {
                assert_within_sigmas(
                    &format!("{stochastic}, max_depth {depth}, channel {c}"),
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
    for depth in [2, 4] {
        let scene = furnace("sphere", "0.5", "2", depth, "");
        let runs = ppm_runs(
            &scene,
            &[PHOTONS, "stochastic=true", "hide_emitters=true"],
            8,
            4,
            30 + depth as u64,
        );
        let expected: f64 = (1..depth).map(|j| le * a.powi(j)).sum();
        assert_within_sigmas(
            &format!("hidden emitter, max_depth {depth}"),
            image_mean_over_runs(&runs, 1),
            expected,
        );
    }
}

/// relMSE against passes, one run: the least-squares slope of log relMSE over log passes.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.0.ln() / n, y + p.1.ln() / n));
    let sxy: f64 = points
        .iter()
        .map(|p| (p.0.ln() - mx) * (p.1.ln() - my))
        .sum();
    let sxx: f64 = points.iter().map(|p| (p.0.ln() - mx).powi(2)).sum();
    sxy / sxx
}

#[test]
fn sppm_converges_on_the_cornell_box_at_the_predicted_rate() {
    let scene = shipped_scene("cbox.xml", 32);
    let reference = render_with("pt", &scene, &[], 16384, 1);
    let checkpoints = [8u32, 16, 32, 64, 128];
    let runs = 4;
    // relMSE of each run at each checkpoint, and the mean image's (its bias part).
    let mut rel = vec![0.0; checkpoints.len()];
    let mut mean_images: Vec<Image> = Vec::new();
    for run in 0..runs {
        let params = Params::parse(&["stochastic=true", PHOTONS]).unwrap();
        let mut e = estimator::create("ppm", &params, &scene, 50 + run).unwrap();
        let mut done = 0;
        for (k, &passes) in checkpoints.iter().enumerate() {
            for pass in done..passes {
                e.run_pass(&scene, pass);
            }
            done = passes;
            let image = e.image();
            rel[k] += metrics(&image, &reference).unwrap().relmse / runs as f64;
            if run == 0 {
                mean_images.push(image);
            } else {
                for (m, p) in mean_images[k].pixels.iter_mut().zip(&image.pixels) {
                    *m += *p;
                }
            }
        }
    }
    let bias: Vec<f64> = mean_images
        .iter()
        .map(|m| {
            let mut m = m.clone();
            for p in &mut m.pixels {
                *p *= 1.0 / runs as f32;
            }
            metrics(&m, &reference).unwrap().relmse
        })
        .collect();
    let points: Vec<(f64, f64)> = checkpoints
        .iter()
        .zip(&rel)
        .skip(1)
        .map(|(&p, &r)| (p as f64, r))
        .collect();
    let s = slope(&points);
    eprintln!("relMSE {rel:?}, of the mean image {bias:?}, slope {s:.3}");
    assert!((-0.9..=-0.45).contains(&s), "slope {s}");
    assert!(
        bias.last().unwrap() < &(0.5 * bias[0]),
        "bias {bias:?} does not fall"
    );
}

#[test]
fn one_and_two_threads_give_the_same_bits() {
    let scene = shipped_scene("cbox-spheres.xml", 24);
    for stochastic in ["stochastic=false", "stochastic=true"] {
        let render = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render_with("ppm", &scene, &[PHOTONS, stochastic], 3, 9))
        };
        assert!(render(1) == render(2), "{stochastic}");
    }
}

#[test]
fn bad_parameters_are_refused_naming_them() {
    let scene = shipped_scene("cbox.xml", 8);
    for (param, expected) in [
        ("alpha=0", "alpha"),
        ("alpha=1", "alpha"),
        ("alpha=1.5", "alpha"),
        ("alpha=nan", "alpha"),
        ("photons=0", "photons"),
        ("radius=0", "radius"),
        ("radius=-1", "radius"),
        ("radius=inf", "radius"),
        ("radius=NaN", "radius"),
        ("radius=large", "radius"),
        ("wavefront=false", "wavefront"),
    ] {
        let err = estimator::create("ppm", &Params::parse(&[param]).unwrap(), &scene, 1)
            .err()
            .unwrap_or_else(|| panic!("ppm {param} accepted"))
            .to_string();
        assert!(err.contains(expected), "{param}: {err}");
    }
    let xml = format!(
        r#"<scene version="3.0.0">{}<shape type="sphere"><float name="radius" value="1"/></shape></scene>"#,
        camera()
    );
    let err = estimator::create("ppm", &Params::default(), &render_support::scene(&xml), 1)
        .err()
        .expect("a scene without light")
        .to_string();
    assert!(
        err.contains("test-scene.xml") && err.contains("no light"),
        "{err}"
    );
}
