//! The Monte Carlo lecture's quantitative claims as code that measures them. These are not
//! estimator races but small exact experiments: their spec files say `kind = "..."`, and
//! `mltbench run NAME` sends them here instead of to the experiment harness.
//!
//! Every count in a lecture spec has an upper bound (the work and memory grow with it), and
//! every error about a spec names the file and the line of the offending key.

pub mod mc_basics;
pub mod mc_basics_report;
pub mod sampling_rates;
pub mod sampling_spectra;

use std::ops::{Range, RangeInclusive};
use std::path::{Path, PathBuf};

use serde::Deserialize;
use serde::de::DeserializeOwned;
use toml::Spanned;

use crate::error::{Error, Location, Result};
use crate::experiment::spec::line_of;

/// The lecture experiments, by their `kind`.
pub const KINDS: [&str; 3] = ["mc-basics", "sampling-rates", "sampling-spectra"];

/// Whether an experiment file is a lecture experiment: it has a top-level `kind` key,
/// whatever its value (a bad value is reported by `run`, not taken for an estimator race).
pub fn is_lecture(text: &str) -> bool {
    toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("kind"))
}

/// The `description` of an experiment file, read without validating the rest.
pub fn description_of(text: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    table.get("description")?.as_str().map(str::to_string)
}

/// A lecture spec's text with its path, for errors that name both the file and the line.
#[derive(Clone, Copy)]
pub struct SpecText<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl SpecText<'_> {
    /// Deserialises the whole file (the TOML parser's messages carry their own line).
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T> {
        toml::from_str(self.text)
            .map_err(|e| Error::input(Location::file(self.path), e.to_string()))
    }

    /// An error at the value `span` covers: the file, its line and the key.
    pub fn error_at(&self, span: Range<usize>, key: &str, message: impl Into<String>) -> Error {
        Error::input(
            Location::at(self.path, line_of(self.text, span.start), key),
            message,
        )
    }

    /// A count written under `key`, checked to lie in `range`.
    pub fn count(
        &self,
        value: &Spanned<usize>,
        key: &str,
        range: RangeInclusive<usize>,
    ) -> Result<usize> {
        let v = *value.get_ref();
        if range.contains(&v) {
            Ok(v)
        } else {
            Err(self.error_at(
                value.span(),
                key,
                format!(
                    "{key} must be between {} and {}, got {v}",
                    range.start(),
                    range.end()
                ),
            ))
        }
    }
}

#[derive(Deserialize)]
struct KindOnly {
    kind: Spanned<toml::Value>,
}

/// The lecture experiment `spec_path` is, checked against `KINDS`.
fn kind(spec: SpecText) -> Result<&'static str> {
    let KindOnly { kind } = spec.parse()?;
    let known = KINDS.join(", ");
    match kind.get_ref().as_str() {
        Some(k) => KINDS.iter().copied().find(|&n| n == k).ok_or_else(|| {
            spec.error_at(
                kind.span(),
                "kind",
                format!("unknown experiment kind \"{k}\" (known: {known})"),
            )
        }),
        None => Err(spec.error_at(
            kind.span(),
            "kind",
            format!("kind must be a string, one of {known}"),
        )),
    }
}

/// Reads and checks the lecture experiment `spec_path` without running it; returns its kind.
pub fn check(spec_path: &Path, text: &str) -> Result<&'static str> {
    let spec = SpecText {
        path: spec_path,
        text,
    };
    let kind = kind(spec)?;
    match kind {
        "mc-basics" => mc_basics_report::parse(spec).map(|_| ()),
        "sampling-rates" => sampling_rates::parse(spec).map(|_| ()),
        _ => sampling_spectra::parse(spec).map(|_| ()),
    }?;
    Ok(kind)
}

/// Runs the lecture experiment described by `spec_path`, writing into
/// `results_root/NAME/`; returns its kind and that folder.
pub fn run(spec_path: &Path, text: &str, results_root: &Path) -> Result<(&'static str, PathBuf)> {
    let spec = SpecText {
        path: spec_path,
        text,
    };
    let name = spec_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("lecture");
    let out = results_root.join(name);
    let kind = kind(spec)?;
    match kind {
        "mc-basics" => mc_basics_report::run(spec, &out)?,
        "sampling-rates" => sampling_rates::run(spec, &out)?,
        _ => sampling_spectra::run(spec, &out)?,
    }
    Ok((kind, out))
}
