//! The experiment harness (docs/DESIGN.md §5–6): named experiments pit estimators against a long
//! reference at equal time or equal work, over independent runs, and report errors,
//! convergence slopes, efficiency, bias and variance as CSV, JSON, plots and a README.
//!
//! * `spec`: the `experiments/NAME.toml` format;
//! * `reference`: rendering, caching and loading references, with their own noise;
//! * `runner`: one (estimator, run) cell from checkpoint to checkpoint, its files;
//! * `metrics`, `statistics`: the error measures and the statistics over runs;
//! * `plot`: convergence and bias plots, the contact sheet;
//! * `report`: merges whatever cells are present into the summary and the README;
//! * `strategies`: the optional `[strategies]` table, which bdpt strategy carries what.

pub mod chain_diagnostics;
pub mod metrics;
pub mod photon_diagnostics;
pub mod plot;
pub mod reference;
pub mod report;
pub mod runner;
pub mod spec;
pub mod statistics;
pub mod strategies;

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::error::{Error, Result};
use crate::render::Budget;
pub use report::Summary;
use runner::ResultsDir;
pub use spec::Experiment;

/// Where experiments are looked up by name: `experiments/` under the working directory,
/// then under the source tree mltbench was built from.
pub fn experiment_dirs() -> Vec<PathBuf> {
    vec![
        PathBuf::from("experiments"),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments"),
    ]
}

/// The spec file for `name_or_path`: a path to a `.toml` file, or the name of one in
/// `experiment_dirs()`.
pub fn find_experiment(name_or_path: &str) -> Result<PathBuf> {
    let as_path = Path::new(name_or_path);
    if name_or_path.ends_with(".toml") || as_path.components().count() > 1 {
        return if as_path.is_file() {
            Ok(as_path.to_path_buf())
        } else {
            Err(Error::usage(format!("no experiment file {name_or_path}")))
        };
    }
    for dir in experiment_dirs() {
        let candidate = dir.join(format!("{name_or_path}.toml"));
        if candidate.is_file() {
            return Ok(candidate);
        }
    }
    let known: Vec<String> = list_experiments()
        .unwrap_or_default()
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    Err(Error::usage(format!(
        "no experiment named \"{name_or_path}\" (known: {})",
        known.join(", ")
    )))
}

/// (name, description) of every experiment in the first of `experiment_dirs()` that exists.
pub fn list_experiments() -> Result<Vec<(String, String)>> {
    let Some(dir) = experiment_dirs().into_iter().find(|d| d.is_dir()) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).map_err(|e| Error::io(&dir, e))? {
        let path = entry.map_err(|e| Error::io(&dir, e))?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("")
            .to_string();
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let description = if crate::lecture::is_lecture(&text) {
            crate::lecture::description_of(&text).unwrap_or_default()
        } else {
            match Experiment::load(&path, false) {
                Ok(e) => e.description.lines().next().unwrap_or("").to_string(),
                Err(err) => format!("(cannot be read: {err})"),
            }
        };
        out.push((name, description));
    }
    out.sort();
    Ok(out)
}

/// How `run` runs.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The `results/` folder.
    pub results_root: PathBuf,
    /// Delete earlier results first instead of resuming: the whole experiment's, or with
    /// `cell` only that cell's own files.
    pub fresh: bool,
    /// Run only this cell (`Experiment::cells` index) and write only its files.
    pub cell: Option<usize>,
    /// Stop with an error after this many checkpoints (all cells together), as a kill
    /// between checkpoints would: lets tests interrupt a run at a known point.
    pub stop_after_checkpoints: Option<usize>,
}

/// Runs the experiment's cells that are not complete yet (or only `options.cell`), then,
/// unless a single cell was asked for, writes the report. Returns the summary if reported.
pub fn run(
    experiment: &Experiment,
    options: &RunOptions,
    bar: &ProgressBar,
) -> Result<Option<Summary>> {
    let results = ResultsDir::new(&options.results_root, experiment);
    let cells = experiment.cells();
    let selected: Vec<(usize, u32)> = match options.cell {
        Some(k) => vec![*cells.get(k).ok_or_else(|| {
            Error::usage(format!(
                "{} has {} cells (0..{}); --cell {k} is out of range",
                experiment.name,
                cells.len(),
                cells.len()
            ))
        })?],
        None => cells.clone(),
    };
    bar.set_message(format!("{}: loading the scene", experiment.name));
    let scene = runner::load_scene(experiment)?;
    let fingerprint = runner::fingerprint(experiment, &scene)?;
    // --fresh on the whole experiment clears it all; with --cell K only cell K's own
    // files go (a Slurm array run with --fresh must not wipe the cells of its other tasks),
    // and then only if the other cells' results were made from this same experiment.
    if options.fresh && options.cell.is_none() {
        runner::clear_results(&results)?;
    }
    runner::check_fingerprint(&results, &fingerprint)?;
    if options.fresh && options.cell.is_some() {
        for &(e, r) in &selected {
            runner::clear_cell(experiment, &results, e, r)?;
        }
    }
    let reference = runner::obtain_reference(experiment, &scene, &options.results_root, bar)?;
    if options.cell.is_none() {
        strategies::ensure(experiment, &scene, &results, bar)?;
    }

    let todo: Vec<(usize, u32)> = selected
        .into_iter()
        .map(|(e, r)| {
            Ok((
                (e, r),
                runner::cell_is_complete(experiment, &results, e, r)?,
            ))
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .filter(|(_, done)| !done)
        .map(|(cell, _)| cell)
        .collect();
    let per_cell = match experiment.budget {
        Budget::Passes(p) => p as u64,
        Budget::Seconds(s) => (s * 1000.0) as u64,
    };
    bar.set_length(per_cell * todo.len() as u64);
    bar.set_position(0);
    let mut checkpoints_done = 0usize;
    let mut after_checkpoint = || {
        checkpoints_done += 1;
        match options.stop_after_checkpoints {
            Some(n) if checkpoints_done >= n => Err(Error::usage(format!(
                "{}: interrupted after {n} checkpoints, as asked",
                experiment.name
            ))),
            _ => Ok(()),
        }
    };
    for (e, r) in todo {
        runner::run_cell(
            experiment,
            &scene,
            &reference,
            &results,
            (e, r),
            bar,
            &mut after_checkpoint,
        )?;
    }
    if options.cell.is_some() {
        return Ok(None);
    }
    bar.set_message(format!("{}: writing the report", experiment.name));
    report::report(experiment, &results, &reference).map(Some)
}

/// For each of the experiment's cells (`Experiment::cells` order), whether its rows and final
/// image under `results_root` are complete, so that a scheduler queues only the others.
pub fn cells_complete(experiment: &Experiment, results_root: &Path) -> Result<Vec<bool>> {
    let results = ResultsDir::new(results_root, experiment);
    experiment
        .cells()
        .into_iter()
        .map(|(e, r)| runner::cell_is_complete(experiment, &results, e, r))
        .collect()
}

/// Merges the cells present under `results/NAME/` into the summary, plots and README.
pub fn report_only(
    experiment: &Experiment,
    results_root: &Path,
    bar: &ProgressBar,
) -> Result<Summary> {
    let results = ResultsDir::new(results_root, experiment);
    let scene = runner::load_scene(experiment)?;
    runner::check_fingerprint(&results, &runner::fingerprint(experiment, &scene)?)?;
    let reference = runner::obtain_reference(experiment, &scene, results_root, bar)?;
    report::report(experiment, &results, &reference)
}

/// Makes sure the experiment's reference exists (rendering it if needed): run once before
/// spreading cells over several machines, so that they do not each render it.
pub fn prepare(experiment: &Experiment, options: &RunOptions, bar: &ProgressBar) -> Result<()> {
    let results = ResultsDir::new(&options.results_root, experiment);
    let scene = runner::load_scene(experiment)?;
    let fingerprint = runner::fingerprint(experiment, &scene)?;
    if options.fresh {
        runner::clear_results(&results)?;
    }
    runner::check_fingerprint(&results, &fingerprint)?;
    runner::obtain_reference(experiment, &scene, &options.results_root, bar)?;
    strategies::ensure(experiment, &scene, &results, bar)
}
