//! The `sampling-rates` experiment: how the mean squared error of a 2D integral estimate
//! falls with the number of points N for each sample pattern, on a smooth integrand and on a
//! discontinuous one (a disk's indicator), with fitted log-log slopes beside the theory.
//!
//! For the disk (a discontinuity along a curve) Pilleboue et al. 2015 give the rates the
//! lecture quotes: random N⁻¹, jittered N⁻¹·⁵, Poisson disk N⁻¹, CCVT N⁻¹·⁵; a smooth
//! integrand lets jittered sampling reach N⁻² in 2D.
//!
//! Those rates are asymptotic, so slopes are fitted over the later half of each pattern's
//! point counts (`fit_later_half`, docs/DESIGN.md §5's rule for convergence slopes). Poisson disk
//! needs it most. With P(ν) the expected power spectrum of the points (P = 1 for random
//! points), Pilleboue et al.'s Var = (1/N)·Σ_{ν≠0} |f̂(ν)|² P(ν); dart throwing leaves a
//! low-frequency plateau P₀ > 0 (≈ 0.06 at `poisson::RELATIVE_RADIUS` = 0.75) inside its
//! blue-noise ring at |ν| ≈ √N. The disk's |f̂|² ∝ |ν|⁻³ puts most of Σ|f̂|² = a(1 − a),
//! a its area, at low ν, so N·Var ≈ P₀·a(1 − a) + B/√N (measured: B ≈ 0.14). The B term,
//! power above the ring, falls like N⁻¹·⁵ and dominates below N ≈ 130, so the local slope
//! is −1.37 at N = 16 … 32, −1.14 at 512 … 1024 and about −1.05 above 8192 (65536 … 128
//! realisations per N, 64 translations each). `experiments/sampling-rates.toml` therefore
//! runs every pattern but CCVT to N = 181², so that the fit takes N = 32² … 181².

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;

use glam::Vec2;
use rayon::prelude::*;
use serde::Deserialize;
use toml::Spanned;

use super::SpecText;
use crate::error::{Error, Result};
use crate::experiment::plot::{Band, Series, convergence_plot};
use crate::experiment::statistics::{SlopeFit, fit_later_half, later_half};
use crate::io::atomic::write_file_atomically;
use crate::sampler::independent::{IndependentSampler, hash_words};
use crate::sampler::pattern::{Pattern, points, uniform_f64};

/// `experiments/sampling-rates.toml`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SamplingRatesSpec {
    pub kind: String,
    pub description: String,
    /// Grid sides k: the point counts are N = k² (square, so every pattern gets its grid).
    pub sides: Spanned<Vec<usize>>,
    /// Sides for one pattern instead of `sides` (CCVT, whose optimisation is slow at large N).
    #[serde(default)]
    pub pattern_sides: BTreeMap<String, Spanned<Vec<usize>>>,
    /// Independent realisations per (pattern, N).
    pub realisations: Spanned<usize>,
    /// Random translations of the disk per realisation (see `Settings::shifts`).
    pub shifts: Spanned<usize>,
    #[serde(default)]
    pub seed: u64,
    /// Patterns to compare (default: all).
    pub patterns: Option<Spanned<Vec<String>>>,
}

/// Fewest sides per pattern: the slope is fitted over the later half of them.
pub const MIN_SIDES: usize = 6;

/// Most sides per pattern.
pub const MAX_SIDES: usize = 64;

/// Largest grid side: N = 256² = 65536 points, the most a pattern makes for a renderer too.
pub const MAX_SIDE: usize = 256;

/// Most realisations per (pattern, N).
pub const MAX_REALISATIONS: usize = 16384;

/// Most translations of the disk per realisation.
pub const MAX_SHIFTS: usize = 4096;

/// The checked spec.
#[derive(Clone, Debug)]
pub struct SamplingRates {
    pub description: String,
    /// Each pattern with its sides, in the order they are run.
    pub patterns: Vec<(Pattern, Vec<usize>)>,
    pub settings: Settings,
}

/// Reads and checks the spec.
pub fn parse(spec: SpecText) -> Result<SamplingRates> {
    let file: SamplingRatesSpec = spec.parse()?;
    let check_sides = |sides: &Spanned<Vec<usize>>, key: &str| -> Result<Vec<usize>> {
        let fail = |m: String| spec.error_at(sides.span(), key, m);
        let k = sides.get_ref();
        if !(MIN_SIDES..=MAX_SIDES).contains(&k.len()) {
            return Err(fail(format!(
                "{key} needs between {MIN_SIDES} and {MAX_SIDES} grid sides (the slope is \
                 fitted over the later half), got {}",
                k.len()
            )));
        }
        if let Some(bad) = k.iter().find(|&&s| !(2..=MAX_SIDE).contains(&s)) {
            return Err(fail(format!(
                "{key}: every side must be between 2 and {MAX_SIDE} (N = k² points), got {bad}"
            )));
        }
        if k.windows(2).any(|w| w[0] >= w[1]) {
            return Err(fail(format!(
                "{key} must increase strictly: the slope is fitted over the later half, the \
                 largest N, and needs distinct N there"
            )));
        }
        Ok(k.clone())
    };
    let sides = check_sides(&file.sides, "sides")?;
    let patterns: Vec<Pattern> = match &file.patterns {
        Some(listed) if !listed.get_ref().is_empty() => {
            let fail = |m: String| spec.error_at(listed.span(), "patterns", m);
            let mut out = Vec::new();
            for name in listed.get_ref() {
                let p = name.parse::<Pattern>().map_err(fail)?;
                if out.contains(&p) {
                    return Err(fail(format!("pattern \"{name}\" is listed twice")));
                }
                out.push(p);
            }
            out
        }
        _ => Pattern::ALL.to_vec(),
    };
    let mut sides_of: Vec<(Pattern, Vec<usize>)> = Vec::new();
    for (name, own) in &file.pattern_sides {
        let key = format!("pattern_sides.{name}");
        let pattern = name
            .parse::<Pattern>()
            .map_err(|m| spec.error_at(own.span(), &key, m))?;
        if !patterns.contains(&pattern) {
            return Err(spec.error_at(
                own.span(),
                &key,
                format!(
                    "{name} is not among the patterns run ({}): its sides would go unused",
                    patterns
                        .iter()
                        .map(|p| p.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        sides_of.push((pattern, check_sides(own, &key)?));
    }
    let settings = Settings {
        realisations: spec.count(&file.realisations, "realisations", 2..=MAX_REALISATIONS)?,
        shifts: spec.count(&file.shifts, "shifts", 1..=MAX_SHIFTS)?,
        seed: file.seed,
    };
    Ok(SamplingRates {
        description: file.description,
        patterns: patterns
            .into_iter()
            .map(|p| {
                let own = sides_of.iter().find(|(q, _)| *q == p).map(|(_, s)| s);
                (p, own.unwrap_or(&sides).clone())
            })
            .collect(),
        settings,
    })
}

/// How each MSE is measured.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Independent point sets per N.
    pub realisations: usize,
    /// Translations of the disk on the unit torus per point set, each uniform: the disk
    /// estimate is that of Pilleboue et al.'s homogenised (randomly translated) pattern, which
    /// is what their rates describe. Averaging several translations of one point set lowers the
    /// noise of the MSE at little cost (S·N indicator evaluations against generating the set).
    /// The smooth integrand is not translated: on the torus it would have kinks along the
    /// seam, and its rates (jittered N⁻², Owen-scrambled Sobol' N⁻³) are for it as it is.
    pub shifts: usize,
    pub seed: u64,
}

/// The two integrands over [0, 1]².
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrand {
    /// sin(πx)·sin(πy): ∫ = 4/π².
    Smooth,
    /// The indicator of the disk of radius 0.3 centred at (0.47, 0.52): ∫ = 0.09π.
    Disk,
}

/// The disk's radius and centre.
const DISK_RADIUS: f64 = 0.3;
const DISK_CENTRE: (f64, f64) = (0.47, 0.52);

impl Integrand {
    pub const ALL: [Integrand; 2] = [Integrand::Smooth, Integrand::Disk];

    pub fn name(self) -> &'static str {
        match self {
            Integrand::Smooth => "smooth",
            Integrand::Disk => "disk",
        }
    }

    pub fn eval(self, p: Vec2) -> f64 {
        let (x, y) = (p.x as f64, p.y as f64);
        match self {
            Integrand::Smooth => (PI * x).sin() * (PI * y).sin(),
            Integrand::Disk => disk_indicator(x - DISK_CENTRE.0, y - DISK_CENTRE.1),
        }
    }

    pub fn integral(self) -> f64 {
        match self {
            Integrand::Smooth => 4.0 / (PI * PI),
            Integrand::Disk => PI * DISK_RADIUS * DISK_RADIUS,
        }
    }

    /// The exponent of N in the MSE that theory gives for `pattern` (None: no clean rate).
    pub fn theory(self, pattern: Pattern) -> Option<f64> {
        match (self, pattern) {
            (_, Pattern::Independent) => Some(-1.0),
            (_, Pattern::Poisson) => Some(-1.0),
            (Integrand::Disk, Pattern::Stratified | Pattern::Ccvt | Pattern::Sobol) => Some(-1.5),
            (Integrand::Disk, Pattern::Regular) => Some(-1.5),
            (Integrand::Smooth, Pattern::Stratified | Pattern::Regular | Pattern::Ccvt) => {
                Some(-2.0)
            }
            (Integrand::Smooth, Pattern::Sobol) => Some(-3.0),
        }
    }
}

/// 1 if the offset (dx, dy) from the disk's centre, taken on the unit torus, is inside it.
/// The disk's diameter is below 1, so on the torus it is still a disk of area 0.09π.
fn disk_indicator(dx: f64, dy: f64) -> f64 {
    let wrap = |d: f64| d - (d + 0.5).floor();
    let (dx, dy) = (wrap(dx), wrap(dy));
    if dx * dx + dy * dy < DISK_RADIUS * DISK_RADIUS {
        1.0
    } else {
        0.0
    }
}

/// The point set of realisation `r` (the experiment's seeds since its first version).
fn realisation(pattern: Pattern, n: usize, r: usize, seed: u64) -> Vec<Vec2> {
    points(pattern, n, seed ^ ((r as u64) << 20) ^ n as u64)
}

/// Mean squared error of the N-point estimate of each integrand, indexed like
/// `Integrand::ALL`, over `settings.realisations` point sets (the disk also over
/// `settings.shifts` translations of each). Realisations run in parallel; the sum is taken in
/// their order, so the result does not depend on the thread count.
pub fn mse(pattern: Pattern, n: usize, settings: Settings) -> [f64; 2] {
    let per_set: Vec<[f64; 2]> = (0..settings.realisations)
        .into_par_iter()
        .map(|r| {
            let pts = realisation(pattern, n, r, settings.seed);
            let m = pts.len() as f64;
            let smooth = pts.iter().map(|&p| Integrand::Smooth.eval(p)).sum::<f64>() / m;
            let mut shift = IndependentSampler::new(hash_words(&[
                settings.seed,
                n as u64,
                r as u64,
                pattern as u64,
                SHIFT_STREAM,
            ]));
            let disk = (0..settings.shifts)
                .map(|_| {
                    let t = (uniform_f64(&mut shift), uniform_f64(&mut shift));
                    let (cx, cy) = (DISK_CENTRE.0 + t.0, DISK_CENTRE.1 + t.1);
                    let estimate = pts
                        .iter()
                        .map(|p| disk_indicator(p.x as f64 - cx, p.y as f64 - cy))
                        .sum::<f64>()
                        / m;
                    (estimate - Integrand::Disk.integral()).powi(2)
                })
                .sum::<f64>()
                / settings.shifts as f64;
            [(smooth - Integrand::Smooth.integral()).powi(2), disk]
        })
        .collect();
    let r = settings.realisations as f64;
    [
        per_set.iter().map(|e| e[0]).sum::<f64>() / r,
        per_set.iter().map(|e| e[1]).sum::<f64>() / r,
    ]
}

/// Keeps the translations' random stream apart from the patterns' own.
const SHIFT_STREAM: u64 = 0x0073_6869_6674; // "shift"

/// One integrand's MSE against N.
#[derive(Clone, Debug)]
pub struct Curve {
    pub ns: Vec<f64>,
    pub errors: Vec<f64>,
}

impl Curve {
    /// The power law fitted over the later half of the point counts, where the asymptotic
    /// rate shows (see the module comment).
    pub fn fit(&self) -> Option<SlopeFit> {
        fit_later_half(&self.ns, &self.errors)
    }
}

/// MSE against N = k² for every side k in `sides`, one curve per integrand (indexed like
/// `Integrand::ALL`), both from the same point sets.
pub fn rates(pattern: Pattern, sides: &[usize], settings: Settings) -> [Curve; 2] {
    let ns: Vec<f64> = sides.iter().map(|k| (k * k) as f64).collect();
    let errors: Vec<[f64; 2]> = sides
        .iter()
        .map(|k| mse(pattern, k * k, settings))
        .collect();
    [0, 1].map(|i| Curve {
        ns: ns.clone(),
        errors: errors.iter().map(|e| e[i]).collect(),
    })
}

/// Runs the experiment into `out`: `summary.csv` (pattern, integrand, slope, slope_se),
/// one plot per integrand, `README.md`.
pub fn run(spec: SpecText, out: &std::path::Path) -> Result<()> {
    let spec = parse(spec)?;
    let settings = spec.settings;
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let curves: Vec<(Pattern, &[usize], [Curve; 2])> = spec
        .patterns
        .iter()
        .map(|(pattern, sides)| (*pattern, &sides[..], rates(*pattern, sides, settings)))
        .collect();
    let mut csv = String::from("pattern,integrand,slope,slope_se,theory\n");
    let mut md = format!(
        "# Experiment `sampling-rates`\n\n{}\n\nN = k² points, {} realisations per point \
         count; the disk is also translated to {} uniform positions on the torus per \
         realisation (Pilleboue et al.'s homogenised patterns). MSE of the estimate of the \
         integral against its closed form; slopes fitted over the later half of each \
         pattern's point counts (the asymptotic range). Reproduce with \
         `cargo run --release -- run sampling-rates`.\n\n\
         | pattern | sides k (fitted) | integrand | fitted slope ± se | theory |\n\
         |---|---|---|---|---|\n",
        spec.description, settings.realisations, settings.shifts
    );
    for (i, integrand) in Integrand::ALL.into_iter().enumerate() {
        let mut series = Vec::new();
        for (pattern, sides, curve) in &curves {
            let curve = &curve[i];
            let fitted = later_half(sides);
            let theory = integrand.theory(*pattern);
            let t = theory.map(|t| format!("{t}")).unwrap_or_default();
            let sides_text = format!(
                "{}…{} ({}…{})",
                sides[0],
                sides[sides.len() - 1],
                fitted[0],
                fitted[fitted.len() - 1]
            );
            match curve.fit() {
                Some(f) => {
                    let _ = writeln!(
                        csv,
                        "{pattern},{},{:.4},{:.4},{t}",
                        integrand.name(),
                        f.slope,
                        f.slope_se
                    );
                    let _ = writeln!(
                        md,
                        "| {pattern} | {sides_text} | {} | {:.2} ± {:.2} | {} |",
                        integrand.name(),
                        f.slope,
                        f.slope_se,
                        if t.is_empty() {
                            "–".into()
                        } else {
                            t.clone()
                        }
                    );
                }
                None => {
                    let _ = writeln!(csv, "{pattern},{},,,{t}", integrand.name());
                    let _ = writeln!(
                        md,
                        "| {pattern} | {sides_text} | {} | (no fit: zero error) | {t} |",
                        integrand.name()
                    );
                }
            }
            series.push(Series {
                label: pattern.to_string(),
                band: Band {
                    lo: curve.errors.clone(),
                    hi: curve.errors.clone(),
                    mean: curve.errors.clone(),
                    x: curve.ns.clone(),
                },
            });
        }
        convergence_plot(
            &out.join(integrand.name()),
            &format!("MSE against N: {} integrand", integrand.name()),
            "points N",
            "mean squared error",
            &series,
            &[(-1.0, "N⁻¹"), (-1.5, "N⁻¹·⁵"), (-2.0, "N⁻²")],
        )?;
    }
    let _ = writeln!(
        md,
        "\nTheory: for the disk (a discontinuity along a curve), random and Poisson disk N⁻¹, \
         jittered, CCVT, scrambled Sobol' and the randomly translated regular grid N⁻¹·⁵ \
         (Pilleboue et al. 2015). For the smooth integrand (not translated, so the regular \
         grid is deterministic there) jittered sampling reaches N⁻² in 2D and Owen-scrambled \
         Sobol' N⁻³.\n\n\
         Poisson disk reaches its N⁻¹ only slowly: dart throwing leaves a small low-frequency \
         plateau in its spectrum (≈ 0.06 of white noise at the minimum distance used here); \
         its N⁻¹ term overtakes a steeper N⁻¹·⁵ term only above N ≈ 130, and the local slope \
         is still −1.14 between N = 512 and 1024 (a fit over N = 16 … 1024 gives about \
         −1.25). Fitting the later half of the point counts keeps N ≥ 1024 for it. The \
         randomly translated regular grid's error oscillates with N (the disk's radius \
         against the grid spacing), so its slope depends on which N are sampled. Sobol' \
         points form complete nets only when N is a power of two (here N = 4ʲ, the dips on \
         the smooth plot), so its smooth fit is not a rate.\n\n\
         ![smooth](smooth.png)\n\n![disk](disk.png)"
    );
    write_file_atomically(&out.join("summary.csv"), csv.as_bytes())?;
    write_file_atomically(&out.join("README.md"), md.as_bytes())
}
