//! The Metropolis chain on a 2D toy target with a known integral: the cos⁵⁰ bump of the
//! lecture, f(x, y) = c(x)·c(y) + ε with c(x) = cos⁵⁰(π(x − ½)), whose integral over [0, 1)²
//! is W² + ε with Wallis' W = ∫₀¹ c = 49!!/50!!.
//!
//! * 16 independent chains (fixed seeds) estimate the integral of f over the left half of
//!   the square through expected-value splatting (`mlt::chain`), with b the known integral;
//!   their mean lands within 4 σ of the closed form, σ from the chains' spread.
//! * The chains' states, histogrammed on an 8 × 8 grid, pass a χ² test against the cells'
//!   integrals, with the counts scaled to the effective sample size: the chain length over
//!   its integrated autocorrelation time (Sokal's window, measured here).
//!
//! Both for Kelemen's mutation and for the Gaussian one, with large steps and without.

use glam::Vec2;
use mltbench::estimator::mlt::autocorrelation::{SOKAL_C, integrated_autocorrelation_time};
use mltbench::estimator::mlt::chain::Chain;
use mltbench::estimator::mlt::importance::ImportanceKind;
use mltbench::estimator::mlt::settings::{ChainSettings, Lengths, Normalisation};
use mltbench::estimator::mlt::target::Contributions;
use mltbench::film::SplatList;
use mltbench::math::Rgb;
use mltbench::sampler::primary_sample::{Mutation, PrimarySampleSampler};
use mltbench::sampler::{Sampler, Stream};
use statrs::distribution::{ChiSquared, ContinuousCDF};

const FLOOR: f64 = 0.01;

fn bump(x: f64) -> f64 {
    (std::f64::consts::PI * (x - 0.5)).cos().powi(50)
}

/// ∫₀¹ c = π⁻¹ · π · ∏_{k=1}^{25} (2k − 1)/(2k) (Wallis).
fn wallis() -> f64 {
    (1..=25)
        .map(|k| (2 * k - 1) as f64 / (2 * k) as f64)
        .product()
}

/// ∫_a^b c by Simpson's rule on 2000 intervals (c is smooth: error far below 1e-12).
fn bump_integral(a: f64, b: f64) -> f64 {
    let n = 2000;
    let h = (b - a) / n as f64;
    let mut sum = bump(a) + bump(b);
    for i in 1..n {
        sum += bump(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

fn f(x: f64, y: f64) -> f64 {
    bump(x) * bump(y) + FLOOR
}

/// The toy path function: two numbers of the camera stream make the point; its value
/// is f, splatted at the point.
fn evaluate(sampler: &mut PrimarySampleSampler, out: &mut Contributions) -> (u64, u64) {
    out.clear();
    sampler.start_stream(Stream::Camera);
    let p = sampler.next_2d();
    let v = f(p.x as f64, p.y as f64) as f32;
    let mut invalid = 0;
    out.push(p, Rgb::new(v, v, v), &mut invalid);
    out.finish();
    (0, invalid)
}

struct Run {
    /// The chain's estimate of ∫ over x < ½.
    left_half: f64,
    histogram: Vec<u64>,
    xs: Vec<f32>,
    luminance: Vec<f32>,
}

fn run_chain(settings: &ChainSettings, seed: u64, steps: usize, integral: f64) -> Run {
    // Start from a point drawn in proportion to f among 1000 independent ones (the
    // estimator's bootstrap, in small).
    let candidates: Vec<(f64, u64)> = (0..1000u64)
        .map(|j| {
            let mut s =
                PrimarySampleSampler::new(&[seed, j], settings.large_step, settings.mutation);
            let mut out = Contributions::default();
            evaluate(&mut s, &mut out);
            (out.luminance, j)
        })
        .collect();
    let total: f64 = candidates.iter().map(|c| c.0).sum();
    let mut pick = 0.37 * total;
    let j = candidates
        .iter()
        .find(|c| {
            pick -= c.0;
            pick < 0.0
        })
        .map_or(0, |c| c.1);
    let mut sampler = PrimarySampleSampler::new(&[seed, j], settings.large_step, settings.mutation);
    let mut current = Contributions::default();
    evaluate(&mut sampler, &mut current);
    sampler.start_chain(&[seed, 1 << 40]);
    let mut chain = Chain::new(sampler, current);
    let mut splats = SplatList::new();
    let mut left = 0.0;
    let mut histogram = vec![0u64; 64];
    let mut xs = Vec::with_capacity(steps);
    for _ in 0..steps {
        splats.clear();
        chain.step(settings, integral, &mut splats, evaluate);
        left += splats
            .entries()
            .iter()
            .filter(|(p, _)| p.x < 0.5)
            .map(|(_, v)| v.luminance() as f64)
            .sum::<f64>();
        let p: Vec2 = chain.current.entries[0].0;
        let cell = (p.x * 8.0) as usize + 8 * (p.y * 8.0) as usize;
        histogram[cell.min(63)] += 1;
        xs.push(p.x);
    }
    Run {
        left_half: left / steps as f64,
        histogram,
        xs,
        luminance: chain.luminance_series.clone(),
    }
}

fn check(settings: ChainSettings) {
    let w = wallis();
    let integral = w * w + FLOOR;
    let left_truth = 0.5 * w * w + 0.5 * FLOOR;
    let steps = 40_000;
    let runs: Vec<Run> = (0..16u64)
        .map(|seed| run_chain(&settings, 100 + seed, steps, integral))
        .collect();
    let k = runs.len() as f64;
    let mean = runs.iter().map(|r| r.left_half).sum::<f64>() / k;
    let var = runs
        .iter()
        .map(|r| (r.left_half - mean).powi(2))
        .sum::<f64>()
        / (k - 1.0);
    let sigma = (var / k).sqrt();
    assert!(
        (mean - left_truth).abs() < 4.0 * sigma,
        "{settings:?}: left half {mean} against {left_truth} ± {sigma}"
    );

    // χ² on the pooled histogram, counts scaled to the effective sample size.
    let xs: Vec<&[f32]> = runs.iter().map(|r| r.xs.as_slice()).collect();
    let lum: Vec<&[f32]> = runs.iter().map(|r| r.luminance.as_slice()).collect();
    let tau_x = integrated_autocorrelation_time(&xs, SOKAL_C).unwrap();
    let tau_l = integrated_autocorrelation_time(&lum, SOKAL_C).unwrap();
    assert!(tau_x.converged, "{tau_x:?}");
    let tau = tau_x.tau.max(tau_l.tau).max(1.0);
    let n = k * steps as f64;
    let scale = 1.0 / tau;
    let mut chi2 = 0.0;
    for cy in 0..8 {
        for cx in 0..8 {
            let (x0, y0) = (cx as f64 / 8.0, cy as f64 / 8.0);
            let cell = bump_integral(x0, x0 + 0.125) * bump_integral(y0, y0 + 0.125) + FLOOR / 64.0;
            let expected = n * cell / integral * scale;
            let observed =
                runs.iter().map(|r| r.histogram[cx + 8 * cy]).sum::<u64>() as f64 * scale;
            chi2 += (observed - expected).powi(2) / expected;
        }
    }
    let p = 1.0 - ChiSquared::new(63.0).unwrap().cdf(chi2);
    assert!(
        p > 1e-4,
        "{settings:?}: χ² {chi2:.1} (63 dof, τ {tau:.1}) p = {p:e}"
    );
}

fn settings(large_step: f64, mutation: Mutation) -> ChainSettings {
    ChainSettings {
        large_step,
        mutation,
        bootstrap: 1000,
        chains: 1,
        kelemen_weights: false,
        importance: ImportanceKind::Luminance,
        normalisation: Normalisation::Bootstrap,
        lengths: Lengths::Mutable,
    }
}

#[test]
fn kelemen_mutation_with_large_steps() {
    check(settings(
        0.3,
        Mutation::Kelemen {
            s1: 1.0 / 1024.0,
            s2: 1.0 / 64.0,
        },
    ));
}

#[test]
fn kelemen_mutation_small_steps_only() {
    check(settings(
        0.0,
        Mutation::Kelemen {
            s1: 1.0 / 256.0,
            s2: 1.0 / 8.0,
        },
    ));
}

#[test]
fn gaussian_mutation() {
    check(settings(0.1, Mutation::Gaussian { sigma: 0.05 }));
}

/// Kelemen's weights (the chain combined with its large steps as independent samples)
/// estimate the same integral.
#[test]
fn kelemen_weights() {
    let mut s = settings(
        0.3,
        Mutation::Kelemen {
            s1: 1.0 / 1024.0,
            s2: 1.0 / 64.0,
        },
    );
    s.kelemen_weights = true;
    check(s);
}
