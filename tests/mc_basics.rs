//! The lecture's Monte Carlo basics against their closed forms (fixed seeds; each within
//! 4 standard errors measured from the samples themselves).

use mltbench::lecture::mc_basics::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

const SIGMAS: f64 = 4.0;

fn check(what: &str, e: Estimate, truth: f64) {
    let z = e.z(truth);
    eprintln!(
        "{what}: {:.6} ± {:.6} (closed form {truth:.6}, {z:+.2} σ)",
        e.value, e.std_error
    );
    assert!(
        z.abs() <= SIGMAS,
        "{what}: {} is {z:.2} σ from {truth}",
        e.value
    );
}

#[test]
fn buffons_needle_estimates_pi() {
    check(
        "Buffon l=0.8 t=1",
        buffon_pi(1_000_000, 0.8, 1.0, 1),
        std::f64::consts::PI,
    );
    check(
        "Buffon l=t=1",
        buffon_pi(1_000_000, 1.0, 1.0, 2),
        std::f64::consts::PI,
    );
}

#[test]
fn cos50_by_uniform_and_gaussian_importance_sampling() {
    let truth = cos50_integral();
    // Wallis: π·(49!!)/(50!!) ≈ 0.35311; cross-check against a midpoint rule.
    let m = 200_000;
    let midpoint: f64 = (0..m)
        .map(|i| {
            let x =
                -std::f64::consts::FRAC_PI_2 + (i as f64 + 0.5) * std::f64::consts::PI / m as f64;
            x.cos().powi(50)
        })
        .sum::<f64>()
        * std::f64::consts::PI
        / m as f64;
    assert!((midpoint - truth).abs() < 1e-9, "{midpoint} vs {truth}");
    let uniform = cos50_uniform(200_000, 3);
    check("cos^50 uniform", uniform, truth);
    let mut best = (f64::INFINITY, 0.0);
    for sigma in [0.08, 0.1, 0.12, 0.14, 0.16, 0.2, 0.3, 0.5] {
        let g = cos50_gaussian(200_000, sigma, 4);
        check(&format!("cos^50 Gaussian σ={sigma}"), g, truth);
        eprintln!(
            "  variance {:.3e} (uniform {:.3e})",
            g.sample_variance, uniform.sample_variance
        );
        if g.sample_variance < best.0 {
            best = (g.sample_variance, sigma);
        }
        if (0.12..=0.16).contains(&sigma) {
            assert!(
                g.sample_variance < uniform.sample_variance / 20.0,
                "σ={sigma}"
            );
        }
    }
    // The variance is smallest near σ = 1/√50 ≈ 0.141, where N(0, σ²) ∝ exp(−25x²) ≈ cos^50.
    assert!((0.12..=0.16).contains(&best.1), "best σ = {}", best.1);
}

#[test]
fn rejection_sampling_takes_c_proposals_on_average() {
    let (iterations, values) = rejection_beta22(200_000, 5);
    check("rejection iterations", iterations, 1.5);
    check("rejection sample mean", values, 0.5);
}

#[test]
fn inverse_transform_exponential_passes_chi_square() {
    let lambda = 2.0;
    let xs = exponential_inverse_transform(200_000, lambda, 6);
    // 20 bins of equal probability: edges at the quantiles −ln(1 − k/20)/λ.
    let bins = 20;
    let mut counts = vec![0f64; bins];
    for x in &xs {
        let cdf = 1.0 - (-lambda * x).exp();
        counts[((cdf * bins as f64) as usize).min(bins - 1)] += 1.0;
    }
    let expected = xs.len() as f64 / bins as f64;
    let chi2: f64 = counts
        .iter()
        .map(|c| (c - expected).powi(2) / expected)
        .sum();
    let p = 1.0 - ChiSquared::new((bins - 1) as f64).unwrap().cdf(chi2);
    eprintln!("exponential χ² = {chi2:.2}, p = {p:.3}");
    assert!(p > 1e-3, "χ² = {chi2}, p = {p}");
}

#[test]
fn balance_heuristic_beats_the_plain_average_of_two_strategies() {
    let balance = two_strategies(200_000, true, 7);
    let naive = two_strategies(200_000, false, 8);
    check("MIS balance", balance, MIS_INTEGRAL);
    check("MIS naive average", naive, MIS_INTEGRAL);
    eprintln!(
        "variance: balance {:.5}, naive {:.5}",
        balance.sample_variance, naive.sample_variance
    );
    assert!(balance.sample_variance < naive.sample_variance);
}

#[test]
fn control_variates_with_the_optimal_beta_beat_beta_one() {
    let truth = std::f64::consts::E - 1.0;
    let (optimal, beta) = control_variate_exp(200_000, None, 9);
    let (one, _) = control_variate_exp(200_000, Some(1.0), 10);
    let (plain, _) = control_variate_exp(200_000, Some(0.0), 11);
    check("control variate β*", optimal, truth);
    check("control variate β=1", one, truth);
    check("no control variate", plain, truth);
    // β* = 6(3 − e) ≈ 1.690; variances in closed form: Var(e^x) = (e² − 1)/2 − (e − 1)²,
    // with β: Var(e^x) − 2β Cov + β² Var(x), Cov = (3 − e)/2, Var(x) = 1/12.
    let e = std::f64::consts::E;
    let var_f = (e * e - 1.0) / 2.0 - (e - 1.0).powi(2);
    let var_with = |b: f64| var_f - 2.0 * b * (3.0 - e) / 2.0 + b * b / 12.0;
    assert!(
        (beta - control_variate_optimal_beta()).abs() < 0.02,
        "β̂ = {beta}"
    );
    for (what, est, b) in [
        ("β*", optimal, beta),
        ("β=1", one, 1.0),
        ("none", plain, 0.0),
    ] {
        let rel = est.sample_variance / var_with(b) - 1.0;
        eprintln!(
            "variance {what}: {:.5} (closed form {:.5})",
            est.sample_variance,
            var_with(b)
        );
        assert!(rel.abs() < 0.05, "{what}: {rel}");
    }
    assert!(optimal.sample_variance < one.sample_variance / 5.0);
}

#[test]
fn the_4d_example_matches_its_1d_reduction() {
    let truth = cos50_4d_integral();
    // Cross-check the reduction with a 4D midpoint rule (24⁴ points; the integrand is smooth).
    let k = 24;
    let mut sum = 0.0;
    for a in 0..k {
        for b in 0..k {
            for c in 0..k {
                for d in 0..k {
                    let m = |i: usize| (i as f64 + 0.5) / k as f64;
                    sum += (m(a) * m(b) * m(c) * m(d)).cos().powi(50);
                }
            }
        }
    }
    let midpoint = sum / (k as f64).powi(4);
    assert!(
        (midpoint - truth).abs() < 2e-3,
        "midpoint {midpoint} vs {truth}"
    );
    check(
        "cos^50(xyzw) over [0,1]^4",
        cos50_4d_uniform(400_000, 12),
        truth,
    );
}
