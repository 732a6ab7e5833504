//! Small `eyelight` renders of the shipped scenes, shared by the sampler tests.

use std::path::Path;

use mltbench::estimator::{self, Params};
use mltbench::image::Image;
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};

/// `experiments/scenes/FILE` at `res`×`res` pixels.
pub fn shipped_scene(file: &str, res: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("experiments/scenes")
        .join(file);
    let params = [("res".to_string(), res.to_string())];
    Scene::build(mitsuba::load_file_with(&path, &params).unwrap()).unwrap()
}

/// `eyelight` with the sample pattern `sampler` of `spp` samples per pixel, `spp` passes.
pub fn eyelight(scene: &Scene, sampler: &str, spp: u32, seed: u64) -> Image {
    let params =
        Params::parse(&[format!("sampler={sampler}"), format!("sampler_size={spp}")]).unwrap();
    let mut est = estimator::create("eyelight", &params, scene, seed).unwrap();
    render(scene, est.as_mut(), Budget::Passes(spp), |_, _| {}).image
}
