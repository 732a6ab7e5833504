//! Running an experiment's cells: each (estimator, run) renders with its own seed, stops
//! at log-spaced checkpoints, and measures its image against the reference there.
//!
//! Files under `results/NAME/` (docs/DESIGN.md §6), each written atomically:
//! * `cells/LABEL-runR.csv`: the cell's rows so far (one per checkpoint and region; the
//!   whole image is region ""), rewritten after every checkpoint;
//! * `checkpoints/LABEL/runR-cpK.exr`: the image at each checkpoint (bias and variance are
//!   computed across runs at equal checkpoints; not committed);
//! * `images/LABEL-runR.exr` (+ `.png` for run 0): the final image;
//! * `fingerprint.txt`: what the results were made from; a rerun with a changed experiment
//!   stops with an error instead of mixing results (use `--fresh`).
//!
//! Resuming: a cell whose rows and final image are complete is skipped; an unfinished cell
//! is rendered again from its first pass. With a pass budget that replays it bit for bit
//! (the rows it had already written come out the same); with a time budget its checkpoints
//! are retaken.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use super::metrics::{Region as MetricRegion, metrics, metrics_in};
use super::reference::{self, Reference};
use super::spec::{Experiment, ReferenceSource, file_label};
use crate::error::{Error, Location, Result};
use crate::estimator::{self, Params};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::exr::write_exr;
use crate::io::png::write_png_preview;
use crate::render::{Budget, Progress, advance};
use crate::sampler::independent::hash_words;
use crate::scene::{Scene, mitsuba};

/// The header of `metrics.csv` and of every cell file (docs/DESIGN.md §6, plus `region`).
pub const CSV_HEADER: &str =
    "estimator,run,checkpoint,seconds,passes,samples,region,relmse,rmse,mape";

/// One measurement: an estimator's image at a checkpoint, over the whole image
/// (`region` empty) or one region.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub estimator: String,
    pub run: u32,
    pub checkpoint: u32,
    /// Time spent in the estimator's passes (not in measuring or writing).
    pub seconds: f64,
    pub passes: u64,
    pub samples: u64,
    pub region: String,
    pub relmse: f64,
    pub rmse: f64,
    pub mape: f64,
}

impl Row {
    pub fn to_csv(&self) -> String {
        format!(
            "{},{},{},{:.6},{},{},{},{:.9e},{:.9e},{:.9e}",
            self.estimator,
            self.run,
            self.checkpoint,
            self.seconds,
            self.passes,
            self.samples,
            self.region,
            self.relmse,
            self.rmse,
            self.mape
        )
    }

    /// Parses one line of a cell or metrics file; errors name `path` and the line. Counts
    /// must fit their types and times and metrics must be finite and non-negative.
    pub fn from_csv(line: &str, path: &Path, line_no: usize) -> Result<Row> {
        let fail = |what: String| {
            Error::input(
                Location {
                    file: path.to_path_buf(),
                    line: Some(line_no.try_into().unwrap_or(u32::MAX)),
                    element: None,
                },
                format!("not an mltbench results row ({what}): \"{line}\""),
            )
        };
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 10 {
            return Err(fail("expected 10 fields".into()));
        }
        const NAMES: [&str; 10] = [
            "estimator",
            "run",
            "checkpoint",
            "seconds",
            "passes",
            "samples",
            "region",
            "relmse",
            "rmse",
            "mape",
        ];
        let num = |i: usize| match f[i].parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
            Ok(v) => Err(fail(format!(
                "{} is {v}: it must be a finite number >= 0",
                NAMES[i]
            ))),
            Err(_) => Err(fail(format!("{} is not a number", NAMES[i]))),
        };
        let int = |i: usize, max: u64| match f[i].parse::<u64>() {
            Ok(v) if v <= max => Ok(v),
            _ => Err(fail(format!(
                "{} must be an integer from 0 to {max}",
                NAMES[i]
            ))),
        };
        let small = |i: usize| int(i, u64::from(u32::MAX)).map(|v| v as u32);
        Ok(Row {
            estimator: f[0].to_string(),
            run: small(1)?,
            checkpoint: small(2)?,
            seconds: num(3)?,
            passes: int(4, u64::MAX)?,
            samples: int(5, u64::MAX)?,
            region: f[6].to_string(),
            relmse: num(7)?,
            rmse: num(8)?,
            mape: num(9)?,
        })
    }
}

/// Reads a CSV file of rows written by `write_rows`.
pub fn read_rows(path: &Path) -> Result<Vec<Row>> {
    read_rows_checked(path, |_| Ok(()))
}

/// Reads a CSV file of rows, with `check` run on each row; its message is reported with the
/// file and the row's line.
fn read_rows_checked(
    path: &Path,
    mut check: impl FnMut(&Row) -> std::result::Result<(), String>,
) -> Result<Vec<Row>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut lines = text.lines();
    if lines.next() != Some(CSV_HEADER) {
        return Err(Error::input(
            Location::file(path),
            format!("not an mltbench results file: the first line must be \"{CSV_HEADER}\""),
        ));
    }
    lines
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let row = Row::from_csv(l, path, i + 2)?;
            check(&row).map_err(|m| {
                let line = (i + 2).try_into().unwrap_or(u32::MAX);
                Error::input(
                    Location {
                        file: path.to_path_buf(),
                        line: Some(line),
                        element: None,
                    },
                    m,
                )
            })?;
            Ok(row)
        })
        .collect()
}

/// The rows of cell (estimator `e`, run `r`), each checked to belong to it: its label and
/// run, a checkpoint the experiment has and a region it defines (or none).
pub fn read_cell_rows(
    experiment: &Experiment,
    results: &ResultsDir,
    e: usize,
    r: u32,
) -> Result<Vec<Row>> {
    let label = &experiment.estimators[e].label;
    let checkpoints = experiment.checkpoint_budgets().len();
    let mut seen = std::collections::HashSet::new();
    read_rows_checked(&results.cell_csv(label, r), |row| {
        if row.estimator != *label || row.run != r {
            return Err(format!(
                "a row of {label} run {r} names {} run {}",
                row.estimator, row.run
            ));
        }
        if row.checkpoint as usize >= checkpoints {
            return Err(format!(
                "checkpoint {} is out of range: the experiment's are numbered 0 to {}",
                row.checkpoint,
                checkpoints - 1
            ));
        }
        if !seen.insert((row.checkpoint, row.region.clone())) {
            return Err(format!(
                "checkpoint {} (region \"{}\") appears twice",
                row.checkpoint, row.region
            ));
        }
        if !row.region.is_empty() && !experiment.regions.iter().any(|g| g.label == row.region) {
            return Err(format!(
                "region \"{}\" is not one of the experiment's",
                row.region
            ));
        }
        Ok(())
    })
}

/// Writes rows with the header, atomically.
pub fn write_rows(path: &Path, rows: &[Row]) -> Result<()> {
    let mut text = String::from(CSV_HEADER);
    text.push('\n');
    for r in rows {
        text.push_str(&r.to_csv());
        text.push('\n');
    }
    write_file_atomically(path, text.as_bytes())
}

/// Where an experiment's files go.
#[derive(Clone, Debug)]
pub struct ResultsDir {
    pub root: PathBuf,
    pub dir: PathBuf,
}

impl ResultsDir {
    pub fn new(results_root: &Path, experiment: &Experiment) -> ResultsDir {
        ResultsDir {
            root: results_root.to_path_buf(),
            dir: results_root.join(&experiment.name),
        }
    }

    pub fn cell_csv(&self, label: &str, run: u32) -> PathBuf {
        self.dir
            .join("cells")
            .join(format!("{}-run{run}.csv", file_label(label)))
    }

    /// The estimator's own diagnostics of one run (the Metropolis estimators' chains), JSON.
    pub fn cell_diagnostics(&self, label: &str, run: u32) -> PathBuf {
        self.cell_csv(label, run).with_extension("json")
    }

    pub fn checkpoint_image(&self, label: &str, run: u32, checkpoint: u32) -> PathBuf {
        self.dir
            .join("checkpoints")
            .join(file_label(label))
            .join(format!("run{run}-cp{checkpoint}.exr"))
    }

    pub fn final_image(&self, label: &str, run: u32) -> PathBuf {
        self.dir
            .join("images")
            .join(format!("{}-run{run}.exr", file_label(label)))
    }
}

/// Loads the experiment's scene with its parameters, and checks that every region lies on
/// its film and every estimator (and the reference's) accepts its parameters, so that a
/// mistake fails before any rendering rather than after the reference.
pub fn load_scene(experiment: &Experiment) -> Result<Scene> {
    let scene = Scene::build(mitsuba::load_file_with(
        &experiment.scene,
        &experiment.scene_params,
    )?)?;
    experiment.check_regions(scene.width(), scene.height())?;
    let mut entries: Vec<(&str, &[String])> = experiment
        .estimators
        .iter()
        .map(|e| (e.name.as_str(), e.params.as_slice()))
        .collect();
    if let ReferenceSource::Render {
        estimator, params, ..
    } = &experiment.reference
    {
        entries.push((estimator.as_str(), params.as_slice()));
    }
    for (name, params) in entries {
        estimator::create(name, &Params::parse(params)?, &scene, 0).map_err(|e| {
            Error::input(
                Location::file(&experiment.spec_path),
                format!("estimator {name}: {e}"),
            )
        })?;
    }
    Ok(scene)
}

/// The experiment's reference: its file, or the cached render, rendering it if needed.
pub fn obtain_reference(
    experiment: &Experiment,
    scene: &Scene,
    results_root: &Path,
    bar: &ProgressBar,
) -> Result<Reference> {
    let reference = match &experiment.reference {
        ReferenceSource::File(path) => reference::load(path)?,
        ReferenceSource::Render {
            estimator,
            params,
            budget,
        } => {
            let key = reference::cache_key(
                scene,
                &experiment.scene_params,
                estimator,
                params,
                *budget,
                experiment.seed,
            )?;
            let stem = experiment
                .scene
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("scene");
            let path = results_root
                .join("references")
                .join(format!("{stem}-{estimator}-{key}.exr"));
            if path.exists() {
                let r = reference::load(&path)?;
                if r.info.key != key {
                    return Err(Error::input(
                        Location::file(path.with_extension("json")),
                        format!(
                            "cached reference has key {} but {key} was expected",
                            r.info.key
                        ),
                    ));
                }
                r
            } else {
                bar.set_message(format!(
                    "{}: rendering the reference ({estimator}, {budget:?})",
                    experiment.name
                ));
                let (image, mut info) = reference::render_reference(
                    scene,
                    estimator,
                    params,
                    *budget,
                    experiment.seed,
                    |half, pass| {
                        bar.set_message(format!(
                            "{}: reference half {}/2, pass {pass}",
                            experiment.name,
                            half + 1
                        ))
                    },
                )?;
                info.key = key;
                info.scene = experiment.scene.display().to_string();
                reference::save(&path, &image, &info)?;
                Reference { image, info, path }
            }
        }
    };
    let (w, h) = (scene.width(), scene.height());
    if (reference.image.width, reference.image.height) != (w, h) {
        return Err(Error::input(
            Location::file(&reference.path),
            format!(
                "the reference is {}×{} but the scene renders {w}×{h}",
                reference.image.width, reference.image.height
            ),
        ));
    }
    Ok(reference)
}

/// A fingerprint of everything the results depend on (spec fields and scene files).
pub fn fingerprint(experiment: &Experiment, scene: &Scene) -> Result<String> {
    let reference = match &experiment.reference {
        ReferenceSource::File(p) => format!("file {}", p.display()),
        r => format!("{r:?}"),
    };
    let text = format!(
        "{:?}|{:?}|{}|{}|{}|{:?}|{:?}|{}",
        experiment.budget,
        experiment.scene_params,
        experiment.checkpoints,
        experiment.runs,
        experiment.seed,
        experiment.estimators,
        experiment.regions,
        reference
    );
    let key = reference::cache_key(scene, &[], "", &[text], Budget::Passes(0), 0)?;
    Ok(key)
}

/// Checks (or, on the first run, writes) the fingerprint of the results directory.
pub fn check_fingerprint(results: &ResultsDir, fingerprint: &str) -> Result<()> {
    let path = results.dir.join("fingerprint.txt");
    match std::fs::read_to_string(&path) {
        Ok(existing) if existing.trim() == fingerprint => Ok(()),
        Ok(_) => Err(Error::input(
            Location::file(&path),
            "these results were made from a different experiment (spec, scene or version); \
             rerun with --fresh to start over (with --cell K, --fresh discards only that \
             cell's files: start a cluster run over with `run NAME --prepare --fresh`)",
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::create_dir_all(&results.dir).map_err(|e| Error::io(&results.dir, e))?;
            write_file_atomically(&path, format!("{fingerprint}\n").as_bytes())
        }
        Err(e) => Err(Error::io(&path, e)),
    }
}

/// Removes what `run` writes (for `--fresh`), leaving other files alone.
pub fn clear_results(results: &ResultsDir) -> Result<()> {
    for sub in ["cells", "checkpoints", "images"] {
        let d = results.dir.join(sub);
        if d.exists() {
            std::fs::remove_dir_all(&d).map_err(|e| Error::io(&d, e))?;
        }
    }
    let f = results.dir.join("fingerprint.txt");
    if f.exists() {
        std::fs::remove_file(&f).map_err(|e| Error::io(&f, e))?;
    }
    Ok(())
}

/// Removes cell (estimator `e`, run `r`)'s own files: its rows, checkpoint images and final
/// image (for `--cell K --fresh`; every other cell's files stay).
pub fn clear_cell(experiment: &Experiment, results: &ResultsDir, e: usize, r: u32) -> Result<()> {
    let label = &experiment.estimators[e].label;
    let final_image = results.final_image(label, r);
    let mut files = vec![
        results.cell_csv(label, r),
        results.cell_diagnostics(label, r),
        final_image.with_extension("png"),
        final_image,
    ];
    // Every checkpoint image of this run, also any beyond the current checkpoint count.
    let checkpoints = results
        .checkpoint_image(label, r, 0)
        .parent()
        .map(Path::to_path_buf);
    if let Some(dir) = checkpoints.filter(|d| d.is_dir()) {
        let prefix = format!("run{r}-cp");
        for entry in std::fs::read_dir(&dir).map_err(|e| Error::io(&dir, e))? {
            let path = entry.map_err(|e| Error::io(&dir, e))?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let is_mine = name
                .strip_prefix(&prefix)
                .and_then(|rest| rest.strip_suffix(".exr"))
                .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()));
            if is_mine {
                files.push(path);
            }
        }
    }
    for f in files {
        match std::fs::remove_file(&f) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(&f, e)),
        }
    }
    Ok(())
}

/// True when cell (estimator `e`, run `r`) has all its checkpoint rows and final image.
pub fn cell_is_complete(
    experiment: &Experiment,
    results: &ResultsDir,
    e: usize,
    r: u32,
) -> Result<bool> {
    let label = &experiment.estimators[e].label;
    let csv = results.cell_csv(label, r);
    if !csv.exists() || !results.final_image(label, r).exists() {
        return Ok(false);
    }
    let rows = read_cell_rows(experiment, results, e, r)?;
    let whole = rows.iter().filter(|row| row.region.is_empty()).count();
    Ok(whole == experiment.checkpoint_budgets().len())
}

/// The seed of run `run` of estimator `label`.
pub fn run_seed(experiment: &Experiment, label: &str, run: u32) -> u64 {
    let label_hash = hash_words(&label.bytes().map(u64::from).collect::<Vec<_>>());
    hash_words(&[experiment.seed, label_hash, run as u64])
}

/// Renders cell (estimator `e`, `run`) to its last checkpoint, writing its rows and images
/// as it goes; `after_checkpoint` runs once each checkpoint's files are written (an error
/// from it stops the cell there).
pub fn run_cell(
    experiment: &Experiment,
    scene: &Scene,
    reference: &Reference,
    results: &ResultsDir,
    (e, run): (usize, u32),
    bar: &ProgressBar,
    after_checkpoint: &mut dyn FnMut() -> Result<()>,
) -> Result<Vec<Row>> {
    let entry = &experiment.estimators[e];
    let params = Params::parse(&entry.params)?;
    let seed = run_seed(experiment, &entry.label, run);
    let mut est = estimator::create(&entry.name, &params, scene, seed)?;
    let budgets = experiment.checkpoint_budgets();
    let csv = results.cell_csv(&entry.label, run);
    for dir in [
        csv.parent().unwrap().to_path_buf(),
        results
            .checkpoint_image(&entry.label, run, 0)
            .parent()
            .unwrap()
            .to_path_buf(),
        results
            .final_image(&entry.label, run)
            .parent()
            .unwrap()
            .to_path_buf(),
    ] {
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    }
    let regions: Vec<MetricRegion> = experiment
        .regions
        .iter()
        .map(|r| MetricRegion {
            x: r.x,
            y: r.y,
            width: r.width,
            height: r.height,
        })
        .collect();

    let mut rows = Vec::new();
    let mut progress = Progress::default();
    let mut image = Image::new(scene.width(), scene.height());
    for (k, budget) in budgets.iter().enumerate() {
        bar.set_message(format!(
            "{}: {} run {}/{}, checkpoint {}/{}",
            experiment.name,
            entry.label,
            run + 1,
            experiment.runs,
            k + 1,
            budgets.len()
        ));
        // Passes in chunks, as `render` takes them (`render::advance`).
        let (mut passes, mut seconds) = (progress.passes, progress.seconds);
        let passes_of = |first, count| est.run_passes(scene, first, count);
        advance(passes_of, *budget, &mut progress, false, |p| {
            match experiment.budget {
                Budget::Passes(_) => bar.inc((p.passes - passes) as u64),
                Budget::Seconds(_) => bar.inc(((p.seconds - seconds) * 1000.0) as u64),
            }
            (passes, seconds) = (p.passes, p.seconds);
        });
        let seconds = progress.seconds;
        image = est.image();
        let stats = est.stats();
        let row = |region: &str, m: super::metrics::Metrics| Row {
            estimator: entry.label.clone(),
            run,
            checkpoint: k as u32,
            seconds,
            passes: stats.passes,
            samples: stats.samples,
            region: region.to_string(),
            relmse: m.relmse,
            rmse: m.rmse,
            mape: m.mape,
        };
        rows.push(row("", metrics(&image, &reference.image)?));
        for (spec, region) in experiment.regions.iter().zip(&regions) {
            rows.push(row(
                &spec.label,
                metrics_in(&image, &reference.image, *region)?,
            ));
        }
        write_exr(
            &results.checkpoint_image(&entry.label, run, k as u32),
            &image,
        )?;
        write_rows(&csv, &rows)?;
        after_checkpoint()?;
    }
    let final_path = results.final_image(&entry.label, run);
    write_exr(&final_path, &image)?;
    if let Some(diagnostics) = est.diagnostics() {
        let path = results.cell_diagnostics(&entry.label, run);
        let text = serde_json::to_string_pretty(&diagnostics).unwrap_or_default();
        std::fs::write(&path, text + "\n").map_err(|e| Error::io(&path, e))?;
    }
    if run == 0 {
        write_png_preview(&final_path.with_extension("png"), &image)?;
    }
    Ok(rows)
}
