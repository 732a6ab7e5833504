//! The integrated autocorrelation time of Markov chains, with Sokal's automatic window
//! (Sokal 1997, "Monte Carlo methods in statistical mechanics", §3): how many steps of a
//! chain are worth one independent sample.
//!
//! τ = 1 + 2 Σ_{k≥1} ρ(k), where ρ is the normalised autocorrelation at lag k. The sum is
//! cut at the smallest window W with W ≥ c·τ(W) (c = 5 by default): far enough for ρ to
//! have decayed, near enough that the noise of the ρ(k) beyond does not swamp it. Several
//! chains of the same target pool their autocovariances about their common mean, so a
//! chain stuck away from the others shows as long correlation.

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
    let centred: Vec<Vec<f64>> = series
        .iter()
        .map(|s| s.iter().map(|&x| x as f64 - mean).collect())
        .collect();
    let autocovariance = |k: usize| -> f64 {
        let mut sum = 0.0;
        let mut pairs = 0usize;
        for x in &centred {
            if x.len() > k {
                sum += x[..x.len() - k]
                    .iter()
                    .zip(&x[k..])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
                pairs += x.len() - k;
            }
        }
        if pairs > 0 { sum / pairs as f64 } else { 0.0 }
    };
    let c0 = autocovariance(0);
    if c0 <= 0.0 || !c0.is_finite() {
        return None;
    }
    let longest = series.iter().map(|s| s.len()).max().unwrap_or(0);
    let max_window = (longest / 2).max(1);
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
