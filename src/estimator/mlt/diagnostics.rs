//! What a researcher needs to trust a Metropolis estimator's chains, written as JSON beside
//! every image and summarised in experiment reports.

use serde::Serialize;

use super::autocorrelation::{SOKAL_C, integrated_autocorrelation_time};
use super::chain::{Chain, ChainCounts};
use super::settings::ChainSettings;
use crate::sampler::primary_sample::Mutation;

/// What the bootstrap found: the normalisation b = Σ over strata of their mean importance.
#[derive(Clone, Debug, Serialize)]
pub struct Bootstrap {
    pub b: f64,
    /// Standard error of b (from the bootstrap samples' variance, strata independent).
    pub b_standard_error: f64,
    /// Mean importance per stratum (`mmlt`: per path length, 1 to `max_depth`).
    pub stratum_means: Vec<f64>,
    pub samples: u64,
    /// Samples whose importance was above 0.
    pub nonzero: u64,
}

impl Bootstrap {
    /// From the importances of `strata` strata of `per_stratum` samples each, stratum by
    /// stratum.
    pub fn new(importance: &[f32], strata: usize, per_stratum: u64) -> Bootstrap {
        let mut b = 0.0;
        let mut variance = 0.0;
        let mut stratum_means = Vec::with_capacity(strata);
        for chunk in importance.chunks(per_stratum as usize) {
            let n = chunk.len() as f64;
            let mean = chunk.iter().map(|&x| x as f64).sum::<f64>() / n;
            let var = chunk
                .iter()
                .map(|&x| (x as f64 - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0).max(1.0);
            b += mean;
            variance += var / n;
            stratum_means.push(mean);
        }
        Bootstrap {
            b,
            b_standard_error: variance.sqrt(),
            stratum_means,
            samples: importance.len() as u64,
            nonzero: importance.iter().filter(|&&x| x > 0.0).count() as u64,
        }
    }
}

/// Proposals of one kind and how many were accepted.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Acceptance {
    pub proposed: u64,
    pub accepted: u64,
    /// accepted / proposed (0 when none was proposed).
    pub rate: f64,
}

impl Acceptance {
    fn new(proposed: u64, accepted: u64) -> Acceptance {
        Acceptance {
            proposed,
            accepted,
            rate: if proposed > 0 {
                accepted as f64 / proposed as f64
            } else {
                0.0
            },
        }
    }
}

/// The diagnostics of one render.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnostics {
    pub estimator: String,
    pub base: Option<String>,
    pub large_step: f64,
    pub mutation: String,
    pub kelemen_weights: bool,
    /// `luminance` or `relative` (`importance.rs`).
    pub importance: String,
    /// `importance=relative`: the pilot's block side in pixels (set by the estimator).
    pub pilot_block: Option<u32>,
    /// `normalisation=large_steps`: the b the image is scaled by, pooled from the bootstrap
    /// and every large step (set by the estimator); None with the bootstrap's b.
    pub b_pooled: Option<f64>,
    pub bootstrap: Bootstrap,
    pub chains: u64,
    /// Chains that accepted no proposal.
    pub chains_never_moved: u64,
    /// Chains per stratum when each keeps one (`mmlt` with `lengths=fixed`: per path
    /// length, length 1 first); None when chains range over every stratum.
    pub chains_per_stratum: Option<Vec<u64>>,
    pub mutations: u64,
    pub acceptance: Acceptance,
    pub small_steps: Acceptance,
    pub large_steps: Acceptance,
    /// The integrated autocorrelation time of the chains' importance (Sokal's automatic
    /// window, c = 5), in mutations, over each chain's first `chain::RECORDED_STEPS` steps;
    /// None when the importance never varied.
    pub autocorrelation_time: Option<f64>,
    pub autocorrelation_window: Option<usize>,
    /// False when no window satisfied Sokal's criterion within the recorded steps: the time
    /// is then a lower bound.
    pub autocorrelation_converged: bool,
    /// Mutations / autocorrelation time.
    pub effective_sample_size: Option<f64>,
    pub seconds: f64,
    pub bootstrap_seconds: f64,
    /// Mutations per second of the chains (bootstrap time excluded).
    pub mutations_per_second: f64,
    pub rays: u64,
    pub invalid_samples: u64,
}

impl Diagnostics {
    pub fn new(
        name: &str,
        base: Option<&str>,
        settings: &ChainSettings,
        bootstrap: &Bootstrap,
        chains: &[Chain],
        seconds: f64,
        bootstrap_seconds: f64,
    ) -> Diagnostics {
        let mut counts = ChainCounts::default();
        for c in chains {
            counts.add(&c.counts);
        }
        let series: Vec<&[f32]> = chains
            .iter()
            .map(|c| c.luminance_series.as_slice())
            .collect();
        let tau = integrated_autocorrelation_time(&series, SOKAL_C);
        let mutations = counts.steps();
        let chain_seconds = (seconds - bootstrap_seconds).max(0.0);
        Diagnostics {
            estimator: name.to_string(),
            base: base.map(str::to_string),
            large_step: settings.large_step,
            mutation: match settings.mutation {
                Mutation::Kelemen { s1, s2 } => format!("kelemen s1={s1} s2={s2}"),
                Mutation::Gaussian { sigma } => format!("gaussian sigma={sigma}"),
            },
            kelemen_weights: settings.kelemen_weights,
            importance: settings.importance.name().to_string(),
            pilot_block: None,
            b_pooled: None,
            bootstrap: bootstrap.clone(),
            chains: chains.len() as u64,
            chains_never_moved: chains
                .iter()
                .filter(|c| c.counts.steps() > 0 && c.counts.accepted() == 0)
                .count() as u64,
            chains_per_stratum: chains.iter().any(|c| c.stratum.is_some()).then(|| {
                let mut per = vec![0; bootstrap.stratum_means.len()];
                for k in chains.iter().filter_map(|c| c.stratum) {
                    per[k] += 1;
                }
                per
            }),
            mutations,
            acceptance: Acceptance::new(mutations, counts.accepted()),
            small_steps: Acceptance::new(counts.small_proposed, counts.small_accepted),
            large_steps: Acceptance::new(counts.large_proposed, counts.large_accepted),
            autocorrelation_time: tau.map(|t| t.tau),
            autocorrelation_window: tau.map(|t| t.window),
            autocorrelation_converged: tau.is_some_and(|t| t.converged),
            effective_sample_size: tau.map(|t| mutations as f64 / t.tau.max(1.0)),
            seconds,
            bootstrap_seconds,
            mutations_per_second: if chain_seconds > 0.0 {
                mutations as f64 / chain_seconds
            } else {
                0.0
            },
            rays: counts.rays,
            invalid_samples: counts.invalid,
        }
    }
}
