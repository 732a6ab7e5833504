//! The integrated autocorrelation time of Markov chains, with Sokal's automatic window
//! (Sokal 1997, "Monte Carlo methods in statistical mechanics", §3): how many steps of a
//! chain are worth one independent sample.
//!
//! τ = 1 + 2 Σ_{k≥1} ρ(k), where ρ is the normalised autocorrelation at lag k. The sum is
//! cut at the smallest window W with W ≥ c·τ(W) (c = 5 by default): far enough for ρ to
//! have decayed, near enough that the noise of the ρ(k) beyond does not swamp it. Several
//! chains of the same target pool their autocovariances about their common mean, so a
//! chain stuck away from the others shows as long correlation.

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// Sokal's constant: the window reaches c integrated autocorrelation times.
pub const SOKAL_C: f64 = 5.0;

/// The estimate and how it was cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutocorrelationTime {
    /// τ, in steps of the chain.
    pub tau: f64,
    /// The window W the sum stopped at.
    pub window: usize,
    /// False when no window up to half the chains' length satisfied W ≥ c·τ(W): τ is then
    /// a lower bound.
    pub converged: bool,
}

/// For every lag k ≤ `max_lag`, Σ over chains and i of (x_i − mean)(x_{i+k} − mean), by
/// the Wiener–Khinchin theorem: the inverse FFT of each zero-padded chain's power spectrum
/// (O(n log n) per chain where the direct sums cost O(n·W)).
fn lagged_products(series: &[&[f32]], mean: f64, max_lag: usize) -> Vec<f64> {
    let mut sums = vec![0.0; max_lag + 1];
    let mut planner = FftPlanner::<f64>::new();
    for x in series.iter().filter(|x| !x.is_empty()) {
        // Padding to twice the length keeps the circular correlation from wrapping.
        let n = (2 * x.len()).next_power_of_two();
        let mut buffer: Vec<Complex<f64>> = x
            .iter()
            .map(|&v| Complex::new(v as f64 - mean, 0.0))
            .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
            .take(n)
            .collect();
        planner.plan_fft_forward(n).process(&mut buffer);
        for c in &mut buffer {
            *c = Complex::new(c.norm_sqr(), 0.0);
        }
        planner.plan_fft_inverse(n).process(&mut buffer);
        for (k, sum) in sums.iter_mut().enumerate().take(x.len()) {
            *sum += buffer[k].re / n as f64;
        }
    }
    sums
}

/// τ of the chains' `series` (one slice per chain, equal or unequal lengths) with Sokal's
/// window constant `c`; None when the values do not vary (τ is undefined).
pub fn integrated_autocorrelation_time(series: &[&[f32]], c: f64) -> Option<AutocorrelationTime> {
    let count: usize = series.iter().map(|s| s.len()).sum();
    if count < 2 {
        return None;
    }
    let mean = series
        .iter()
        .flat_map(|s| s.iter())
        .map(|&x| x as f64)
        .sum::<f64>()
        / count as f64;
    let longest = series.iter().map(|s| s.len()).max().unwrap_or(0);
    let max_window = (longest / 2).max(1);
    let lagged = lagged_products(series, mean, max_window);
    let autocovariance = |k: usize| -> f64 {
        let pairs: usize = series.iter().map(|s| s.len().saturating_sub(k)).sum();
        if pairs > 0 {
            lagged[k] / pairs as f64
        } else {
            0.0
        }
    };
    let c0 = autocovariance(0);
    if c0 <= 0.0 || !c0.is_finite() {
        return None;
    }
    let mut tau = 1.0;
    for w in 1..=max_window {
        tau += 2.0 * autocovariance(w) / c0;
        if w as f64 >= c * tau {
            return Some(AutocorrelationTime {
                tau: tau.max(f64::MIN_POSITIVE),
                window: w,
                converged: true,
            });
        }
    }
    Some(AutocorrelationTime {
        tau,
        window: max_window,
        converged: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The FFT's lagged products equal the direct sums, on chains of unequal lengths.
    #[test]
    fn lagged_products_equal_the_direct_sums() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let chains: Vec<Vec<f32>> = [37usize, 64, 5, 1]
            .iter()
            .map(|&n| (0..n).map(|_| rng.random::<f32>()).collect())
            .collect();
        let slices: Vec<&[f32]> = chains.iter().map(|c| c.as_slice()).collect();
        let mean = 0.4;
        let fast = lagged_products(&slices, mean, 40);
        for (k, &value) in fast.iter().enumerate() {
            let direct: f64 = chains
                .iter()
                .filter(|x| x.len() > k)
                .map(|x| {
                    (0..x.len() - k)
                        .map(|i| (x[i] as f64 - mean) * (x[i + k] as f64 - mean))
                        .sum::<f64>()
                })
                .sum();
            assert!(
                (value - direct).abs() < 1e-9,
                "lag {k}: {value} against {direct}"
            );
        }
    }

    /// An AR(1) process x' = φx + ε has ρ(k) = φ^k and τ = (1 + φ)/(1 − φ): the estimate
    /// finds it within its statistical error (Sokal's variance, 2(2W + 1)/N·τ², 4 σ).
    #[test]
    fn ar1_process_has_the_known_time() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for phi in [0.0f64, 0.5, 0.9] {
            let chains: Vec<Vec<f32>> = (0..8)
                .map(|_| {
                    let mut x = 0.0f64;
                    (0..20_000)
                        .map(|_| {
                            let e: f64 = rng.random::<f64>() - 0.5;
                            x = phi * x + e;
                            x as f32
                        })
                        .collect()
                })
                .collect();
            let slices: Vec<&[f32]> = chains.iter().map(|c| c.as_slice()).collect();
            let est = integrated_autocorrelation_time(&slices, SOKAL_C).unwrap();
            let truth = (1.0 + phi) / (1.0 - phi);
            let n = 8.0 * 20_000.0;
            let sigma = (2.0 * (2.0 * est.window as f64 + 1.0) / n).sqrt() * truth;
            assert!(est.converged);
            assert!(
                (est.tau - truth).abs() < 4.0 * sigma + 0.02,
                "φ {phi}: τ {} against {truth} ± {sigma}",
                est.tau
            );
        }
        assert_eq!(
            integrated_autocorrelation_time(&[&[1.0, 1.0, 1.0]], 5.0),
            None
        );
    }
}
