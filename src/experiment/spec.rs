//! `experiments/NAME.toml`: what an experiment compares, for how long, against what.
//!
//! ```toml
//! description = "Cornell box: the estimators agree on a diffuse scene"
//! scene = "scenes/cbox.xml"          # relative to this file
//! scene_params = { res = 128 }       # the scene's <default> parameters (Mitsuba's -D)
//! budget = { seconds = 20 }          # per run: equal time; or { passes = 256 }: equal work
//! checkpoints = 8                    # log-spaced, each doubling the budget before it
//! runs = 4                           # independent runs (seeds) per estimator
//! seed = 1                           # base seed; every run's seed derives from it
//!
//! [reference]                        # a file, or an estimator and a budget to render one
//! estimator = "pt"
//! budget = { passes = 4096 }
//!
//! [[estimator]]                      # the same estimator may appear twice, with labels
//! name = "pt"
//! label = "pt (rr 5)"
//! params = { rr_depth = 5 }
//!
//! [[region]]                         # optional crops, measured and shown zoomed
//! label = "caustic"
//! x = 40
//! y = 90
//! width = 32
//! height = 24
//!
//! [strategies]                       # optional: which bdpt strategy carries which light
//! passes = 256                       # bdpt passes (× [quick] scale), one image per (s, t)
//! params = { mis = "power" }         # optional bdpt parameters
//!
//! [quick]                            # what --quick does (defaults shown)
//! scale = 0.1                        # budgets (experiment and reference) × scale
//! runs = 2                           # at most this many runs
//! ```
//!
//! `strategies` and `strategies_max_depth`, `bdpt`'s diagnostic of `render`, are refused
//! among an estimator's params: the `[strategies]` table measures the same for a report.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use crate::error::{Error, Location, Result};
use crate::estimator::ESTIMATOR_NAMES;
use crate::render::Budget;

/// The experiment as written in its TOML file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecFile {
    description: String,
    scene: PathBuf,
    #[serde(default)]
    scene_params: BTreeMap<String, toml::Value>,
    budget: Spanned<BudgetFile>,
    checkpoints: Spanned<u32>,
    runs: Spanned<u32>,
    #[serde(default)]
    seed: u64,
    reference: Spanned<ReferenceFile>,
    #[serde(rename = "estimator")]
    estimators: Vec<Spanned<EstimatorFile>>,
    #[serde(default, rename = "region")]
    regions: Vec<Spanned<Region>>,
    strategies: Option<Spanned<StrategiesFile>>,
    quick: Option<Spanned<QuickFile>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StrategiesFile {
    passes: u32,
    #[serde(default)]
    params: BTreeMap<String, toml::Value>,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BudgetFile {
    seconds: Option<f64>,
    passes: Option<u32>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ReferenceFile {
    file: Option<PathBuf>,
    estimator: Option<String>,
    budget: Option<BudgetFile>,
    #[serde(default)]
    params: BTreeMap<String, toml::Value>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EstimatorFile {
    name: String,
    label: Option<Spanned<String>>,
    #[serde(default)]
    params: BTreeMap<String, toml::Value>,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct QuickFile {
    #[serde(default = "default_quick_scale")]
    scale: f64,
    #[serde(default = "default_quick_runs")]
    runs: u32,
}

fn default_quick_scale() -> f64 {
    0.1
}

fn default_quick_runs() -> u32 {
    2
}

impl Default for QuickFile {
    fn default() -> Self {
        QuickFile {
            scale: default_quick_scale(),
            runs: default_quick_runs(),
        }
    }
}

/// A rectangle of pixels measured on its own (e.g. a caustic).
#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub label: String,
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// One competitor: an estimator with its parameters under a unique label.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimatorEntry {
    pub name: String,
    pub label: String,
    /// `key=value` strings, as `--set` takes them.
    pub params: Vec<String>,
}

/// Where the reference comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceSource {
    File(PathBuf),
    Render {
        estimator: String,
        params: Vec<String>,
        budget: Budget,
    },
}

/// The `[strategies]` table: a `bdpt` render with one image per strategy, whose shares of
/// the image and of each region the report shows.
#[derive(Clone, Debug, PartialEq)]
pub struct StrategiesSpec {
    pub passes: u32,
    /// `key=value` strings for `bdpt`.
    pub params: Vec<String>,
}

/// A validated experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// The file stem (`cbox` for `experiments/cbox.toml`), or with `-quick` under --quick.
    pub name: String,
    /// Loaded with --quick (scaled budgets, capped runs).
    pub quick: bool,
    pub spec_path: PathBuf,
    pub description: String,
    pub scene: PathBuf,
    /// `<default>` parameters of the scene, as (name, value).
    pub scene_params: Vec<(String, String)>,
    pub budget: Budget,
    pub checkpoints: u32,
    pub runs: u32,
    pub seed: u64,
    pub reference: ReferenceSource,
    pub estimators: Vec<EstimatorEntry>,
    pub regions: Vec<Region>,
    /// The line of each `[[region]]` in the spec, for errors found once the film size is
    /// known (kept apart from `regions`, which the results' fingerprint covers).
    pub region_lines: Vec<u32>,
    pub strategies: Option<StrategiesSpec>,
}

/// The most independent runs per estimator (every run is a cell that writes its own
/// checkpoints; more belong in several experiments).
pub const MAX_RUNS: u32 = 10_000;

/// The largest number of checkpoints (each doubles the previous budget).
pub const MAX_CHECKPOINTS: u32 = 24;

impl Experiment {
    /// Reads and checks `path`. With `quick`, budgets shrink and runs are capped as its
    /// `[quick]` table says, and the name gets a `-quick` suffix (separate results).
    pub fn load(path: &Path, quick: bool) -> Result<Experiment> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Experiment::parse(&text, path, quick)
    }

    pub fn parse(text: &str, path: &Path, quick: bool) -> Result<Experiment> {
        let fail = |message: String| Error::input(Location::file(path), message);
        // An error at the value `span` covers: the file, its line and the key.
        let fail_at = |span: std::ops::Range<usize>, key: &str, message: String| {
            Error::input(Location::at(path, line_of(text, span.start), key), message)
        };
        let file: SpecFile = toml::from_str(text).map_err(|e| fail(e.to_string()))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .ok_or_else(|| fail("the experiment file needs a UTF-8 name".into()))?;

        // A count written in the file, checked to lie in 1..=max.
        let count_in = |value: &Spanned<u32>, key: &str, max: u32| {
            let v = *value.get_ref();
            if (1..=max).contains(&v) {
                Ok(v)
            } else {
                Err(fail_at(
                    value.span(),
                    key,
                    format!("{key} must be between 1 and {max}, got {v}"),
                ))
            }
        };
        let runs_written = count_in(&file.runs, "runs", MAX_RUNS)?;
        let checkpoints = count_in(&file.checkpoints, "checkpoints", MAX_CHECKPOINTS)?;
        let quick_file = file
            .quick
            .as_ref()
            .map_or_else(QuickFile::default, |q| *q.get_ref());
        if !(quick_file.scale > 0.0 && quick_file.scale <= 1.0) || quick_file.runs == 0 {
            let span = file.quick.as_ref().map_or(0..0, |q| q.span());
            return Err(fail_at(
                span,
                "[quick]",
                "[quick] needs 0 < scale <= 1 and runs >= 1".to_string(),
            ));
        }
        let scale = if quick { quick_file.scale } else { 1.0 };
        let budget = parse_budget(file.budget.get_ref(), "budget", scale)
            .map_err(|m| fail_at(file.budget.span(), "budget", m))?;
        let runs = if quick {
            runs_written.min(quick_file.runs)
        } else {
            runs_written
        };

        if file.estimators.is_empty() {
            return Err(fail("no [[estimator]]: nothing to compare".into()));
        }
        let mut estimators: Vec<EstimatorEntry> = Vec::new();
        for spanned in &file.estimators {
            let e = spanned.get_ref();
            let fail = |m: String| fail_at(spanned.span(), "[[estimator]]", m);
            check_estimator_name(&e.name).map_err(fail)?;
            let label = e
                .label
                .as_ref()
                .map_or_else(|| e.name.clone(), |l| l.get_ref().clone());
            let fail_label = |m: String| match &e.label {
                Some(l) => fail_at(l.span(), "label", m),
                None => fail(m),
            };
            if !is_safe_label(&label) {
                return Err(fail_label(format!(
                    "estimator label \"{label}\": use letters, digits, spaces and . _ - ( ) only"
                )));
            }
            if file_label(&label).starts_with('.') {
                return Err(fail_label(format!(
                    "estimator label \"{label}\" starts with a dot: its files would be hidden \
                     or, for \".\" and \"..\", land outside checkpoints/; do not start it with a dot"
                )));
            }
            if estimators
                .iter()
                .any(|o| file_label(&o.label) == file_label(&label))
            {
                return Err(fail(format!(
                    "two estimators are labelled \"{label}\" (or alike once spaces and \
                     brackets become _): give each a distinct label"
                )));
            }
            estimators.push(EstimatorEntry {
                name: e.name.clone(),
                label,
                params: params_to_strings(&e.params).map_err(fail)?,
            });
        }

        let fail_reference = |m: String| fail_at(file.reference.span(), "[reference]", m);
        let reference_file = file.reference.get_ref();
        let reference = match (&reference_file.file, &reference_file.estimator) {
            (Some(f), None) => {
                if reference_file.budget.is_some() || !reference_file.params.is_empty() {
                    return Err(fail_reference(
                        "[reference] with a file takes no budget or params".into(),
                    ));
                }
                ReferenceSource::File(dir.join(f))
            }
            (None, Some(estimator)) => {
                check_estimator_name(estimator).map_err(fail_reference)?;
                let b = reference_file.budget.ok_or_else(|| {
                    fail_reference("[reference] with an estimator needs a budget".into())
                })?;
                ReferenceSource::Render {
                    estimator: estimator.clone(),
                    params: params_to_strings(&reference_file.params).map_err(fail_reference)?,
                    budget: parse_budget(&b, "reference.budget", scale).map_err(fail_reference)?,
                }
            }
            _ => {
                return Err(fail_reference(
                    "[reference] needs either file = \"...\" or estimator = \"...\" with a budget"
                        .into(),
                ));
            }
        };

        let mut regions: Vec<Region> = Vec::new();
        let mut region_lines = Vec::new();
        for spanned in &file.regions {
            let r = spanned.get_ref();
            let fail = |m: String| fail_at(spanned.span(), "[[region]]", m);
            if r.width == 0 || r.height == 0 {
                return Err(fail(format!("region \"{}\" is empty", r.label)));
            }
            if !is_safe_label(&r.label) || regions.iter().any(|o| o.label == r.label) {
                return Err(fail(format!(
                    "region label \"{}\" must be unique and use letters, digits, spaces and . _ - ( )",
                    r.label
                )));
            }
            regions.push(r.clone());
            region_lines.push(line_of(text, spanned.span().start));
        }

        let strategies = match &file.strategies {
            None => None,
            Some(spanned) => {
                let st = spanned.get_ref();
                let fail = |m: String| fail_at(spanned.span(), "[strategies]", m);
                if st.passes == 0 {
                    return Err(fail("[strategies] needs passes >= 1".into()));
                }
                Some(StrategiesSpec {
                    passes: ((st.passes as f64 * scale).ceil() as u32).max(1),
                    params: params_to_strings(&st.params).map_err(fail)?,
                })
            }
        };

        let scene_params = file
            .scene_params
            .iter()
            .map(|(k, v)| Ok((k.clone(), value_to_string(k, v)?)))
            .collect::<std::result::Result<Vec<_>, String>>()
            .map_err(fail)?;

        Ok(Experiment {
            name: if quick {
                format!("{stem}-quick")
            } else {
                stem.to_string()
            },
            quick,
            spec_path: path.to_path_buf(),
            description: file.description.trim().to_string(),
            scene: dir.join(&file.scene),
            scene_params,
            budget,
            checkpoints,
            runs,
            seed: file.seed,
            reference,
            estimators,
            regions,
            region_lines,
            strategies,
        })
    }

    /// Checks that every region lies inside a `width`×`height` film (known once the scene
    /// is loaded, before anything renders); the error names the spec, the region's line and
    /// its label.
    pub fn check_regions(&self, width: u32, height: u32) -> Result<()> {
        for (k, r) in self.regions.iter().enumerate() {
            let right = u64::from(r.x) + u64::from(r.width);
            let bottom = u64::from(r.y) + u64::from(r.height);
            if right > u64::from(width) || bottom > u64::from(height) {
                let line = self.region_lines.get(k).copied().unwrap_or(0);
                return Err(Error::input(
                    Location::at(&self.spec_path, line, "[[region]]"),
                    format!(
                        "region \"{}\" ({}×{} at x = {}, y = {}) reaches past the scene's \
                         {width}×{height} film: it must lie inside (x + width <= {width}, \
                         y + height <= {height})",
                        r.label, r.width, r.height, r.x, r.y
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The independent cells (estimator index, run), in a fixed order: `--cell K` runs
    /// number K of this list.
    pub fn cells(&self) -> Vec<(usize, u32)> {
        (0..self.estimators.len())
            .flat_map(|e| (0..self.runs).map(move |r| (e, r)))
            .collect()
    }

    /// The budget spent by the end of checkpoint `k` (0-based): log-spaced, each checkpoint
    /// doubling the one before, the last at the full budget. Pass counts are rounded up
    /// and never repeat.
    pub fn checkpoint_budgets(&self) -> Vec<Budget> {
        let n = self.checkpoints as i32;
        match self.budget {
            Budget::Seconds(s) => (0..n)
                .map(|k| Budget::Seconds(s * 2f64.powi(k - n + 1)))
                .collect(),
            Budget::Passes(p) => {
                let mut out: Vec<u32> = Vec::new();
                for k in 0..n {
                    let passes = ((p as f64) * 2f64.powi(k - n + 1)).ceil().max(1.0) as u32;
                    if out.last() != Some(&passes) {
                        out.push(passes);
                    }
                }
                out.into_iter().map(Budget::Passes).collect()
            }
        }
    }
}

/// The 1-based line of byte `offset` in `text` (clamped to its end).
pub fn line_of(text: &str, offset: usize) -> u32 {
    let newlines = text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count();
    (1 + newlines).try_into().unwrap_or(u32::MAX)
}

fn parse_budget(b: &BudgetFile, what: &str, scale: f64) -> std::result::Result<Budget, String> {
    match (b.seconds, b.passes) {
        (Some(s), None) if s.is_finite() && s > 0.0 => Ok(Budget::Seconds(s * scale)),
        (None, Some(p)) if p > 0 => Ok(Budget::Passes(((p as f64 * scale).ceil() as u32).max(1))),
        _ => Err(format!(
            "{what} must be {{ seconds = S }} (S > 0) or {{ passes = N }} (N >= 1), not both"
        )),
    }
}

fn check_estimator_name(name: &str) -> std::result::Result<(), String> {
    if ESTIMATOR_NAMES.contains(&name) {
        Ok(())
    } else {
        Err(format!(
            "unknown estimator \"{name}\" (known: {})",
            ESTIMATOR_NAMES.join(", ")
        ))
    }
}

/// Labels become file names: keep them to a safe alphabet.
fn is_safe_label(label: &str) -> bool {
    !label.is_empty()
        && label.len() <= 64
        && label
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || " ._-()".contains(c))
}

fn params_to_strings(
    params: &BTreeMap<String, toml::Value>,
) -> std::result::Result<Vec<String>, String> {
    if let Some(key) = ["strategies", "strategies_max_depth"]
        .into_iter()
        .find(|k| params.contains_key(*k))
    {
        return Err(format!(
            "parameter \"{key}\" is a diagnostic of `mltbench render` (one image per bdpt \
             strategy); an experiment measures the strategies with a [strategies] table instead"
        ));
    }
    params
        .iter()
        .map(|(k, v)| Ok(format!("{k}={}", value_to_string(k, v)?)))
        .collect()
}

fn value_to_string(key: &str, v: &toml::Value) -> std::result::Result<String, String> {
    match v {
        toml::Value::String(s) => Ok(s.clone()),
        toml::Value::Integer(i) => Ok(i.to_string()),
        toml::Value::Float(f) => Ok(f.to_string()),
        toml::Value::Boolean(b) => Ok(b.to_string()),
        _ => Err(format!(
            "parameter \"{key}\" must be a string, number or boolean"
        )),
    }
}

/// A file-name-safe form of a label: spaces and brackets become `_`.
pub fn file_label(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
