//! The Monte Carlo basics a rendering course starts from, as measurable estimators: each
//! returns its estimate with a standard error, so that it can be checked against its closed
//! form (issue "The lecture's Monte Carlo results", experiment `mc-basics`).

use std::f64::consts::PI;

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// A Monte Carlo estimate: the mean of `n` samples and the standard error of that mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub value: f64,
    pub std_error: f64,
    /// Variance of one sample (the estimator's per-sample variance).
    pub sample_variance: f64,
    pub n: usize,
}

impl Estimate {
    /// The estimate from individual samples (unbiased sample variance).
    pub fn from_samples(samples: impl Iterator<Item = f64>) -> Estimate {
        // Welford's running mean and variance (Knuth, TAOCP vol. 2, §4.2.2).
        let (mut n, mut mean, mut m2) = (0usize, 0.0f64, 0.0f64);
        for x in samples {
            n += 1;
            let d = x - mean;
            mean += d / n as f64;
            m2 += d * (x - mean);
        }
        let var = if n > 1 { m2 / (n - 1) as f64 } else { 0.0 };
        Estimate {
            value: mean,
            std_error: (var / n.max(1) as f64).sqrt(),
            sample_variance: var,
            n,
        }
    }

    /// (estimate − truth) / standard error.
    pub fn z(&self, truth: f64) -> f64 {
        (self.value - truth) / self.std_error
    }
}

fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// Buffon's needle: needles of length `l` dropped on lines `t` apart (l ≤ t) cross a line
/// with probability 2l/(πt), so π ≈ 2l·n / (t·crossings). The needle's direction is drawn by
/// rejection from the unit disk, so the experiment does not use π to estimate it. The
/// standard error follows from the binomial one by the delta method:
/// se(π̂) = π̂ · se(p̂)/p̂, se(p̂) = √(p̂(1 − p̂)/n).
pub fn buffon_pi(n: usize, needle: f64, spacing: f64, seed: u64) -> Estimate {
    assert!(needle > 0.0 && needle <= spacing, "Buffon needs 0 < l <= t");
    let mut r = rng(seed);
    let mut crossings = 0usize;
    for _ in 0..n {
        // Distance of the needle's centre from the nearest line, uniform in [0, t/2].
        let y = r.random::<f64>() * spacing / 2.0;
        // sin θ of a uniform direction in the half plane.
        let sin = loop {
            let (u, v) = (r.random::<f64>(), r.random::<f64>());
            let len2 = u * u + v * v;
            if len2 <= 1.0 && len2 > 0.0 {
                break v / len2.sqrt();
            }
        };
        if y <= needle / 2.0 * sin {
            crossings += 1;
        }
    }
    let p = crossings as f64 / n as f64;
    let pi = 2.0 * needle / (spacing * p);
    let se_p = (p * (1.0 - p) / n as f64).sqrt();
    Estimate {
        value: pi,
        std_error: pi * se_p / p,
        sample_variance: (pi * se_p / p).powi(2) * n as f64,
        n,
    }
}

/// ∫_{−π/2}^{π/2} cos^50(x) dx = π · (49!!)/(50!!) = π ∏_{k=1}^{25} (2k − 1)/(2k)
/// (Wallis' integral).
pub fn cos50_integral() -> f64 {
    PI * (1..=25)
        .map(|k| (2 * k - 1) as f64 / (2 * k) as f64)
        .product::<f64>()
}

fn cos50(x: f64) -> f64 {
    if x.abs() > PI / 2.0 {
        0.0
    } else {
        x.cos().powi(50)
    }
}

/// ∫ cos^50 over [−π/2, π/2] with x uniform on the interval: π·cos^50(x).
pub fn cos50_uniform(n: usize, seed: u64) -> Estimate {
    let mut r = rng(seed);
    Estimate::from_samples((0..n).map(|_| {
        let x = (r.random::<f64>() - 0.5) * PI;
        PI * cos50(x)
    }))
}

/// ∫ cos^50 with x ~ N(0, σ²) (importance sampling; the integrand is 0 outside
/// [−π/2, π/2]): f(x)/p(x). cos^50 x ≈ exp(−25x²) near 0, so σ ≈ 1/√50 ≈ 0.141 is close
/// to the zero-variance density.
pub fn cos50_gaussian(n: usize, sigma: f64, seed: u64) -> Estimate {
    let mut r = rng(seed);
    Estimate::from_samples((0..n).map(|_| {
        // Box–Muller (Box & Muller 1958).
        let u1 = 1.0 - r.random::<f64>();
        let u2 = r.random::<f64>();
        let x = sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos();
        let pdf = (-0.5 * (x / sigma).powi(2)).exp() / (sigma * (2.0 * PI).sqrt());
        cos50(x) / pdf
    }))
}

/// Bound of the rejection sampler: 6x(1 − x) ≤ c·1 on [0, 1] with c = 1.5.
const REJECTION_C: f64 = 1.5;

/// One sample of the density 6x(1 − x) by rejection under c·U(0, 1): (sample, proposals).
fn rejection_beta22_draw(r: &mut Xoshiro256PlusPlus) -> (f64, u32) {
    let mut proposals = 0u32;
    loop {
        proposals += 1;
        let x = r.random::<f64>();
        if r.random::<f64>() * REJECTION_C <= 6.0 * x * (1.0 - x) {
            return (x, proposals);
        }
    }
}

/// Rejection sampling of the density 6x(1 − x) on [0, 1] under the bound c·U(0,1), c = 1.5:
/// returns the mean number of proposals per accepted sample (expected: c) and the accepted
/// samples' mean (expected: 1/2).
pub fn rejection_beta22(n: usize, seed: u64) -> (Estimate, Estimate) {
    let mut r = rng(seed);
    let draws: Vec<(f64, u32)> = (0..n).map(|_| rejection_beta22_draw(&mut r)).collect();
    (
        Estimate::from_samples(draws.iter().map(|&(_, k)| k as f64)),
        Estimate::from_samples(draws.iter().map(|&(x, _)| x)),
    )
}

/// The accepted samples of the rejection sampler of `rejection_beta22` (same seed, same
/// samples).
pub fn rejection_beta22_samples(n: usize, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    (0..n).map(|_| rejection_beta22_draw(&mut r).0).collect()
}

/// Exponential variates of rate λ by inverse transform: x = −ln(1 − u)/λ.
pub fn exponential_inverse_transform(n: usize, lambda: f64, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    (0..n)
        .map(|_| -(1.0 - r.random::<f64>()).ln() / lambda)
        .collect()
}

/// The two strategies of the multiple-importance-sampling example on [0, 1]:
/// p1(x) = (1 + 2x)/2 and its mirror p2(x) = (3 − 2x)/2, for f(x) = x² + (1 − x)²
/// (∫f = 2/3). One sample from each per estimate.
fn p1(x: f64) -> f64 {
    (1.0 + 2.0 * x) / 2.0
}

fn p2(x: f64) -> f64 {
    (3.0 - 2.0 * x) / 2.0
}

fn sample_p1(u: f64) -> f64 {
    // Inverse of the CDF (x + x²)/2.
    (-1.0 + (1.0 + 8.0 * u).sqrt()) / 2.0
}

fn mis_integrand(x: f64) -> f64 {
    x * x + (1.0 - x) * (1.0 - x)
}

/// ∫ f of the MIS example.
pub const MIS_INTEGRAL: f64 = 2.0 / 3.0;

/// One sample from each strategy, combined (Veach 1997, eq. 9.3) with the balance heuristic
/// (`balance = true`: w_i = p_i / (p1 + p2)) or as a plain average of the two one-sample
/// estimates (w_i = 1/2).
pub fn two_strategies(n: usize, balance: bool, seed: u64) -> Estimate {
    let mut r = rng(seed);
    Estimate::from_samples((0..n).map(|_| {
        let x1 = sample_p1(r.random::<f64>());
        let x2 = 1.0 - sample_p1(r.random::<f64>());
        if balance {
            mis_integrand(x1) / (p1(x1) + p2(x1)) + mis_integrand(x2) / (p1(x2) + p2(x2))
        } else {
            0.5 * (mis_integrand(x1) / p1(x1) + mis_integrand(x2) / p2(x2))
        }
    }))
}

/// ∫_0^1 e^x dx = e − 1 with the control variate h(x) = 1 + x (∫h = 3/2): samples
/// f(x) − β(h(x) − 3/2). `beta = None` uses the estimated optimum β = Cov(f, h)/Var(h) from
/// the same samples (a small bias of order 1/n, far below the standard error here).
pub fn control_variate_exp(n: usize, beta: Option<f64>, seed: u64) -> (Estimate, f64) {
    let mut r = rng(seed);
    let xs: Vec<f64> = (0..n).map(|_| r.random::<f64>()).collect();
    let beta = beta.unwrap_or_else(|| {
        let fs: Vec<f64> = xs.iter().map(|x| x.exp()).collect();
        let mf = fs.iter().sum::<f64>() / n as f64;
        let mh = xs.iter().map(|x| 1.0 + x).sum::<f64>() / n as f64;
        let cov: f64 = xs
            .iter()
            .zip(&fs)
            .map(|(x, f)| (f - mf) * (1.0 + x - mh))
            .sum();
        let var: f64 = xs.iter().map(|x| (1.0 + x - mh).powi(2)).sum();
        cov / var
    });
    let estimate = Estimate::from_samples(xs.iter().map(|x| x.exp() - beta * (1.0 + x - 1.5)));
    (estimate, beta)
}

/// The optimal control-variate coefficient for e^x against 1 + x on [0, 1], in closed form:
/// Cov(e^x, x)/Var(x) = (1 − (e − 1)/2)/(1/12) = 12·(3 − e)/2 = 6(3 − e).
pub fn control_variate_optimal_beta() -> f64 {
    6.0 * (3.0 - std::f64::consts::E)
}

/// The 4D example: ∫ over [0, 1]⁴ of cos⁵⁰(xyzw), by uniform sampling.
pub fn cos50_4d_uniform(n: usize, seed: u64) -> Estimate {
    let mut r = rng(seed);
    Estimate::from_samples((0..n).map(|_| {
        let t: f64 = (0..4).map(|_| r.random::<f64>()).product();
        t.cos().powi(50)
    }))
}

/// The exact value of the 4D example by a 1D reduction: the product t = xyzw of four
/// independent uniforms has density (ln 1/t)³/3! on (0, 1] (the sum of four Exp(1) variables
/// −ln x… has the Gamma(4, 1) density s³e^(−s)/6), so the integral is
/// ∫_0^∞ cos⁵⁰(e^(−s)) s³ e^(−s)/6 ds, evaluated by composite Simpson over s ∈ [0, 80]
/// (the tail beyond is below 10⁻²⁹).
pub fn cos50_4d_integral() -> f64 {
    let (a, b, m) = (0.0f64, 80.0f64, 400_000usize);
    let h = (b - a) / m as f64;
    let g = |s: f64| (-s).exp().cos().powi(50) * s.powi(3) * (-s).exp() / 6.0;
    let mut sum = g(a) + g(b);
    for i in 1..m {
        sum += g(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}
