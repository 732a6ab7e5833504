//! The `mltbench` command line: parses arguments, calls the library, reports errors.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use mltbench::estimator::{self, ESTIMATOR_NAMES, Params};
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};
use mltbench::{Error, Result, io};

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
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene: a Mitsuba 3 XML file.
    scene: PathBuf,
    /// Which estimator renders it.
    #[arg(short, long, value_name = "NAME", help = estimator_help())]
    estimator: String,
    /// Samples per pixel (passes). Default: the scene's <sampler sample_count>.
    #[arg(long, value_name = "N", conflicts_with = "time")]
    spp: Option<u32>,
    /// Render for this many seconds of wall-clock time instead of a fixed spp.
    #[arg(long, value_name = "SECONDS")]
    time: Option<f64>,
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
    /// Output EXR. Default: <scene name>.exr in the working directory. A PNG preview is
    /// written beside it.
    #[arg(short, long, value_name = "OUT.exr")]
    output: Option<PathBuf>,
}

fn estimator_help() -> String {
    format!("Which estimator renders it: {}", ESTIMATOR_NAMES.join(", "))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Render(args) => run_render(args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}

fn run_render(args: RenderArgs) -> Result<()> {
    let params = Params::parse(&args.set)?;
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
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene));
    if output.extension().and_then(|e| e.to_str()) != Some("exr") {
        return Err(Error::usage(format!(
            "output {} must end in .exr",
            output.display()
        )));
    }

    let scene_params = parse_defines(&args.define)?;
    let description = mitsuba::load_file_with(&args.scene, &scene_params)?;
    for warning in &description.warnings {
        eprintln!("warning: {warning}");
    }
    if description.skipped_triangles > 0 {
        eprintln!(
            "warning: {}: skipped {} degenerate triangles",
            args.scene.display(),
            description.skipped_triangles
        );
    }
    let scene = Scene::build(description)?;
    let budget = match (args.spp, args.time) {
        (_, Some(seconds)) => Budget::Seconds(seconds),
        (Some(spp), None) => Budget::Passes(spp),
        (None, None) => Budget::Passes(scene.description.sensor.sample_count.max(1)),
    };

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::usage(format!("cannot start {:?} threads: {e}", args.threads)))?;
    let mut estimator = estimator::create(&args.estimator, &params, &scene, args.seed)?;

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
    let preview = output.with_extension("png");
    io::png::write_png_preview(&preview, &result.image)?;

    let stats = &result.stats;
    eprintln!(
        "{}: {} passes, {} samples, {:.2} s ({:.3} M samples/s, {:.3} M rays/s), \
         {} invalid samples dropped -> {} (+ {})",
        args.estimator,
        stats.passes,
        stats.samples,
        result.seconds,
        stats.samples as f64 / result.seconds / 1e6,
        stats.rays as f64 / result.seconds / 1e6,
        stats.invalid_samples,
        output.display(),
        preview.display()
    );
    Ok(())
}

/// `NAME=VALUE` pairs of `-D`.
fn parse_defines(defines: &[String]) -> Result<Vec<(String, String)>> {
    defines
        .iter()
        .map(|d| match d.split_once('=') {
            Some((name, value)) if !name.trim().is_empty() => {
                Ok((name.trim().to_string(), value.trim().to_string()))
            }
            _ => Err(Error::usage(format!("-D expects NAME=VALUE, got '{d}'"))),
        })
        .collect()
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
