//! An experiment's `[strategies]` table: a `bdpt` render that keeps one image per strategy
//! (s, t), and a report of how much of the image and of each region every strategy carries
//! (its weighted image's share of the mean luminance there). Written under
//! `results/NAME/strategies/`: the pyramids (`pyramid-weighted.png`,
//! `pyramid-unweighted.png`), `strategies.csv` (whole image) and `regions.csv` (region,
//! s, t, length, share). Rendered once, with `prepare` (before the cells), and kept.

use std::fmt::Write as _;
use std::path::PathBuf;

use indicatif::ProgressBar;

use super::Experiment;
use super::runner::{ResultsDir, run_seed};
use crate::error::{Error, Location, Result};
use crate::estimator::{self, Params};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::strategy_images;
use crate::render::{Budget, render};
use crate::scene::Scene;

/// Where the strategy files go.
pub fn folder(results: &ResultsDir) -> PathBuf {
    results.dir.join("strategies")
}

/// Renders the strategy images unless they are there already; nothing without a
/// `[strategies]` table.
pub fn ensure(
    experiment: &Experiment,
    scene: &Scene,
    results: &ResultsDir,
    bar: &ProgressBar,
) -> Result<()> {
    let Some(spec) = &experiment.strategies else {
        return Ok(());
    };
    let dir = folder(results);
    if dir.join("regions.csv").is_file() {
        return Ok(());
    }
    let mut params = spec.params.clone();
    params.push("strategies=true".into());
    let params = Params::parse(&params)?;
    let seed = run_seed(experiment, "[strategies]", 0);
    let mut bdpt = estimator::create("bdpt", &params, scene, seed).map_err(|e| {
        Error::input(
            Location::file(&experiment.spec_path),
            format!("[strategies]: {e}"),
        )
    })?;
    bar.set_message(format!(
        "{}: bdpt's strategies, {} passes",
        experiment.name, spec.passes
    ));
    let out = render(scene, bdpt.as_mut(), Budget::Passes(spec.passes), |_, _| {});
    let images = bdpt
        .strategy_images()
        .expect("bdpt with strategies=true keeps them");
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    strategy_images::write(&dir, &out.image, &images, false)?;
    // Each region's share per strategy; the whole image first.
    let mut csv = String::from("region,s,t,length,share\n");
    let whole = (
        "whole image".to_string(),
        0,
        0,
        out.image.width,
        out.image.height,
    );
    let regions = std::iter::once(whole).chain(
        experiment
            .regions
            .iter()
            .map(|r| (r.label.clone(), r.x, r.y, r.width, r.height)),
    );
    for (label, x, y, w, h) in regions {
        let total = mean_luminance(&out.image, x, y, w, h);
        for im in &images {
            let share = if total > 0.0 {
                mean_luminance(&im.weighted, x, y, w, h) / total
            } else {
                0.0
            };
            let _ = writeln!(
                csv,
                "{label},{},{},{},{share:.6e}",
                im.s,
                im.t,
                im.s + im.t - 1
            );
        }
    }
    write_file_atomically(&dir.join("regions.csv"), csv.as_bytes())
}

/// Mean BT.709 luminance of the `w` × `h` rectangle at (x, y).
fn mean_luminance(image: &Image, x: u32, y: u32, w: u32, h: u32) -> f64 {
    let mut sum = 0.0;
    for j in y..y + h {
        for i in x..x + w {
            let c = image.get(i, j);
            sum += 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        }
    }
    sum / (w as f64 * h as f64).max(1.0)
}

/// The report's section on the strategies, if they were rendered: the pyramids, and a table
/// of the strategies that carry at least 2% of the image or of a region.
pub fn readme_section(experiment: &Experiment, results: &ResultsDir) -> Option<String> {
    let spec = experiment.strategies.as_ref()?;
    let text = std::fs::read_to_string(folder(results).join("regions.csv")).ok()?;
    // (region, s, t, share) rows.
    let rows: Vec<(String, usize, usize, f64)> = text
        .lines()
        .skip(1)
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            (f.len() == 5).then(|| {
                Some((
                    f[0].to_string(),
                    f[1].parse().ok()?,
                    f[2].parse().ok()?,
                    f[4].parse().ok()?,
                ))
            })?
        })
        .collect();
    let mut regions: Vec<String> = Vec::new();
    for (r, ..) in &rows {
        if !regions.contains(r) {
            regions.push(r.clone());
        }
    }
    let mut strategies: Vec<(usize, usize)> = Vec::new();
    for &(_, s, t, share) in &rows {
        if share >= 0.02 && !strategies.contains(&(s, t)) {
            strategies.push((s, t));
        }
    }
    strategies.sort_by_key(|&(s, t)| (s + t, s));
    let share = |region: &str, s: usize, t: usize| {
        rows.iter()
            .find(|(r, rs, rt, _)| r == region && *rs == s && *rt == t)
            .map_or(0.0, |x| x.3)
    };
    let mut md = String::new();
    let _ = writeln!(
        md,
        "\n## Which strategy carries which light\n\n`bdpt` with one image per strategy \
         (s light vertices, t camera vertices, path length s + t − 1), {} passes{}: each \
         strategy's weighted image's share of the mean luminance of the image and of each \
         region. Strategies carrying at least 2% somewhere; the rest in the last row.\n",
        spec.passes,
        if spec.params.is_empty() {
            String::new()
        } else {
            format!(" (`{}`)", spec.params.join(" "))
        }
    );
    let _ = writeln!(md, "| (s, t) | length | {} |", regions.join(" | "));
    let _ = writeln!(md, "|---|---|{}", "---|".repeat(regions.len()));
    for &(s, t) in &strategies {
        let cells: Vec<String> = regions
            .iter()
            .map(|r| format!("{:.1}%", 100.0 * share(r, s, t)))
            .collect();
        let _ = writeln!(md, "| ({s}, {t}) | {} | {} |", s + t - 1, cells.join(" | "));
    }
    let rest: Vec<String> = regions
        .iter()
        .map(|r| {
            let listed: f64 = strategies.iter().map(|&(s, t)| share(r, s, t)).sum();
            let all: f64 = rows.iter().filter(|x| &x.0 == r).map(|x| x.3).sum();
            format!("{:.1}%", 100.0 * (all - listed))
        })
        .collect();
    let _ = writeln!(md, "| others | | {} |", rest.join(" | "));
    let _ = writeln!(
        md,
        "\n![weighted strategies](strategies/pyramid-weighted.png)\n\n\
         ![unweighted strategies](strategies/pyramid-unweighted.png)\n\n\
         Data: `strategies/regions.csv`, `strategies/strategies.csv`.\n"
    );
    Some(md)
}
