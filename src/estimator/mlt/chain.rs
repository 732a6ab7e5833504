//! One Markov chain in primary sample space: Metropolis–Hastings with Kelemen et al.
//! 2002's mutations, its state's contributions, and what it has recorded about itself.
//!
//! The target density is proportional to the importance I (the luminance of a state's
//! contributions); the proposal is symmetric (small steps are symmetric perturbations,
//! large steps independent uniforms), so a proposal is accepted with probability
//! a = min(1, I_new / I_old) (Veach 1997, eq. 11.4).
//!
//! Expected-value splatting (Veach 1997, §11.5): each step adds both the current and the
//! proposed state, weighted by 1 − a and a, each value f scaled by b / I(f). Over the chain
//! the splats' mean per step is the integral of f over primary sample space, whatever
//! happens to be accepted. With `kelemen_weights` the weights are Kelemen et al. 2002's
//! (§5, their combination of the chain with its large steps as independent samples):
//! (a + [large step]) / (I_new / b + p_large) and (1 − a) / (I_old / b + p_large).

use crate::estimator::mlt::settings::ChainSettings;
use crate::estimator::mlt::target::Contributions;
use crate::film::SplatList;
use crate::sampler::primary_sample::PrimarySampleSampler;

/// Luminances each chain keeps for the autocorrelation estimate (its first steps).
pub const RECORDED_STEPS: usize = 4096;

/// What a chain counts about itself.
#[derive(Clone, Debug, Default)]
pub struct ChainCounts {
    pub small_proposed: u64,
    pub small_accepted: u64,
    pub large_proposed: u64,
    pub large_accepted: u64,
    /// Σ of the large steps' proposals' importance (independent points: `Normalisation`).
    pub large_importance: f64,
    pub rays: u64,
    pub invalid: u64,
}

impl ChainCounts {
    pub fn add(&mut self, other: &ChainCounts) {
        self.small_proposed += other.small_proposed;
        self.small_accepted += other.small_accepted;
        self.large_proposed += other.large_proposed;
        self.large_accepted += other.large_accepted;
        self.large_importance += other.large_importance;
        self.rays += other.rays;
        self.invalid += other.invalid;
    }

    pub fn steps(&self) -> u64 {
        self.small_proposed + self.large_proposed
    }

    pub fn accepted(&self) -> u64 {
        self.small_accepted + self.large_accepted
    }
}

pub struct Chain {
    pub sampler: PrimarySampleSampler,
    pub current: Contributions,
    proposal: Contributions,
    pub counts: ChainCounts,
    /// The current state's importance after each of the first `RECORDED_STEPS` steps.
    pub luminance_series: Vec<f32>,
    /// The stratum the chain is confined to (`mmlt` with `lengths=fixed`: its path
    /// length), or None when its states range over every stratum.
    pub stratum: Option<usize>,
    /// Every splat's factor beyond b / I: 1, or for a chain confined to a stratum the
    /// pass's mutations over its stratum's (`Metropolis::start`).
    pub scale: f64,
}

impl Chain {
    /// A chain in state `current` (the sampler's accepted state).
    pub fn new(sampler: PrimarySampleSampler, current: Contributions) -> Chain {
        Chain {
            sampler,
            current,
            proposal: Contributions::default(),
            counts: ChainCounts::default(),
            luminance_series: Vec::new(),
            stratum: None,
            scale: 1.0,
        }
    }

    /// One Metropolis–Hastings step: propose (the sampler mutates), evaluate with
    /// `evaluate` (which reads the proposal through the sampler and returns rays cast and
    /// contributions dropped), splat both states' expected values to `splats` (scaled by
    /// the normalisation `b` of the chain's target and by `scale`), accept or reject.
    pub fn step(
        &mut self,
        settings: &ChainSettings,
        b: f64,
        splats: &mut SplatList,
        evaluate: impl FnOnce(&mut PrimarySampleSampler, &mut Contributions) -> (u64, u64),
    ) {
        self.sampler.start_iteration();
        let large = self.sampler.is_large_step();
        let (rays, invalid) = evaluate(&mut self.sampler, &mut self.proposal);
        self.counts.rays += rays;
        self.counts.invalid += invalid;
        let (i_old, i_new) = (self.current.luminance, self.proposal.luminance);
        let a = if i_old > 0.0 {
            (i_new / i_old).min(1.0)
        } else {
            1.0
        };
        let (w_new, w_old) = if settings.kelemen_weights {
            let p_large = settings.large_step;
            let new = (a + if large { 1.0 } else { 0.0 }) / (i_new / b + p_large);
            let old = (1.0 - a) / (i_old / b + p_large);
            (new, old)
        } else {
            let new = if i_new > 0.0 { a * b / i_new } else { 0.0 };
            let old = if i_old > 0.0 {
                (1.0 - a) * b / i_old
            } else {
                0.0
            };
            (new, old)
        };
        splat(splats, &self.current, w_old * self.scale);
        splat(splats, &self.proposal, w_new * self.scale);
        let accept = a >= 1.0 || self.sampler.uniform() < a;
        if large {
            self.counts.large_proposed += 1;
            self.counts.large_accepted += accept as u64;
            self.counts.large_importance += i_new;
        } else {
            self.counts.small_proposed += 1;
            self.counts.small_accepted += accept as u64;
        }
        if accept {
            self.sampler.accept();
            std::mem::swap(&mut self.current, &mut self.proposal);
        } else {
            self.sampler.reject();
        }
        if self.luminance_series.len() < RECORDED_STEPS {
            self.luminance_series.push(self.current.luminance as f32);
        }
    }
}

/// Adds `state`'s contributions times `weight` to `splats`.
fn splat(splats: &mut SplatList, state: &Contributions, weight: f64) {
    if weight > 0.0 && weight.is_finite() {
        for &(raster, value) in &state.entries {
            splats.push(raster, value * weight as f32);
        }
    }
}
