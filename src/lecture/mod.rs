//! The Monte Carlo lecture's quantitative claims as code that measures them. These are not
//! estimator races but small exact experiments: their spec files say `kind = "..."`, and
//! `mltbench run NAME` sends them here instead of to the experiment harness.

pub mod mc_basics;
pub mod mc_basics_report;
pub mod sampling_rates;
pub mod sampling_spectra;

use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};

/// The `kind` of an experiment file, if it has one (lecture experiments do).
pub fn kind_of(text: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    table.get("kind")?.as_str().map(str::to_string)
}

/// The `description` of an experiment file, read without validating the rest.
pub fn description_of(text: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    table.get("description")?.as_str().map(str::to_string)
}

/// Runs the lecture experiment `kind` described by `spec_path`, writing into
/// `results_root/NAME/`; returns that folder.
pub fn run(kind: &str, spec_path: &Path, text: &str, results_root: &Path) -> Result<PathBuf> {
    let name = spec_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("lecture");
    let out = results_root.join(name);
    match kind {
        "mc-basics" => mc_basics_report::run(spec_path, text, &out)?,
        "sampling-rates" => sampling_rates::run(spec_path, text, &out)?,
        "sampling-spectra" => sampling_spectra::run(spec_path, text, &out)?,
        other => {
            return Err(Error::input(
                Location::file(spec_path),
                format!(
                    "unknown experiment kind \"{other}\" (known: mc-basics, sampling-rates, sampling-spectra)"
                ),
            ));
        }
    }
    Ok(out)
}
