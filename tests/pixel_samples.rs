//! Sample patterns inside pixels (`--set sampler=NAME`): on `eyelight`, whose only
//! randomness is where a sample falls in its pixel, structured patterns must converge to
//! the same image as independent offsets, with less error at equal spp on the edges.

use std::path::Path;

use mltbench::estimator::{self, Params};
use mltbench::experiment::metrics::metrics;
use mltbench::image::Image;
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};

fn scene() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/cbox.xml");
    let params = [("res".to_string(), "32".to_string())];
    Scene::build(mitsuba::load_file_with(&path, &params).unwrap()).unwrap()
}

fn eyelight(scene: &Scene, sampler: &str, spp: u32, seed: u64) -> Image {
    let params =
        Params::parse(&[format!("sampler={sampler}"), format!("sampler_size={spp}")]).unwrap();
    let mut est = estimator::create("eyelight", &params, scene, seed).unwrap();
    render(scene, est.as_mut(), Budget::Passes(spp), |_, _| {}).image
}

#[test]
fn structured_pixel_samples_beat_independent_ones_and_agree_with_them() {
    let scene = scene();
    let reference = eyelight(&scene, "sobol", 4096, 1);
    // Mean relMSE over 4 seeds at 16 spp.
    let error = |sampler: &str| {
        (0..4)
            .map(|s| {
                metrics(&eyelight(&scene, sampler, 16, 10 + s), &reference)
                    .unwrap()
                    .relmse
            })
            .sum::<f64>()
            / 4.0
    };
    let independent = error("independent");
    for sampler in ["stratified", "poisson", "ccvt", "sobol"] {
        let e = error(sampler);
        eprintln!("{sampler}: relMSE {e:.3e} (independent {independent:.3e})");
        assert!(e < 0.75 * independent, "{sampler}: {e} vs {independent}");
    }
    // Unbiased: at 1024 spp every pattern is as close to the reference as independent
    // offsets are (the reference itself uses Sobol' points).
    let far = metrics(&eyelight(&scene, "independent", 1024, 3), &reference)
        .unwrap()
        .relmse;
    for sampler in ["stratified", "poisson", "ccvt"] {
        let e = metrics(&eyelight(&scene, sampler, 1024, 3), &reference)
            .unwrap()
            .relmse;
        assert!(e < 2.0 * far, "{sampler}: {e} vs independent {far}");
    }
}

#[test]
fn an_unknown_sampler_is_an_error() {
    let scene = scene();
    let params = Params::parse(&["sampler=halton"]).unwrap();
    let err = estimator::create("pt", &params, &scene, 0)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("halton") && err.contains("stratified"),
        "{err}"
    );
}
