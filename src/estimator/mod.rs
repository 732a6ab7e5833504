//! Estimators: interchangeable ways of estimating the pixel integrals (docs/DESIGN.md §3).
//!
//! An estimator is progressive: each `run_pass` adds work, `image` is the current estimate.
//! Every random number is drawn from a seed-keyed `Sampler`, and work is cut into pieces that
//! do not depend on the thread count, so a (scene, estimator, parameters, seed, passes)
//! tuple always gives the same bits.

pub mod bdpt;
pub mod camera_pass;
pub mod eyelight;
pub mod lt;
pub mod mlt;
pub mod params;
pub mod ppm;
pub mod pt;

pub use params::Params;

use crate::error::{Error, Result};
use crate::image::Image;
use crate::sampler::pattern::Pattern;
use crate::sampler::pixel_samples::PixelSamples;
use crate::scene::Scene;

/// Counters an estimator reports; experiments read them to normalise by work done.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    pub passes: u64,
    /// Camera paths (camera-side estimators) or light paths (light tracing, photons).
    pub samples: u64,
    /// Rays cast (closest hit and shadow rays).
    pub rays: u64,
    /// Samples that came out NaN, infinite or negative: dropped, never written to the film.
    pub invalid_samples: u64,
}

pub trait Estimator: Send {
    /// The estimator's name as given on the command line (`pt`, `eyelight`, …).
    fn name(&self) -> &str;
    /// Adds one pass of work (for camera estimators: one sample per pixel).
    fn run_pass(&mut self, scene: &Scene, pass_index: u32);
    /// Adds passes `first..first + count`: the same bits as `run_pass` for each in order.
    /// Estimators that can take several passes in one go (fewer waits for the slowest
    /// thread) override it.
    fn run_passes(&mut self, scene: &Scene, first: u32, count: u32) {
        for pass in first..first + count {
            self.run_pass(scene, pass);
        }
    }
    /// The current estimate of radiance per pixel.
    fn image(&self) -> Image;
    fn stats(&self) -> Stats;
    /// True when the estimator keeps one image per bidirectional strategy (`bdpt` with
    /// `strategies=true`).
    fn keeps_strategy_images(&self) -> bool {
        false
    }
    /// Those images so far.
    fn strategy_images(&self) -> Option<Vec<bdpt::StrategyImage>> {
        None
    }
    /// What the estimator reports about itself beyond `stats`, as JSON written beside its
    /// images (the Metropolis estimators' chain diagnostics, photon mapping's map
    /// statistics); None for most.
    fn diagnostics(&self) -> Option<serde_json::Value> {
        None
    }
}

/// Names of the estimators this build knows, for `--help` and error messages.
pub const ESTIMATOR_NAMES: &[&str] = &["pt", "lt", "bdpt", "pssmlt", "mmlt", "ppm", "eyelight"];

/// Fails, listing the known names, unless `name` is one of `ESTIMATOR_NAMES`: for commands
/// to check before they load a scene.
pub fn check_name(name: &str) -> Result<()> {
    if ESTIMATOR_NAMES.contains(&name) {
        Ok(())
    } else {
        Err(unknown_estimator(name))
    }
}

fn unknown_estimator(name: &str) -> Error {
    Error::usage(format!(
        "unknown estimator '{name}' (known: {})",
        ESTIMATOR_NAMES.join(", ")
    ))
}

/// Makes the estimator called `name`, reading its parameters from `params`.
/// Fails on an unknown name or a parameter the estimator does not have.
pub fn create(name: &str, params: &Params, scene: &Scene, seed: u64) -> Result<Box<dyn Estimator>> {
    let estimator: Box<dyn Estimator> = match name {
        "eyelight" => Box::new(
            eyelight::new(scene, seed)?.with_pixel_samples(pixel_samples(params, scene, seed)?),
        ),
        "pt" => Box::new(
            pt::new(scene, seed, pt::PtSettings::from_params(params, scene)?)?
                .with_pixel_samples(pixel_samples(params, scene, seed)?),
        ),
        "lt" => Box::new(lt::new(
            scene,
            seed,
            lt::LtSettings::from_params(params, scene)?,
        )?),
        "bdpt" => Box::new(
            bdpt::new(scene, seed, bdpt::BdptSettings::from_params(params, scene)?)?
                .with_pixel_samples(pixel_samples(params, scene, seed)?),
        ),
        "pssmlt" => mlt::pssmlt(params, scene, seed)?,
        "mmlt" => Box::new(mlt::mmlt(params, scene, seed)?),
        "ppm" => Box::new(ppm::new(
            scene,
            seed,
            ppm::PpmSettings::from_params(params, scene)?,
        )?),
        _ => return Err(unknown_estimator(name)),
    };
    params.check_all_used(name)?;
    Ok(estimator)
}

/// The most points a sample pattern may have (`sampler_size`).
const MAX_PATTERN_SIZE: usize = 1 << 16;

/// The camera estimators' `sampler` (a `sampler::pattern::Pattern` name, default
/// `independent`) and `sampler_size` (points in the pattern, default the scene's
/// `<sampler sample_count>`: the spp the pattern is laid out for) parameters.
fn pixel_samples(params: &Params, scene: &Scene, seed: u64) -> Result<PixelSamples> {
    let name: String = params.get("sampler", "independent".to_string())?;
    let pattern: Pattern = name
        .parse()
        .map_err(|e: String| Error::usage(format!("--set sampler={name}: {e}")))?;
    let explicit = params.raw("sampler_size").is_some();
    let default_size = scene.description.sensor.sample_count.max(1) as usize;
    let size: usize = params.get("sampler_size", default_size)?;
    // Independent samples need no pattern: any spp works.
    if pattern == Pattern::Independent && !explicit {
        return Ok(PixelSamples::new(pattern, 1, seed));
    }
    if size == 0 || size > MAX_PATTERN_SIZE {
        return Err(if explicit {
            Error::usage(format!(
                "--set sampler_size={size}: must be between 1 and {MAX_PATTERN_SIZE}"
            ))
        } else {
            Error::usage(format!(
                "{}: the sampler's sample_count {size} is larger than the largest {name} \
                 pattern ({MAX_PATTERN_SIZE} points); pass --set sampler_size=N",
                scene.description.source.display()
            ))
        });
    }
    Ok(PixelSamples::new(pattern, size, seed))
}
