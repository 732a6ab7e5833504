//! The `mltbench` command line: parses arguments, calls the library, reports errors.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use mltbench::estimator::{self, ESTIMATOR_NAMES, Params};
use mltbench::experiment::{self, Experiment};
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};
use mltbench::{Error, Result, interrupt, io};

/// mltbench: a research bench for light-transport estimators.
///
/// Renders Mitsuba 3 XML scenes with interchangeable estimators and measures them.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene with one estimator and write an EXR (linear radiance) and a PNG preview.
    ///
    /// The image is bit-identical for the same scene, estimator, parameters, seed and
    /// number of passes, whatever --threads is.
    Render(RenderArgs),
    /// Run a named experiment (experiments/NAME.toml, or a path to a .toml file): every
    /// estimator × run to its checkpoints, against the reference, then the report under
    /// results/NAME/. Unless --fresh, cells an earlier run finished are kept and an
    /// unfinished cell starts again from its first pass.
    Run(RunArgs),
    /// List the experiments with one-line descriptions.
    List,
    /// Merge the cells present under results/NAME/ into the summary, plots and README
    /// (after `run --cell K` jobs, e.g. a Slurm array).
    Report(ReportArgs),
    /// Render a reference: two independent halves averaged, with the noise estimate from
    /// their difference written to OUT.json beside OUT.exr.
    Reference(ReferenceArgs),
    /// Print relMSE, RMSE and MAPE (docs/DESIGN.md §5) of an image against a reference.
    Compare(CompareArgs),
}

#[derive(clap::Args)]
struct RunArgs {
    /// Experiment name or path to its .toml file.
    experiment: String,
    /// Scale budgets down and cap runs as the experiment's [quick] table says (a smoke
    /// run; results go to results/NAME-quick/).
    #[arg(long)]
    quick: bool,
    /// Delete earlier results of this experiment and start over (with --cell K: only cell
    /// K's own files).
    #[arg(long)]
    fresh: bool,
    /// List the experiment's independent (estimator, run) cells and exit.
    #[arg(long, conflicts_with = "cell")]
    cells: bool,
    /// Run only cell K (see --cells) and write only its files; `report` merges them.
    #[arg(long, value_name = "K")]
    cell: Option<usize>,
    /// Only make sure the reference (and the [strategies] images, if the spec asks for
    /// them) exist, rendering them if needed, and exit: run this once before spreading
    /// cells over a cluster.
    #[arg(long, conflicts_with_all = ["cell", "cells"])]
    prepare: bool,
    /// Folder of results (default: results).
    #[arg(long, value_name = "DIR", default_value = "results")]
    results: PathBuf,
    /// Worker threads (default: all cores). Does not change the images.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
}

#[derive(clap::Args)]
struct ReportArgs {
    /// Experiment name or path to its .toml file.
    experiment: String,
    /// Report on the --quick results.
    #[arg(long)]
    quick: bool,
    #[arg(long, value_name = "DIR", default_value = "results")]
    results: PathBuf,
}

#[derive(clap::Args)]
struct ReferenceArgs {
    #[command(flatten)]
    common: SceneEstimatorArgs,
    /// Passes in all (each half renders half of them).
    #[arg(
        long,
        value_name = "N",
        conflicts_with = "time",
        required_unless_present = "time"
    )]
    spp: Option<u32>,
    /// Seconds in all (each half renders half of them).
    #[arg(long, value_name = "SECONDS")]
    time: Option<f64>,
    /// Output EXR (default: <scene name>-reference.exr); OUT.json and OUT.png beside it.
    #[arg(short, long, value_name = "OUT.exr")]
    output: Option<PathBuf>,
}

#[derive(clap::Args)]
struct CompareArgs {
    image: PathBuf,
    reference: PathBuf,
}

/// What `render` and `reference` share: the scene, the estimator and how it runs.
#[derive(clap::Args)]
struct SceneEstimatorArgs {
    /// The scene: a Mitsuba 3 XML file.
    scene: PathBuf,
    /// Which estimator renders it.
    #[arg(short, long, value_name = "NAME", help = estimator_help())]
    estimator: String,
    /// Seed of every random stream; the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (default: all cores). Does not change the image.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Estimator parameter, repeatable: --set rr_depth=5 --set mis=power.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Scene parameter, repeatable: -D res=64 sets the scene's <default name="res">
    /// (as Mitsuba's -D). Naming a parameter the scene does not declare is an error.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE")]
    define: Vec<String>,
}

#[derive(clap::Args)]
struct RenderArgs {
    #[command(flatten)]
    common: SceneEstimatorArgs,
    /// Samples per pixel (passes). Default: the scene's <sampler sample_count>.
    #[arg(long, value_name = "N", conflicts_with = "time")]
    spp: Option<u32>,
    /// Render for this many seconds of wall-clock time instead of a fixed spp.
    #[arg(long, value_name = "SECONDS")]
    time: Option<f64>,
    /// Output EXR. Default: <scene name>.exr in the working directory. A PNG preview is
    /// written beside it; with `bdpt --set strategies=true`, the strategy images go to the
    /// folder OUT-strategies/ beside it (one EXR per strategy (s, t), weighted and
    /// unweighted, the pyramid sheets pyramid-weighted.png and pyramid-unweighted.png, and
    /// strategies.csv).
    #[arg(short, long, value_name = "OUT.exr")]
    output: Option<PathBuf>,
}

fn estimator_help() -> String {
    format!("Which estimator renders it: {}", ESTIMATOR_NAMES.join(", "))
}

fn main() -> ExitCode {
    // Before anything else: a build for other CPUs would die of an illegal instruction.
    let missing = mltbench::cpu::missing_features();
    if !missing.is_empty() {
        eprintln!(
            "error: this mltbench was built for CPU features that this machine lacks ({}): \
             build it here, or for a CPU level every machine has (RUSTFLAGS=\"-C \
             target-cpu=x86-64-v2\"; see the README, \"On a cluster\")",
            missing.join(", ")
        );
        return ExitCode::FAILURE;
    }
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Render(args) => match run_render(args) {
            Ok(true) => return ExitCode::from(interrupt::EXIT_STATUS),
            other => other.map(|_| ()),
        },
        Command::Run(args) => run_experiment(args),
        Command::List => list_experiments(),
        Command::Report(args) => report_experiment(args),
        Command::Reference(args) => match render_reference(args) {
            Ok(true) => return ExitCode::from(interrupt::EXIT_STATUS),
            other => other.map(|_| ()),
        },
        Command::Compare(args) => compare(args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}

/// `render`; Ok(true) when a stop request cut it short (the passes done are written).
fn run_render(args: RenderArgs) -> Result<bool> {
    let params = Params::parse(&args.common.set)?;
    if let Some(t) = args.time
        && !(t.is_finite() && t > 0.0)
    {
        return Err(Error::usage(format!(
            "--time must be a positive number of seconds, got {t}"
        )));
    }
    if args.spp == Some(0) {
        return Err(Error::usage("--spp must be at least 1"));
    }
    estimator::check_name(&args.common.estimator)?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.common.scene));
    // Refused now rather than after the render: its result would be lost.
    let mut sidecars = io::outputs::check_outputs(&output, &["png", "diagnostics.json"])?;
    // The JSON is written only by estimators with diagnostics (`pssmlt`, `mmlt`).
    let diagnostics_path = sidecars.pop().unwrap();
    let preview = sidecars.remove(0);
    let scene_params = parse_defines(&args.common.define)?;
    let description = mitsuba::load_file_with(&args.common.scene, &scene_params)?;
    io::outputs::check_not_inputs(
        [output.as_path(), &preview, &diagnostics_path],
        &description.files_read,
    )?;
    // Degenerate triangles are among these, once per mesh with its line.
    for warning in &description.warnings {
        eprintln!("warning: {warning}");
    }
    let scene = Scene::build(description)?;
    let budget = match (args.spp, args.time) {
        (_, Some(seconds)) => Budget::Seconds(seconds),
        (Some(spp), None) => Budget::Passes(spp),
        (None, None) => Budget::Passes(scene.description.sensor.sample_count.max(1)),
    };

    let pool = thread_pool(args.common.threads)?;
    let mut estimator =
        estimator::create(&args.common.estimator, &params, &scene, args.common.seed)?;
    let strategy_folder = estimator
        .keeps_strategy_images()
        .then(|| io::strategy_images::folder_for(&output));
    if let Some(folder) = &strategy_folder {
        io::strategy_images::prepare(folder)?;
    }

    // From here on Ctrl-C (or SIGTERM) stops after the pass in progress and writes it.
    interrupt::install();
    eprintln!(
        "{}: rendering {} × {} pixels{}; Ctrl-C stops after the current pass and writes the \
         image so far",
        args.common.estimator,
        scene.width(),
        scene.height(),
        match budget {
            Budget::Passes(n) => format!(", {n} passes"),
            Budget::Seconds(s) => format!(" for {s} s"),
        }
    );
    let bar = progress_bar(budget);
    let result = pool.install(|| {
        render(
            &scene,
            estimator.as_mut(),
            budget,
            |pass, elapsed| match budget {
                Budget::Passes(_) => bar.set_position(pass as u64),
                Budget::Seconds(_) => {
                    bar.set_position(elapsed.as_millis() as u64);
                    bar.set_message(format!("{pass} passes"));
                }
            },
        )
    });
    bar.finish_and_clear();

    io::exr::write_exr(&output, &result.image)?;
    io::png::write_png_preview(&preview, &result.image)?;
    if let Some(diagnostics) = estimator.diagnostics() {
        let text = serde_json::to_string_pretty(&diagnostics).unwrap_or_default() + "\n";
        io::atomic::write_file_atomically(&diagnostics_path, text.as_bytes())?;
        eprintln!(
            "{}: diagnostics -> {}",
            args.common.estimator,
            diagnostics_path.display()
        );
    }
    if let (Some(folder), Some(images)) = (&strategy_folder, estimator.strategy_images()) {
        io::strategy_images::write(folder, &result.image, &images, true)?;
        eprintln!(
            "{}: {} strategies (weighted and unweighted images, pyramids, strategies.csv) -> {}",
            args.common.estimator,
            images.len(),
            folder.display()
        );
    }

    let stats = &result.stats;
    eprintln!(
        "{}: {} passes, {} samples, {:.2} s ({:.3} M samples/s, {:.3} M rays/s), \
         {} invalid samples dropped -> {} (+ {})",
        args.common.estimator,
        stats.passes,
        stats.samples,
        result.seconds,
        stats.samples as f64 / result.seconds / 1e6,
        stats.rays as f64 / result.seconds / 1e6,
        stats.invalid_samples,
        output.display(),
        preview.display()
    );
    if result.interrupted {
        eprintln!(
            "{}: interrupted: the image holds the {} passes done",
            args.common.estimator, stats.passes
        );
    }
    Ok(result.interrupted)
}

/// The most worker threads `--threads` may ask for.
const MAX_THREADS: usize = 4096;

/// A pool of `threads` workers (all cores for None or 0).
fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    if let Some(n) = threads.filter(|&n| n > MAX_THREADS) {
        return Err(Error::usage(format!(
            "--threads {n}: at most {MAX_THREADS} (0 or none: all cores)"
        )));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::usage(format!("cannot start {threads:?} threads: {e}")))
}

fn experiment_bar() -> ProgressBar {
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {percent}% ETA {eta} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

fn run_experiment(args: RunArgs) -> Result<()> {
    let path = experiment::find_experiment(&args.experiment)?;
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    if mltbench::lecture::is_lecture(&text) {
        if args.cells || args.cell.is_some() || args.prepare || args.quick {
            return Err(Error::usage(format!(
                "{}: a lecture experiment (with `kind`) runs whole: no --quick, --cells, \
                 --cell or --prepare",
                path.display()
            )));
        }
        let pool = thread_pool(args.threads)?;
        let (kind, out) = pool.install(|| mltbench::lecture::run(&path, &text, &args.results))?;
        eprintln!("{kind}: results in {}", out.display());
        return Ok(());
    }
    let exp = Experiment::load(&path, args.quick)?;
    if args.cells {
        let complete = experiment::cells_complete(&exp, &args.results)?;
        println!(
            "# {}: {} cells (cell, estimator label, run, complete or todo in {})",
            exp.name,
            exp.cells().len(),
            args.results.join(&exp.name).display()
        );
        for (k, (e, r)) in exp.cells().into_iter().enumerate() {
            let status = if complete[k] { "complete" } else { "todo" };
            println!("{k}\t{}\t{r}\t{status}", exp.estimators[e].label);
        }
        return Ok(());
    }
    // Whether the cell asked for is complete already (then `run` keeps it as it is).
    let already_complete = match args.cell.and_then(|k| exp.cells().get(k).copied()) {
        Some((e, r)) if !args.fresh => {
            let results = experiment::runner::ResultsDir::new(&args.results, &exp);
            experiment::runner::cell_is_complete(&exp, &results, e, r)?
        }
        _ => false,
    };
    let pool = thread_pool(args.threads)?;
    let bar = experiment_bar();
    let options = experiment::RunOptions {
        results_root: args.results.clone(),
        fresh: args.fresh,
        cell: args.cell,
        stop_after_checkpoints: None,
    };
    let outcome = pool.install(|| {
        if args.prepare {
            experiment::prepare(&exp, &options, &bar).map(|_| None)
        } else {
            experiment::run(&exp, &options, &bar)
        }
    });
    bar.finish_and_clear();
    match outcome? {
        Some(summary) => print_summary(&summary, &args.results.join(&exp.name)),
        None if args.prepare => eprintln!("{}: reference ready", exp.name),
        None => {
            let mut report = format!("mltbench report {}", shell_word(&args.experiment));
            if args.quick {
                report.push_str(" --quick");
            }
            if args.results != Path::new("results") {
                report.push_str(" --results ");
                report.push_str(&shell_word(&args.results.display().to_string()));
            }
            eprintln!(
                "{}: cell {} {}; `{report}` merges the cells",
                exp.name,
                args.cell.unwrap_or(0),
                if already_complete {
                    "was already complete (kept as it was)"
                } else {
                    "done"
                }
            )
        }
    }
    Ok(())
}

/// `word` as one shell word: as it is when it needs no quoting, else in single quotes.
fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./=+,:@%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

fn print_summary(summary: &experiment::Summary, dir: &Path) {
    eprintln!("{}: results in {}", summary.experiment, dir.display());
    for e in &summary.estimators {
        eprintln!(
            "  {:<16} relMSE {} after {:.1} s, slope {}",
            e.label,
            experiment::report::with_interval(&e.relmse, e.runs),
            e.seconds,
            e.slope_seconds
                .map(|f| format!("{:.2} ± {:.2}", f.slope, f.slope_se))
                .unwrap_or_else(|| "–".into())
        );
    }
    if !summary.missing_cells.is_empty() {
        eprintln!("  missing: {}", summary.missing_cells.join(", "));
    }
}

fn list_experiments() -> Result<()> {
    for (name, description) in experiment::list_experiments()? {
        println!("{name:<20} {description}");
    }
    Ok(())
}

fn report_experiment(args: ReportArgs) -> Result<()> {
    let path = experiment::find_experiment(&args.experiment)?;
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    if mltbench::lecture::is_lecture(&text) {
        return Err(Error::usage(format!(
            "{}: a lecture experiment (with `kind`) has no separate report: \
             `mltbench run {}` runs it whole and writes its summary, plots and README",
            path.display(),
            args.experiment
        )));
    }
    let exp = Experiment::load(&path, args.quick)?;
    let bar = experiment_bar();
    let summary = experiment::report_only(&exp, &args.results, &bar);
    bar.finish_and_clear();
    print_summary(&summary?, &args.results.join(&exp.name));
    Ok(())
}

/// `reference`; Ok(true) when a stop request cut it short (the equal halves done are
/// written).
fn render_reference(args: ReferenceArgs) -> Result<bool> {
    Params::parse(&args.common.set)?; // rejects a malformed --set before any rendering
    estimator::check_name(&args.common.estimator)?;
    let budget = match (args.spp, args.time) {
        (_, Some(t)) if t.is_finite() && t > 0.0 => Budget::Seconds(t),
        (Some(n), None) if n >= 2 => Budget::Passes(n),
        _ => {
            return Err(Error::usage(
                "give --spp N (N >= 2: two halves) or --time SECONDS (> 0)",
            ));
        }
    };
    let output = args.output.clone().unwrap_or_else(|| {
        let stem = args
            .common
            .scene
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene");
        PathBuf::from(format!("{stem}-reference.exr"))
    });
    // The EXR, its noise description and its preview (`reference::save`), checked before
    // the render so that none of them is lost at the end or overwrites an input.
    let sidecars = io::outputs::check_outputs(&output, &["json", "png"])?;
    let scene_params = parse_defines(&args.common.define)?;
    let description = mitsuba::load_file_with(&args.common.scene, &scene_params)?;
    let outputs = std::iter::once(output.as_path()).chain(sidecars.iter().map(PathBuf::as_path));
    io::outputs::check_not_inputs(outputs, &description.files_read)?;
    let scene = Scene::build(description)?;
    let pool = thread_pool(args.common.threads)?;
    // From here on Ctrl-C (or SIGTERM) stops both halves after the passes in progress.
    interrupt::install();
    eprintln!(
        "reference: rendering {} × {} pixels in two halves; Ctrl-C stops after the current \
         passes and writes the reference so far",
        scene.width(),
        scene.height()
    );
    let bar = experiment_bar();
    let rendered = pool.install(|| {
        experiment::reference::render_reference(
            &scene,
            &args.common.estimator,
            &args.common.set,
            budget,
            args.common.seed,
            |half, pass| bar.set_message(format!("half {}/2, pass {pass}", half + 1)),
        )
    });
    bar.finish_and_clear();
    let (image, mut info) = rendered?;
    info.scene = args.common.scene.display().to_string();
    experiment::reference::save(&output, &image, &info)?;
    eprintln!(
        "reference: {} passes, {:.1} s, own noise relMSE ≈ {:.3e} -> {} (+ .json, .png)",
        info.passes,
        info.seconds,
        info.noise_relmse.unwrap_or(f64::NAN),
        output.display()
    );
    let interrupted = interrupt::requested();
    if interrupted {
        eprintln!(
            "reference: stopped on request: it holds the {} passes done (two equal halves)",
            info.passes
        );
    }
    Ok(interrupted)
}

fn compare(args: CompareArgs) -> Result<()> {
    let image = io::exr::read_exr(&args.image)?;
    let reference = experiment::reference::load(&args.reference)?;
    // The metrics' messages say "image" and "reference": name the two files.
    let m = experiment::metrics::metrics(&image, &reference.image).map_err(|e| {
        Error::usage(format!(
            "{} against {}: {e}",
            args.image.display(),
            args.reference.display()
        ))
    })?;
    println!("relmse {:.6e}", m.relmse);
    println!("rmse   {:.6e}", m.rmse);
    println!("mape   {:.6e}", m.mape);
    if let Some(noise) = reference.info.noise_relmse {
        println!("reference noise relmse {noise:.6e}");
        if m.relmse < noise {
            println!("note: the error is below the reference's own noise: not meaningful");
        }
    }
    Ok(())
}

/// `NAME=VALUE` pairs of `-D`; a name given twice is refused (as `--set` refuses it), since
/// either value winning silently would surprise someone.
fn parse_defines(defines: &[String]) -> Result<Vec<(String, String)>> {
    let mut pairs: Vec<(String, String)> = Vec::with_capacity(defines.len());
    for d in defines {
        let Some((name, value)) = d.split_once('=').filter(|(n, _)| !n.trim().is_empty()) else {
            return Err(Error::usage(format!("-D expects NAME=VALUE, got '{d}'")));
        };
        let name = name.trim();
        if pairs.iter().any(|(n, _)| n == name) {
            return Err(Error::usage(format!("-D {name} is given more than once")));
        }
        pairs.push((name.to_string(), value.trim().to_string()));
    }
    Ok(pairs)
}

/// `<scene file stem>.exr` in the working directory.
fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_os_string())
        .unwrap_or_else(|| "render".into());
    PathBuf::from(stem).with_extension("exr")
}

fn progress_bar(budget: Budget) -> ProgressBar {
    let (length, template) = match budget {
        Budget::Passes(n) => (
            n as u64,
            "{elapsed_precise} [{bar:40}] {pos}/{len} passes, ETA {eta}",
        ),
        Budget::Seconds(s) => ((s * 1000.0) as u64, "{elapsed_precise} [{bar:40}] {msg}"),
    };
    let bar = ProgressBar::new(length);
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}
