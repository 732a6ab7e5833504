//! References: the long renders every error is measured against, with their own noise.
//!
//! A rendered reference is two independent halves (different seeds, half the budget each),
//! averaged. Their difference estimates the reference's own error (`metrics::
//! reference_noise`): an estimator's error below it cannot be told apart from the
//! reference's, and reports flag it. References are cached under `results/references/`,
//! keyed by a hash of every scene file read, the scene parameters, the estimator, its
//! parameters, the budget, the seed and the mltbench version: change any of them and a new
//! reference is rendered.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::metrics::reference_noise;
use crate::error::{Error, Location, Result};
use crate::estimator::{self, Params};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::exr::{read_exr, write_exr};
use crate::io::png::write_png_preview;
use crate::render::{Budget, Progress, advance};
use crate::sampler::independent::hash_words;
use crate::scene::Scene;

/// What is stored beside a reference EXR (`NAME.json`). A key it does not know is refused
/// when read: a misspelt `noise_relmse` would otherwise pass unnoticed.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReferenceInfo {
    /// The cache key (hex) the reference was rendered for; empty for a file given by hand.
    pub key: String,
    pub scene: String,
    pub estimator: String,
    pub params: Vec<String>,
    pub passes: u64,
    pub samples: u64,
    pub seconds: f64,
    pub seed: u64,
    /// The reference's own relMSE, estimated from its two halves (`None`: unknown).
    pub noise_relmse: Option<f64>,
}

/// A reference image and what is known about it.
#[derive(Clone, Debug)]
pub struct Reference {
    pub image: Image,
    pub info: ReferenceInfo,
    pub path: PathBuf,
}

/// How the two halves are seeded: far from any run's seed.
const HALF_SEED_TAG: u64 = 0x5EF0_5EF0;

/// Renders `scene` with `estimator` as two independent halves of `budget` and averages them
/// (weighted by their samples). The halves take their passes in turn, so that both always
/// hold the same number: a time budget gives each half of it, and a stop request
/// (`interrupt`, after at least one pass each) leaves two equal halves of the passes done.
/// Each half's image is the one it would give alone (its passes do not depend on the
/// other's). `on_pass(half, passes done)` reports progress.
pub fn render_reference(
    scene: &Scene,
    estimator_name: &str,
    params: &[String],
    budget: Budget,
    seed: u64,
    mut on_pass: impl FnMut(usize, u32),
) -> Result<(Image, ReferenceInfo)> {
    let mut estimators = Vec::new();
    for half in 0..2u64 {
        let params = Params::parse(params)?;
        let half_seed = hash_words(&[seed, HALF_SEED_TAG, half]);
        estimators.push(estimator::create(
            estimator_name,
            &params,
            scene,
            half_seed,
        )?);
    }
    // Passes are counted per half; time is shared by both.
    let per_half = match budget {
        Budget::Passes(p) => Budget::Passes(p.div_ceil(2)),
        seconds => seconds,
    };
    // Both halves take every chunk of passes in turn (`render::advance`), so that a stop
    // request leaves them at the same pass.
    let start = Instant::now();
    let mut progress = Progress::default();
    let run_both = |first, count| {
        for half in estimators.iter_mut() {
            half.run_passes(scene, first, count);
        }
    };
    advance(run_both, per_half, &mut progress, true, |p| {
        on_pass(1, p.passes)
    });
    let seconds = start.elapsed().as_secs_f64();
    let (mut passes, mut samples) = (0u64, 0u64);
    let mut halves = Vec::new();
    for est in &estimators {
        let stats = est.stats();
        passes += stats.passes;
        samples += stats.samples;
        halves.push((est.image(), stats.samples.max(1) as f64));
    }
    let (a, wa) = &halves[0];
    let (b, wb) = &halves[1];
    let mut image = Image::new(a.width, a.height);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        *p = (a.pixels[i] * (*wa as f32) + b.pixels[i] * (*wb as f32)) / ((wa + wb) as f32);
    }
    let noise = reference_noise(a, b)?;
    Ok((
        image,
        ReferenceInfo {
            key: String::new(),
            scene: String::new(),
            estimator: estimator_name.to_string(),
            params: params.to_vec(),
            passes,
            samples,
            seconds,
            seed,
            noise_relmse: Some(noise),
        },
    ))
}

/// The cache key of a rendered reference (see the module docs).
pub fn cache_key(
    scene: &Scene,
    scene_params: &[(String, String)],
    estimator_name: &str,
    params: &[String],
    budget: Budget,
    seed: u64,
) -> Result<String> {
    let mut words: Vec<u64> = vec![seed];
    let mut add_bytes = |bytes: &[u8]| {
        words.push(bytes.len() as u64);
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            words.push(u64::from_le_bytes(w));
        }
    };
    let mut files = scene.description.files_read.clone();
    files.sort();
    files.dedup();
    for f in &files {
        let bytes = std::fs::read(f).map_err(|e| Error::io(f, e))?;
        add_bytes(&bytes);
    }
    for (k, v) in scene_params {
        add_bytes(format!("{k}={v}").as_bytes());
    }
    add_bytes(estimator_name.as_bytes());
    for p in params {
        add_bytes(p.as_bytes());
    }
    add_bytes(format!("{budget:?}").as_bytes());
    add_bytes(env!("CARGO_PKG_VERSION").as_bytes());
    Ok(format!("{:016x}", hash_words(&words)))
}

/// Writes a reference EXR, its PNG preview and its `.json` information, atomically.
pub fn save(path: &Path, image: &Image, info: &ReferenceInfo) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    write_exr(path, image)?;
    write_png_preview(&path.with_extension("png"), image)?;
    let json = serde_json::to_string_pretty(info).expect("reference info serialises");
    write_file_atomically(&path.with_extension("json"), json.as_bytes())
}

/// Reads a reference EXR and, if present, the `.json` beside it.
pub fn load(path: &Path) -> Result<Reference> {
    let image = read_exr(path)?;
    if let Some((i, _)) = image
        .pixels
        .iter()
        .enumerate()
        .find(|(_, p)| !p.is_valid_radiance())
    {
        return Err(Error::input(
            Location::file(path),
            format!(
                "reference pixel ({}, {}) is not a finite, non-negative radiance",
                i as u32 % image.width,
                i as u32 / image.width
            ),
        ));
    }
    let json_path = path.with_extension("json");
    let info = if json_path.exists() {
        let text = std::fs::read_to_string(&json_path).map_err(|e| Error::io(&json_path, e))?;
        let info: ReferenceInfo = serde_json::from_str(&text).map_err(|e| {
            Error::input(
                Location::file(&json_path),
                format!("not a reference description: {e}"),
            )
        })?;
        for (key, value) in [
            ("noise_relmse", info.noise_relmse.unwrap_or(0.0)),
            ("seconds", info.seconds),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::input(
                    Location::file(&json_path),
                    format!("{key} must be finite and non-negative, got {value}"),
                ));
            }
        }
        info
    } else {
        ReferenceInfo {
            key: String::new(),
            scene: String::new(),
            estimator: "(given)".into(),
            params: Vec::new(),
            passes: 0,
            samples: 0,
            seconds: 0.0,
            seed: 0,
            noise_relmse: None,
        }
    };
    Ok(Reference {
        image,
        info,
        path: path.to_path_buf(),
    })
}
