//! The `sampling-spectra` experiment: the expected power spectrum of each 2D sample pattern,
//! averaged over realisations, as an image, and its radial mean as a plot — the pictures
//! that tell white noise (flat), blue noise (a dark low-frequency disk) and regular grids
//! (spikes) apart (Ulichney 1987; Heck, Schlömer & Deussen 2013).
//!
//! For N points x_j the periodogram at integer frequency f is P(f) = |Σ_j e^(−2πi f·x_j)|² / N
//! (1 for uniform random points at every f ≠ 0). The exponential factors per point and
//! axis, so the whole (2F+1)² grid costs N·(2F+1)² complex products per realisation.

use std::f64::consts::PI;
use std::fmt::Write as _;

use serde::Deserialize;
use toml::Spanned;

use super::SpecText;
use crate::error::{Error, Result};
use crate::experiment::plot::viridis;
use crate::experiment::plot::{Band, Series, convergence_plot};
use crate::io::atomic::write_file_atomically;
use crate::io::png::write_rgb8_png;
use crate::sampler::pattern::{Pattern, points};

/// Smallest power drawn in the radial plot.
const PLOT_FLOOR: f64 = 1e-4;

/// `experiments/sampling-spectra.toml`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SamplingSpectraSpec {
    pub kind: String,
    pub description: String,
    /// Points per realisation.
    pub points: Spanned<usize>,
    /// Realisations averaged.
    pub realisations: Spanned<usize>,
    /// Highest frequency per axis: the image is (2F+1)².
    pub max_frequency: Spanned<usize>,
    #[serde(default)]
    pub seed: u64,
}

/// Most points per realisation: the phase tables take 32·N·(2F+1) bytes (270 MB at
/// F = 256), and one realisation costs N·(2F+1)² complex products per pattern.
pub const MAX_POINTS: usize = 1 << 14;

/// Most realisations averaged.
pub const MAX_REALISATIONS: usize = 1024;

/// The checked spec.
#[derive(Clone, Debug)]
pub struct SamplingSpectra {
    pub description: String,
    pub points: usize,
    pub realisations: usize,
    pub max_frequency: usize,
    pub seed: u64,
}

/// Reads and checks the spec.
pub fn parse(spec: SpecText) -> Result<SamplingSpectra> {
    let file: SamplingSpectraSpec = spec.parse()?;
    Ok(SamplingSpectra {
        points: spec.count(&file.points, "points", 4..=MAX_POINTS)?,
        realisations: spec.count(&file.realisations, "realisations", 1..=MAX_REALISATIONS)?,
        max_frequency: spec.count(&file.max_frequency, "max_frequency", 4..=256)?,
        description: file.description,
        seed: file.seed,
    })
}

/// The expected periodogram on the (2F+1)² grid of integer frequencies, row-major from
/// (−F, −F); the DC term is left at 0 (it is always N).
pub fn expected_spectrum(
    pattern: Pattern,
    n: usize,
    realisations: usize,
    max_frequency: usize,
    seed: u64,
) -> Vec<f64> {
    let side = 2 * max_frequency + 1;
    let mut sum = vec![0.0f64; side * side];
    let f0 = max_frequency as i64;
    for r in 0..realisations {
        let pts = points(pattern, n, seed ^ ((r as u64 + 1) << 24));
        // e^(−2πi f x) for every point and frequency, per axis.
        let phases = |coord: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
            let mut table = Vec::with_capacity(pts.len() * side);
            for j in 0..pts.len() {
                let x = coord(j);
                for k in 0..side {
                    let a = -2.0 * PI * (k as i64 - f0) as f64 * x;
                    table.push((a.cos(), a.sin()));
                }
            }
            table
        };
        let ex = phases(&|j| pts[j].x as f64);
        let ey = phases(&|j| pts[j].y as f64);
        for ky in 0..side {
            for kx in 0..side {
                let (mut re, mut im) = (0.0, 0.0);
                for j in 0..pts.len() {
                    let (a, b) = ex[j * side + kx];
                    let (c, d) = ey[j * side + ky];
                    re += a * c - b * d;
                    im += a * d + b * c;
                }
                sum[ky * side + kx] += (re * re + im * im) / pts.len() as f64;
            }
        }
    }
    let centre = max_frequency * side + max_frequency;
    for (i, v) in sum.iter_mut().enumerate() {
        *v = if i == centre {
            0.0
        } else {
            *v / realisations as f64
        };
    }
    sum
}

/// Mean of the spectrum over rings of unit width: entry r averages the frequencies with
/// r − ½ ≤ |f| < r + ½, for r = 1 … F.
pub fn radial_mean(spectrum: &[f64], max_frequency: usize) -> Vec<f64> {
    let side = 2 * max_frequency + 1;
    let mut sums = vec![0.0f64; max_frequency + 1];
    let mut counts = vec![0usize; max_frequency + 1];
    for ky in 0..side {
        for kx in 0..side {
            let (fx, fy) = (
                kx as f64 - max_frequency as f64,
                ky as f64 - max_frequency as f64,
            );
            let r = (fx * fx + fy * fy).sqrt().round() as usize;
            if (1..=max_frequency).contains(&r) {
                sums[r] += spectrum[ky * side + kx];
                counts[r] += 1;
            }
        }
    }
    (1..=max_frequency)
        .map(|r| sums[r] / counts[r].max(1) as f64)
        .collect()
}

/// Runs the experiment into `out`: `PATTERN.png` spectra, `radial.png/.svg`, `radial.csv`,
/// `README.md`.
pub fn run(spec: SpecText, out: &std::path::Path) -> Result<()> {
    let spec = parse(spec)?;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let f = spec.max_frequency;
    let side = 2 * f + 1;
    let mut series = Vec::new();
    let mut csv = String::from("pattern,frequency,power\n");
    let mut md = format!(
        "# Experiment `sampling-spectra`\n\n{}\n\n{} points, {} realisations averaged, \
         frequencies up to {f} per axis (DC removed). Images: log₁₀ power from 10⁻² (dark) \
         to 10¹ (bright), viridis; uniform random points give 1 everywhere. Reproduce with \
         `cargo run --release -- run sampling-spectra`.\n\n",
        spec.description, spec.points, spec.realisations
    );
    for pattern in Pattern::ALL {
        let spectrum = expected_spectrum(pattern, spec.points, spec.realisations, f, spec.seed);
        // Each frequency drawn as a ZOOM×ZOOM block, so the picture is readable.
        const ZOOM: usize = 3;
        let mut bytes = Vec::with_capacity(3 * side * side * ZOOM * ZOOM);
        for row in 0..side * ZOOM {
            for col in 0..side * ZOOM {
                let v = spectrum[(row / ZOOM) * side + col / ZOOM];
                let t = ((v.max(1e-2).log10() + 2.0) / 3.0).clamp(0.0, 1.0) as f32;
                bytes.extend(viridis(t));
            }
        }
        let px = (side * ZOOM) as u32;
        write_rgb8_png(&out.join(format!("{pattern}.png")), px, px, &bytes)?;
        let radial = radial_mean(&spectrum, f);
        for (i, p) in radial.iter().enumerate() {
            let _ = writeln!(csv, "{pattern},{},{p:.6e}", i + 1);
        }
        let x: Vec<f64> = (1..=f).map(|r| r as f64).collect();
        // The regular grid's spectrum is exactly 0 off its peaks (10⁻³⁰ in floating point):
        // drawn at the plot's floor so that the other patterns stay readable.
        let radial: Vec<f64> = radial.iter().map(|p| p.max(PLOT_FLOOR)).collect();
        series.push(Series {
            label: pattern.to_string(),
            band: Band {
                lo: radial.clone(),
                hi: radial.clone(),
                mean: radial,
                x,
            },
        });
        let _ = writeln!(md, "**{pattern}**\n\n![{pattern}]({pattern}.png)\n");
    }
    convergence_plot(
        &out.join("radial"),
        "Radially averaged power spectrum",
        "frequency |f|",
        "power",
        &series,
        &[],
    )?;
    let _ = writeln!(
        md,
        "![radial means](radial.png)\n\nRadial means below 10⁻⁴ (the regular grid's exact \
         zeros between its peaks) are drawn at 10⁻⁴; `radial.csv` has the values."
    );
    write_file_atomically(&out.join("radial.csv"), csv.as_bytes())?;
    write_file_atomically(&out.join("README.md"), md.as_bytes())
}
