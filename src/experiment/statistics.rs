//! Statistics reported over runs and checkpoints (docs/DESIGN.md §5): Student-t confidence
//! intervals of a mean, the convergence slope (a power law fitted in log-log space), and the
//! bias/variance decomposition over independent runs with a t-test of zero mean signed error.
//! Everything is f64; bad input gives an error or a documented degenerate value, never a panic.

use serde::Serialize;
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

use crate::error::{Error, Result};
use crate::experiment::metrics::{EPSILON, Region, check_finite, check_pair, check_reference};
use crate::image::Image;

/// The confidence level of every interval `bias_variance` reports (the issue asks for 95%).
pub const CONFIDENCE: f64 = 0.95;

/// A mean with a two-sided confidence interval [lo, hi].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Interval {
    pub mean: f64,
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// Whether `value` lies in [lo, hi].
    pub fn contains(&self, value: f64) -> bool {
        self.lo <= value && value <= self.hi
    }
}

/// The mean of `values` with its Student-t confidence interval at level `confidence`
/// (e.g. 0.95): mean ± t_{(1+confidence)/2, n−1} · s / √n, s the sample standard deviation
/// (divisor n − 1). Assumes the values are independent draws of one distribution (runs).
///
/// Degenerate cases, chosen so that the result stays finite and JSON-friendly:
/// - one value: lo = hi = mean (no spread can be estimated; the interval is unknown, not zero,
///   so readers must look at the number of runs);
/// - `confidence` outside the open interval (0, 1) or NaN: lo = hi = mean;
/// - no values: all three fields NaN (there is no mean to report).
pub fn mean_interval(values: &[f64], confidence: f64) -> Interval {
    let mut moments = Moments::default();
    for &v in values {
        moments.push(v);
    }
    moments.interval(confidence)
}

/// `mean_interval` for a quantity that cannot be negative (relMSE, RMSE, MAPE, efficiency,
/// a variance): the Student-t interval with its lower end raised to 0 where it falls below.
///
/// The t interval is symmetric, and with few runs it reaches below 0 (with 2 runs t = 12.7).
/// The true mean is ≥ 0, so the cut drops only values it cannot take: the interval covers the
/// mean exactly as often as the t interval does. A t interval on ln values would stay positive
/// too, but it estimates the geometric mean (a log-normal's median), not the arithmetic mean
/// reported beside it. No values: NaN as for `mean_interval`.
pub fn nonnegative_mean_interval(values: &[f64], confidence: f64) -> Interval {
    mean_interval(values, confidence).at_least_zero()
}

impl Interval {
    /// The interval with a negative lower end raised to 0 (see `nonnegative_mean_interval`).
    pub fn at_least_zero(self) -> Interval {
        Interval {
            lo: if self.lo < 0.0 { 0.0 } else { self.lo },
            ..self
        }
    }
}

/// Running count, mean and sum of squared deviations (Welford's update), so that intervals
/// over millions of pixel terms need no buffer.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn push(&mut self, v: f64) {
        self.n += 1;
        let delta = v - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (v - self.mean);
    }

    /// Unbiased sample variance (divisor n − 1); 0 for fewer than two values.
    fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    fn interval(&self, confidence: f64) -> Interval {
        if self.n == 0 {
            return Interval {
                mean: f64::NAN,
                lo: f64::NAN,
                hi: f64::NAN,
            };
        }
        let point = Interval {
            mean: self.mean,
            lo: self.mean,
            hi: self.mean,
        };
        if self.n < 2 || !(confidence > 0.0 && confidence < 1.0) {
            return point;
        }
        let Some(t) = t_quantile(0.5 * (1.0 + confidence), (self.n - 1) as f64) else {
            return point;
        };
        let half = t * (self.variance() / self.n as f64).sqrt();
        Interval {
            mean: self.mean,
            lo: self.mean - half,
            hi: self.mean + half,
        }
    }
}

/// The `p` quantile of Student's t with `dof` degrees of freedom (`None` if statrs refuses).
///
/// statrs's inverse goes wrong for large `dof` (its inverse incomplete beta loses accuracy:
/// t_{0.975} comes out as 1.9563 at 3·10⁶ and 1.83 at 10⁷ instead of 1.95996), and intervals
/// over every pixel-channel of an image have millions of degrees of freedom. Above 1000 the
/// Cornish–Fisher expansion of t in terms of the normal quantile z (Abramowitz & Stegun
/// 26.7.5, four terms in 1/ν) is used instead; there it agrees with the exact quantile to
/// about 1e-12.
fn t_quantile(p: f64, dof: f64) -> Option<f64> {
    let t = if dof > 1000.0 {
        let z = Normal::new(0.0, 1.0).ok()?.inverse_cdf(p);
        let g1 = (z.powi(3) + z) / 4.0;
        let g2 = (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / 96.0;
        let g3 = (3.0 * z.powi(7) + 19.0 * z.powi(5) + 17.0 * z.powi(3) - 15.0 * z) / 384.0;
        let g4 = (79.0 * z.powi(9) + 776.0 * z.powi(7) + 1482.0 * z.powi(5)
            - 1920.0 * z.powi(3)
            - 945.0 * z)
            / 92160.0;
        z + g1 / dof + g2 / dof.powi(2) + g3 / dof.powi(3) + g4 / dof.powi(4)
    } else {
        StudentsT::new(0.0, 1.0, dof).ok()?.inverse_cdf(p)
    };
    t.is_finite().then_some(t)
}

/// A power law y ≈ e^intercept · x^slope fitted by least squares in log-log space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SlopeFit {
    /// The exponent: −1 for an unbiased estimator's relMSE against time or passes.
    pub slope: f64,
    /// Standard error of the slope: sqrt(Σr² / (n − 2) / Σ(ln x − mean ln x)²), r the
    /// log-space residuals.
    pub slope_se: f64,
    /// ln of the prefactor (the fitted ln y at x = 1).
    pub intercept: f64,
    /// How many (x, y) pairs went into the fit.
    pub points: usize,
}

/// Ordinary least squares of ln y on ln x: slope = Σ(u − ū)(v − v̄) / Σ(u − ū)², with u = ln x,
/// v = ln y, and the slope's standard error from the residuals with n − 2 degrees of freedom.
///
/// Pairs whose x or y is not finite and positive (a logarithm cannot take them; a relMSE of
/// exactly 0 or a checkpoint at time 0) are skipped, and `points` says how many remain.
/// `None` when the slices differ in length, fewer than three usable pairs remain, or all
/// usable x are equal (no slope is defined).
pub fn fit_power_law(x: &[f64], y: &[f64]) -> Option<SlopeFit> {
    if x.len() != y.len() {
        return None;
    }
    let (u, v): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|&(&a, &b)| a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0)
        .map(|(&a, &b)| (a.ln(), b.ln()))
        .unzip();
    let n = u.len();
    if n < 3 {
        return None;
    }
    let mean_u = u.iter().sum::<f64>() / n as f64;
    let mean_v = v.iter().sum::<f64>() / n as f64;
    let suu: f64 = u.iter().map(|a| (a - mean_u).powi(2)).sum();
    let suv: f64 = u
        .iter()
        .zip(&v)
        .map(|(a, b)| (a - mean_u) * (b - mean_v))
        .sum();
    if !suu.is_finite() || suu <= 0.0 {
        return None;
    }
    let slope = suv / suu;
    let intercept = mean_v - slope * mean_u;
    let sse: f64 = u
        .iter()
        .zip(&v)
        .map(|(a, b)| (b - intercept - slope * a).powi(2))
        .sum();
    let slope_se = (sse / (n - 2) as f64 / suu).sqrt();
    Some(SlopeFit {
        slope,
        slope_se,
        intercept,
        points: n,
    })
}

/// The later half of a sequence of checkpoints, over which docs/DESIGN.md §5 fits the convergence
/// slope (early checkpoints are dominated by start-up, not by the asymptotic rate): the last
/// ⌈n/2⌉ items, so with an odd count the middle checkpoint is included.
pub fn later_half<T>(values: &[T]) -> &[T] {
    &values[values.len() / 2..]
}

/// `fit_power_law` over the later half of the checkpoints (docs/DESIGN.md §5's convergence slope).
pub fn fit_later_half(x: &[f64], y: &[f64]) -> Option<SlopeFit> {
    if x.len() != y.len() {
        return None;
    }
    fit_power_law(later_half(x), later_half(y))
}

/// Bias and variance of an estimator from K independent runs against a reference
/// (docs/DESIGN.md §5), each with a `CONFIDENCE` interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BiasVariance {
    /// mean over pixel-channels of (m − y)² − s²/K: squared bias, in squared radiance.
    pub bias2: Interval,
    /// mean over pixel-channels of s²: the variance of one run, in squared radiance.
    pub variance: Interval,
    /// `bias2` with each term divided by (y² + 0.01), comparable with relMSE.
    pub relative_bias2: Interval,
    /// `variance` with each term divided by (y² + 0.01), comparable with relMSE.
    pub relative_variance: Interval,
    /// Over runs, e_k = mean over pixel-channels of (x_k − y), with its Student-t interval.
    pub mean_signed_error: Interval,
    /// t = ē / (s_e / √K) of the one-sample test of "mean signed error = 0".
    pub t_statistic: f64,
    /// Two-sided p-value of that test, Student's t with K − 1 degrees of freedom.
    pub p_value: f64,
    /// K, the number of runs.
    pub runs: usize,
}

/// The bias/variance decomposition over `runs` (K ≥ 2 independent renders of the same scene
/// with the same budget, different seeds) against `reference` y.
///
/// Per pixel-channel i, with run mean m_i and unbiased sample variance s²_i (divisor K − 1):
/// E[(m_i − y_i)²] = b_i² + σ_i²/K and E[s²_i] = σ_i², so (m_i − y_i)² − s²_i/K estimates the
/// squared bias b_i² without bias (it can be negative; an interval that contains 0 means no
/// detectable bias) and s²_i estimates the variance σ_i² of one run. `bias2` and `variance`
/// are the means of these terms; the relative versions divide each term by y_i² + 0.01 as
/// relMSE does, and then relative_bias2 + relative_variance equals the mean over runs of
/// each run's relMSE exactly (likewise bias2 + variance and the mean squared error).
///
/// The intervals treat the per-pixel-channel terms as independent draws (Student t over the
/// N·3 terms). Pixels of a real render are correlated (reconstruction filter, Markov chains),
/// which makes these intervals too narrow; they are exact for the independent-pixel synthetic
/// ensembles of the test suite.
///
/// The t-test: per run k, e_k = mean_i (x_k,i − y_i); under "no bias" the e_k have mean 0;
/// t = ē / (s_e / √K) with K − 1 degrees of freedom, p = 2·P(T > |t|). If all e_k are equal
/// (s_e = 0), t = 0 and p = 1 when ē = 0, otherwise t = ±f64::MAX and p = 0 (finite for JSON).
pub fn bias_variance(runs: &[Image], reference: &Image) -> Result<BiasVariance> {
    let k = runs.len();
    if k < 2 {
        return Err(Error::usage(format!(
            "bias and variance need at least 2 independent runs, got {k}"
        )));
    }
    let names: Vec<String> = (0..k).map(|r| format!("run {r}")).collect();
    for (run, name) in runs.iter().zip(&names) {
        check_pair(run, reference, name, "reference")?;
    }

    let kf = k as f64;
    let (mut bias2, mut variance) = (Moments::default(), Moments::default());
    let (mut rel_bias2, mut rel_variance) = (Moments::default(), Moments::default());
    let mut signed = vec![0.0f64; k];
    let mut xs = vec![0.0f64; k];
    let mut count = 0u64;
    let full = Region::full(reference.width, reference.height);
    for (px, py, i) in full.indices(reference.width) {
        for c in 0..3 {
            let y = f64::from(reference.pixels[i].0[c]);
            check_reference(y, "reference", px, py, c)?;
            for (r, x) in xs.iter_mut().enumerate() {
                *x = f64::from(runs[r].pixels[i].0[c]);
                check_finite(*x, &names[r], px, py, c)?;
                signed[r] += *x - y;
            }
            // Two-pass mean and variance over the K runs (K is small).
            let m = xs.iter().sum::<f64>() / kf;
            let s2 = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (kf - 1.0);
            let b2 = (m - y).powi(2) - s2 / kf;
            let d = y * y + EPSILON;
            bias2.push(b2);
            variance.push(s2);
            rel_bias2.push(b2 / d);
            rel_variance.push(s2 / d);
            count += 1;
        }
    }

    for e in &mut signed {
        *e /= count as f64;
    }
    let mut errors = Moments::default();
    for &e in &signed {
        errors.push(e);
    }
    let (t_statistic, p_value) = t_test_zero_mean(&errors);
    Ok(BiasVariance {
        bias2: bias2.interval(CONFIDENCE),
        variance: variance.interval(CONFIDENCE).at_least_zero(),
        relative_bias2: rel_bias2.interval(CONFIDENCE),
        relative_variance: rel_variance.interval(CONFIDENCE).at_least_zero(),
        mean_signed_error: errors.interval(CONFIDENCE),
        t_statistic,
        p_value,
        runs: k,
    })
}

/// One-sample two-sided t-test of "mean = 0" (needs n ≥ 2): t = x̄ / (s / √n), n − 1 dof.
fn t_test_zero_mean(m: &Moments) -> (f64, f64) {
    let se = (m.variance() / m.n as f64).sqrt();
    if se.is_nan() || se <= 0.0 {
        return if m.mean == 0.0 {
            (0.0, 1.0)
        } else {
            (f64::MAX.copysign(m.mean), 0.0)
        };
    }
    let t = (m.mean / se).clamp(-f64::MAX, f64::MAX);
    let p = match StudentsT::new(0.0, 1.0, (m.n - 1) as f64) {
        Ok(dist) => (2.0 * dist.sf(t.abs())).clamp(0.0, 1.0),
        Err(_) => f64::NAN,
    };
    (t, p)
}
