//! Sample patterns inside pixels (`--set sampler=NAME`): on `eyelight`, whose only
//! randomness is where a sample falls in its pixel, structured patterns must converge to
//! the same image as independent offsets, with less error at equal spp on the edges.

mod eyelight_support;

use eyelight_support::{eyelight, shipped_scene};

use mltbench::estimator::{self, Params};
use mltbench::experiment::metrics::metrics;
use mltbench::scene::Scene;

fn scene() -> Scene {
    shipped_scene("cbox.xml", 32)
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

#[test]
fn a_large_sample_count_needs_a_pattern_size_only_for_patterns() {
    // A reference scene may ask for more spp than the largest pattern has points: fine for
    // independent samples; a pattern must say which scene asked and how to size it.
    let mut scene = scene();
    scene.description.sensor.sample_count = 100_000;
    assert!(estimator::create("pt", &Params::default(), &scene, 0).is_ok());
    let params = Params::parse(&["sampler=stratified"]).unwrap();
    let err = estimator::create("pt", &params, &scene, 0)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("cbox.xml") && err.contains("100000") && err.contains("sampler_size"),
        "{err}"
    );
    let params = Params::parse(&["sampler=stratified", "sampler_size=64"]).unwrap();
    assert!(estimator::create("pt", &params, &scene, 0).is_ok());
}
