//! Turning the cells present under `results/NAME/` into the experiment's summary, plots and
//! README. The same code serves a single-machine `run` and `report` after cells ran
//! elsewhere: whatever cells are complete are merged; missing ones are listed.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::metrics::relative_error_map;
use super::plot::{
    Band, Crop, Series, SheetEntry, bias_variance_plot, contact_sheet, convergence_plot,
};
use super::reference::Reference;
use super::runner::{ResultsDir, Row, cell_is_complete, read_cell_rows, write_rows};
use super::spec::Experiment;
use super::statistics::{
    BiasVariance, Interval, SlopeFit, bias_variance, fit_later_half, nonnegative_mean_interval,
};
use crate::error::{Error, Result};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::exr::read_exr;
use crate::io::png::write_png_preview;

/// Confidence of every interval in the reports.
pub const CONFIDENCE: f64 = 0.95;

/// What the summary says about one estimator.
#[derive(Clone, Debug, Serialize)]
pub struct EstimatorSummary {
    pub label: String,
    pub estimator: String,
    pub params: Vec<String>,
    /// Runs that finished (the statistics are over these).
    pub runs: usize,
    /// Mean time and passes of the final checkpoint.
    pub seconds: f64,
    pub passes: f64,
    pub relmse: Interval,
    pub rmse: Interval,
    pub mape: Interval,
    /// Least-squares slope of log relMSE (run mean) against log seconds / log passes, over
    /// the later half of the checkpoints.
    pub slope_seconds: Option<SlopeFit>,
    pub slope_passes: Option<SlopeFit>,
    /// 1 / (relMSE × seconds) at the final checkpoint, per run.
    pub efficiency: Interval,
    /// Across runs at the final checkpoint (needs ≥ 2 runs).
    pub bias_variance: Option<BiasVariance>,
    /// The final relMSE is below the reference's own noise: not meaningful.
    pub below_reference_noise: bool,
    /// Final relMSE per region, (label, interval over runs).
    pub regions: Vec<(String, Interval)>,
}

/// The whole summary (`summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub experiment: String,
    pub description: String,
    pub scene: String,
    pub budget: String,
    pub checkpoints: u32,
    pub runs: u32,
    pub reference: String,
    pub reference_noise_relmse: Option<f64>,
    pub missing_cells: Vec<String>,
    pub estimators: Vec<EstimatorSummary>,
}

/// Reads every complete cell, writes `metrics.csv`, `regions.csv`, `summary.csv`,
/// `summary.json`, the plots and `README.md`. Fails if no cell is complete.
pub fn report(
    experiment: &Experiment,
    results: &ResultsDir,
    reference: &Reference,
) -> Result<Summary> {
    let mut rows: Vec<Row> = Vec::new();
    let mut missing = Vec::new();
    for (e, r) in experiment.cells() {
        let label = &experiment.estimators[e].label;
        if cell_is_complete(experiment, results, e, r)? {
            rows.extend(read_cell_rows(experiment, results, e, r)?);
        } else {
            missing.push(format!("{label} run {r}"));
        }
    }
    if rows.is_empty() {
        return Err(Error::usage(format!(
            "{}: no finished cell to report on in {}",
            experiment.name,
            results.dir.display()
        )));
    }
    let whole: Vec<Row> = rows
        .iter()
        .filter(|r| r.region.is_empty())
        .cloned()
        .collect();
    write_metrics_csv(&results.dir.join("metrics.csv"), &whole)?;
    if !experiment.regions.is_empty() {
        let regions: Vec<Row> = rows
            .iter()
            .filter(|r| !r.region.is_empty())
            .cloned()
            .collect();
        write_rows(&results.dir.join("regions.csv"), &regions)?;
    }

    let noise = reference.info.noise_relmse;
    let last = experiment.checkpoint_budgets().len() as u32 - 1;
    let mut summaries = Vec::new();
    let mut by_seconds = Vec::new();
    let mut by_passes = Vec::new();
    let mut bias_series = Vec::new();
    let mut variance_series = Vec::new();
    let mut sheet = Vec::new();
    for entry in &experiment.estimators {
        let mine: Vec<&Row> = whole
            .iter()
            .filter(|r| r.estimator == entry.label)
            .collect();
        if mine.is_empty() {
            continue;
        }
        let runs: Vec<u32> = {
            let mut v: Vec<u32> = mine.iter().map(|r| r.run).collect();
            v.sort();
            v.dedup();
            v
        };
        let at =
            |k: u32| -> Vec<&Row> { mine.iter().copied().filter(|r| r.checkpoint == k).collect() };
        let finals = at(last);
        let values = |f: fn(&Row) -> f64| -> Vec<f64> { finals.iter().map(|r| f(r)).collect() };
        let relmse = nonnegative_mean_interval(&values(|r| r.relmse), CONFIDENCE);

        // Convergence curves: run mean and run range at each checkpoint.
        let mut band_s = Band {
            x: vec![],
            mean: vec![],
            lo: vec![],
            hi: vec![],
        };
        let mut band_p = Band {
            x: vec![],
            mean: vec![],
            lo: vec![],
            hi: vec![],
        };
        let mut bias_band = Band {
            x: vec![],
            mean: vec![],
            lo: vec![],
            hi: vec![],
        };
        let mut var_band = Band {
            x: vec![],
            mean: vec![],
            lo: vec![],
            hi: vec![],
        };
        for k in 0..=last {
            let rows_k = at(k);
            if rows_k.is_empty() {
                continue;
            }
            let n = rows_k.len() as f64;
            let e: Vec<f64> = rows_k.iter().map(|r| r.relmse).collect();
            let mean = e.iter().sum::<f64>() / n;
            let lo = e.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = e.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let secs = rows_k.iter().map(|r| r.seconds).sum::<f64>() / n;
            let passes = rows_k.iter().map(|r| r.passes as f64).sum::<f64>() / n;
            for (band, x) in [(&mut band_s, secs), (&mut band_p, passes)] {
                band.x.push(x);
                band.mean.push(mean);
                band.lo.push(lo);
                band.hi.push(hi);
            }
            if runs.len() >= 2 {
                let images = runs
                    .iter()
                    .map(|&r| read_exr(&results.checkpoint_image(&entry.label, r, k)))
                    .collect::<Result<Vec<Image>>>()?;
                let bv = bias_variance(&images, &reference.image)?;
                for (band, i) in [
                    (&mut bias_band, bv.relative_bias2),
                    (&mut var_band, bv.relative_variance),
                ] {
                    band.x.push(secs);
                    band.mean.push(i.mean);
                    band.lo.push(i.lo);
                    band.hi.push(i.hi);
                }
            }
        }
        let slope_seconds = fit_later_half(&band_s.x, &band_s.mean);
        let slope_passes = fit_later_half(&band_p.x, &band_p.mean);
        let bias_variance = if runs.len() >= 2 {
            let images = runs
                .iter()
                .map(|&r| read_exr(&results.final_image(&entry.label, r)))
                .collect::<Result<Vec<Image>>>()?;
            Some(bias_variance(&images, &reference.image)?)
        } else {
            None
        };
        let first_image = read_exr(&results.final_image(&entry.label, runs[0]))?;
        sheet.push(SheetEntry {
            label: entry.label.clone(),
            error_map: relative_error_map(&first_image, &reference.image)?,
            image: first_image,
        });
        let regions = experiment
            .regions
            .iter()
            .map(|region| {
                let v: Vec<f64> = rows
                    .iter()
                    .filter(|r| {
                        r.estimator == entry.label
                            && r.region == region.label
                            && r.checkpoint == last
                    })
                    .map(|r| r.relmse)
                    .collect();
                (
                    region.label.clone(),
                    nonnegative_mean_interval(&v, CONFIDENCE),
                )
            })
            .collect();
        summaries.push(EstimatorSummary {
            label: entry.label.clone(),
            estimator: entry.name.clone(),
            params: entry.params.clone(),
            runs: finals.len(),
            seconds: values(|r| r.seconds).iter().sum::<f64>() / finals.len() as f64,
            passes: values(|r| r.passes as f64).iter().sum::<f64>() / finals.len() as f64,
            rmse: nonnegative_mean_interval(&values(|r| r.rmse), CONFIDENCE),
            mape: nonnegative_mean_interval(&values(|r| r.mape), CONFIDENCE),
            efficiency: nonnegative_mean_interval(
                &values(|r| 1.0 / (r.relmse * r.seconds)),
                CONFIDENCE,
            ),
            below_reference_noise: noise.is_some_and(|n| relmse.mean < n),
            relmse,
            slope_seconds,
            slope_passes,
            bias_variance,
            regions,
        });
        by_seconds.push(Series {
            label: entry.label.clone(),
            band: band_s,
        });
        by_passes.push(Series {
            label: entry.label.clone(),
            band: band_p,
        });
        if !bias_band.x.is_empty() {
            bias_series.push(Series {
                label: entry.label.clone(),
                band: bias_band,
            });
            variance_series.push(Series {
                label: entry.label.clone(),
                band: var_band,
            });
        }
    }

    let summary = Summary {
        experiment: experiment.name.clone(),
        description: experiment.description.clone(),
        scene: experiment.scene.display().to_string(),
        budget: match experiment.budget {
            crate::render::Budget::Seconds(t) => format!("{t} s"),
            crate::render::Budget::Passes(p) => format!("{p} passes"),
        },
        checkpoints: experiment.checkpoints,
        runs: experiment.runs,
        reference: reference.path.display().to_string(),
        reference_noise_relmse: noise,
        missing_cells: missing,
        estimators: summaries,
    };

    let dir = &results.dir;
    let guides = [(-1.0, "slope −1"), (-2.0 / 3.0, "slope −2/3")];
    let title = format!("{}: relMSE", experiment.name);
    convergence_plot(
        &dir.join("convergence"),
        &title,
        "seconds",
        "relMSE",
        &by_seconds,
        &guides,
    )?;
    convergence_plot(
        &dir.join("convergence-passes"),
        &title,
        "passes",
        "relMSE",
        &by_passes,
        &guides,
    )?;
    bias_variance_plot(
        &dir.join("bias"),
        &format!("{}: relative bias² and variance", experiment.name),
        "seconds",
        &bias_series,
        &variance_series,
    )?;
    let crops: Vec<Crop> = experiment
        .regions
        .iter()
        .map(|r| Crop {
            label: r.label.clone(),
            x: r.x,
            y: r.y,
            width: r.width,
            height: r.height,
        })
        .collect();
    contact_sheet(&dir.join("contact"), &reference.image, &sheet, &crops)?;
    write_png_preview(&dir.join("reference.png"), &reference.image)?;

    write_file_atomically(&dir.join("summary.csv"), summary_csv(&summary).as_bytes())?;
    let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
    write_file_atomically(&dir.join("summary.json"), json.as_bytes())?;
    let chains = super::chain_diagnostics::collect(experiment, results);
    if !chains.is_empty() {
        super::chain_diagnostics::write_json(&dir.join("diagnostics.json"), &chains)?;
    }
    write_file_atomically(
        &dir.join("README.md"),
        readme(experiment, results, &summary, reference, &chains).as_bytes(),
    )?;
    Ok(summary)
}

/// `metrics.csv` with exactly docs/DESIGN.md §6's columns.
fn write_metrics_csv(path: &Path, rows: &[Row]) -> Result<()> {
    let mut text =
        String::from("estimator,run,checkpoint,seconds,passes,samples,relmse,rmse,mape\n");
    for r in rows {
        let _ = writeln!(
            text,
            "{},{},{},{:.6},{},{},{:.9e},{:.9e},{:.9e}",
            r.estimator,
            r.run,
            r.checkpoint,
            r.seconds,
            r.passes,
            r.samples,
            r.relmse,
            r.rmse,
            r.mape
        );
    }
    write_file_atomically(path, text.as_bytes())
}

fn opt(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.6e}")).unwrap_or_default()
}

fn summary_csv(s: &Summary) -> String {
    let mut text = String::from(
        "estimator,name,runs,seconds,passes,relmse,relmse_lo,relmse_hi,rmse,rmse_lo,rmse_hi,\
         mape,mape_lo,mape_hi,slope,slope_se,slope_passes,slope_passes_se,efficiency,\
         efficiency_lo,efficiency_hi,rel_bias2,rel_bias2_lo,rel_bias2_hi,rel_variance,\
         rel_variance_lo,rel_variance_hi,t_statistic,p_value,below_reference_noise\n",
    );
    for e in &s.estimators {
        let i = |v: &Interval| format!("{:.6e},{:.6e},{:.6e}", v.mean, v.lo, v.hi);
        let bv = e.bias_variance.as_ref();
        let _ = writeln!(
            text,
            "{},{},{},{:.4},{:.1},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            e.label,
            e.estimator,
            e.runs,
            e.seconds,
            e.passes,
            i(&e.relmse),
            i(&e.rmse),
            i(&e.mape),
            opt(e.slope_seconds.map(|f| f.slope)),
            opt(e.slope_seconds.map(|f| f.slope_se)),
            opt(e.slope_passes.map(|f| f.slope)),
            opt(e.slope_passes.map(|f| f.slope_se)),
            i(&e.efficiency),
            bv.map(|b| i(&b.relative_bias2))
                .unwrap_or_else(|| ",,".into()),
            bv.map(|b| i(&b.relative_variance))
                .unwrap_or_else(|| ",,".into()),
            opt(bv.map(|b| b.t_statistic)),
            opt(bv.map(|b| b.p_value)),
            e.below_reference_noise,
        );
    }
    text
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// `mean [lo, hi]`, or `mean [–]` from a single run (which gives no interval).
pub fn with_interval(i: &Interval, runs: usize) -> String {
    if runs < 2 {
        format!("{} [–]", sci(i.mean))
    } else {
        format!("{} [{}, {}]", sci(i.mean), sci(i.lo), sci(i.hi))
    }
}

fn readme(
    experiment: &Experiment,
    results: &ResultsDir,
    s: &Summary,
    reference: &Reference,
    chains: &[(String, Vec<serde_json::Value>)],
) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Experiment `{}`\n\n{}\n", s.experiment, s.description);
    let _ = writeln!(
        md,
        "Scene `{}`, budget {} per run, {} checkpoints, {} runs per estimator. \
         Reproduce with `cargo run --release -- run {}{}`.\n",
        experiment
            .scene
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or(""),
        s.budget,
        s.checkpoints,
        s.runs,
        experiment
            .spec_path
            .file_stem()
            .and_then(|f| f.to_str())
            .unwrap_or(""),
        if experiment.quick { " --quick" } else { "" }
    );
    let _ = writeln!(
        md,
        "Reference: `{}` ({}, {} passes, {:.0} s){}.\n",
        reference
            .path
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or(""),
        reference.info.estimator,
        reference.info.passes,
        reference.info.seconds,
        match s.reference_noise_relmse {
            Some(n) => format!(
                ", its own noise relMSE ≈ {} (from two independent halves): errors below it are not meaningful",
                sci(n)
            ),
            None => ", its own noise unknown".into(),
        }
    );
    if !s.missing_cells.is_empty() {
        let _ = writeln!(
            md,
            "**Incomplete:** no results yet for {}.\n",
            s.missing_cells.join(", ")
        );
    }
    let _ = writeln!(
        md,
        "| estimator | runs | seconds | passes | relMSE (95% CI) | slope vs time | efficiency | rel. bias² | rel. variance | t-test p |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    for e in &s.estimators {
        let flag = if e.below_reference_noise {
            " ⚠ below reference noise"
        } else {
            ""
        };
        let bv = e.bias_variance.as_ref();
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {:.0} | {}{} | {} | {} | {} | {} | {} |",
            e.label,
            e.runs,
            e.seconds,
            e.passes,
            with_interval(&e.relmse, e.runs),
            flag,
            e.slope_seconds
                .map(|f| format!("{:.2} ± {:.2}", f.slope, f.slope_se))
                .unwrap_or_else(|| "–".into()),
            sci(e.efficiency.mean),
            bv.map(|b| {
                let within_noise = s
                    .reference_noise_relmse
                    .is_some_and(|n| b.relative_bias2.lo <= n);
                format!(
                    "{} [{}, {}]{}",
                    sci(b.relative_bias2.mean),
                    sci(b.relative_bias2.lo),
                    sci(b.relative_bias2.hi),
                    if within_noise {
                        " (within ref. noise)"
                    } else {
                        ""
                    }
                )
            })
            .unwrap_or_else(|| "–".into()),
            bv.map(|b| sci(b.relative_variance.mean))
                .unwrap_or_else(|| "–".into()),
            bv.map(|b| format!("{:.3}", b.p_value))
                .unwrap_or_else(|| "–".into()),
        );
    }
    for region in &experiment.regions {
        let _ = writeln!(
            md,
            "\nRegion **{}** ({}×{} at {}, {}), final relMSE:",
            region.label, region.width, region.height, region.x, region.y
        );
        for e in &s.estimators {
            if let Some((_, i)) = e.regions.iter().find(|(l, _)| *l == region.label) {
                let _ = writeln!(md, "- {}: {}", e.label, with_interval(i, e.runs));
            }
        }
    }
    let _ = writeln!(
        md,
        "\nIntervals: 95% Student t over the runs; relMSE, RMSE, MAPE, efficiency and variance \
         cannot be negative, so a lower end below 0 (few runs) is shown as 0, which keeps the \
         t interval's coverage. \
         Slope: least squares of log relMSE (mean over runs) against log time over the later half of \
         the checkpoints (−1 for an unbiased estimator). Efficiency = 1 / (relMSE × seconds). \
         Relative bias² and variance: docs/DESIGN.md §5 across runs, each pixel term divided by \
         (y² + 0.01) as relMSE is; the t-test asks whether the mean signed error is 0. The \
         reference's own error enters (m − y)² as well, so a bias² whose interval reaches down \
         to the reference's noise cannot be told from zero (marked \"within ref. noise\").\n"
    );
    let _ = writeln!(md, "![relMSE against time](convergence.png)\n");
    let _ = writeln!(md, "![relMSE against passes](convergence-passes.png)\n");
    let _ = writeln!(md, "![bias² and variance against time](bias.png)\n");
    let _ = writeln!(md, "![final images and relative-error maps](contact.png)\n");
    if let Some(section) = super::chain_diagnostics::readme_section(chains) {
        md.push_str(&section);
    }
    if let Some(section) = super::photon_diagnostics::readme_section(chains) {
        md.push_str(&section);
    }
    if let Some(section) = super::strategies::readme_section(experiment, results) {
        md.push_str(&section);
    }
    let _ = writeln!(
        md,
        "Data: `metrics.csv` (every checkpoint of every run), `summary.csv`, `summary.json`."
    );
    md
}
