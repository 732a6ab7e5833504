//! Metropolis light transport in primary sample space: `pssmlt` (Kelemen et al. 2002, over
//! `pt` or `bdpt`) and `mmlt` (Hachisuka et al. 2014, multiplexed over `bdpt`'s
//! strategies).
//!
//! * A path function (`target`) maps a point of primary sample space to contributions on
//!   the film; the estimators' own sample code reads the point through the sampler
//!   contract from a `PrimarySampleSampler`, which the chains mutate.
//! * The bootstrap: `bootstrap` independent points (per stratum: `mmlt`'s path lengths)
//!   estimate the normalisation b = ∫ I (the mean importance), and chains start at points
//!   drawn from them in proportion to I (systematic resampling): the chains start in their
//!   stationary distribution (no start-up bias up to the bootstrap's finite size).
//! * `chains` chains, each with its own mutation stream keyed by (seed, chain): their
//!   number and their streams do not depend on the thread count. A pass is one mutation
//!   per pixel, spread evenly over the chains; each chain's splats of each pass merge in
//!   (pass, chain) order, so images are bit-identical for any `--threads` and for passes
//!   taken one at a time or in chunks. One thread merges a pass's lists while the chains
//!   take the next pass; the last pass's lists wait for the next call or for `image()`.
//! * Image = b × (expected-value splats) / mutations per pixel (`chain`). b is the
//!   bootstrap's, or with `normalisation=large_steps` the bootstrap pooled with every large
//!   step's proposal so far (`settings::Normalisation`), applied when the image is read.
//! * `importance`: the target is the luminance of a state's contributions, or with
//!   `importance=relative` their luminance relative to a pilot estimate of each pixel, made
//!   from independent points of its own before the bootstrap.
//! * `diagnostics` (JSON beside every image): acceptance, b and its standard error, chains
//!   that never moved, the integrated autocorrelation time of the chains' importance and
//!   the effective sample size, mutations per second.

pub mod autocorrelation;
pub mod chain;
pub mod diagnostics;
pub mod importance;
pub mod multiplexed;
pub mod settings;
pub mod target;

use std::time::Instant;

use rayon::prelude::*;

use super::bdpt::{BdptSample, BdptSettings, mis_from_params};
use super::pt::PathSample;
use super::{Estimator, Params, Stats};
use crate::error::{Error, Result};
use crate::film::{Film, SplatList};
use crate::image::Image;
use crate::path::settings::PathSettings;
use crate::sampler::independent::{hash_words, to_unit_f32};
use crate::sampler::primary_sample::PrimarySampleSampler;
use crate::scene::Scene;
use chain::{Chain, ChainCounts};
use diagnostics::{Bootstrap, Diagnostics};
use glam::Vec2;
use importance::{ImportanceKind, PilotMap};
use multiplexed::MultiplexedTarget;
use settings::{ChainSettings, Lengths, Normalisation};
use target::{BdptTarget, Contributions, PathTarget, PtTarget};

/// Keys that keep the bootstrap's, the chains' and the selection's streams apart.
const BOOTSTRAP_KEY: u64 = 0xB007;
const CHAIN_KEY: u64 = 0xC4A1;
const SELECT_KEY: u64 = 0x5E1E;
const PILOT_KEY: u64 = 0x9107;

/// A Metropolis estimator over path function `T`.
pub struct Metropolis<T: PathTarget> {
    name: &'static str,
    /// `pssmlt`'s base estimator (for the diagnostics).
    base: Option<&'static str>,
    settings: ChainSettings,
    target: T,
    seed: u64,
    /// Every pass merged except the last.
    film: Film,
    /// The last pass's splats, one list per chain, merged into `film` while the chains take
    /// the next pass (and by `image`).
    pending: Vec<SplatList>,
    /// The lists the chains fill in the current pass.
    fresh: Vec<SplatList>,
    chains: Vec<Chain>,
    /// What the bootstrap found (None before the first pass).
    bootstrap: Option<Bootstrap>,
    /// `importance=relative`: the pilot the importance divides by (from the bootstrap).
    pilot: Option<PilotMap>,
    stats: Stats,
    /// Seconds spent in passes (bootstrap included).
    seconds: f64,
    bootstrap_seconds: f64,
}

/// `pssmlt` with `base=pt`.
pub type PssmltPt = Metropolis<PtTarget>;
/// `pssmlt` with `base=bdpt`.
pub type PssmltBdpt = Metropolis<BdptTarget>;
/// `mmlt`.
pub type Mmlt = Metropolis<MultiplexedTarget>;

/// Makes `pssmlt` (`base=bdpt` by default, or `pt`) for `scene`.
pub fn pssmlt(params: &Params, scene: &Scene, seed: u64) -> Result<Box<dyn Estimator>> {
    let settings = ChainSettings::from_params(params, true)?;
    let path = PathSettings::from_params(params, scene)?;
    check_lights(scene, "pssmlt")?;
    match params.get("base", "bdpt".to_string())?.as_str() {
        "pt" => {
            let target = PtTarget {
                sample: PathSample::one_at_a_time(path),
            };
            Ok(Box::new(Metropolis::new(
                "pssmlt",
                Some("pt"),
                scene,
                seed,
                settings,
                target,
            )?))
        }
        "bdpt" => {
            let bdpt = BdptSettings {
                path,
                mis: mis_from_params(params)?,
                strategies: false,
                strategies_max_depth: 1,
            };
            let target = BdptTarget {
                sample: BdptSample::without_images(bdpt),
            };
            Ok(Box::new(Metropolis::new(
                "pssmlt",
                Some("bdpt"),
                scene,
                seed,
                settings,
                target,
            )?))
        }
        other => Err(Error::usage(format!(
            "--set base={other}: expected pt or bdpt"
        ))),
    }
}

/// Makes `mmlt` for `scene`; `max_depth` must be finite.
pub fn mmlt(params: &Params, scene: &Scene, seed: u64) -> Result<Mmlt> {
    let mut settings = ChainSettings::from_params(params, false)?;
    let path = PathSettings::from_params(params, scene)?;
    check_lights(scene, "mmlt")?;
    let Some(max_depth) = path.max_depth else {
        return Err(Error::usage(
            "max_depth=-1 (unbounded): mmlt picks one path length per state, so the \
             lengths must be enumerable; pass --set max_depth=N (N ≥ 1) or set the scene's \
             integrator max_depth",
        ));
    };
    settings.lengths = Lengths::from_params(params)?;
    if settings.lengths == Lengths::Fixed {
        check_fixed_lengths(&settings, scene, max_depth)?;
    }
    let target = MultiplexedTarget::new(path, mis_from_params(params)?, max_depth);
    Metropolis::new("mmlt", None, scene, seed, settings, target)
}

/// `lengths=fixed` gives every path length the bootstrap finds lit a chain of its own, and
/// a chain that takes no mutation in a pass (there are more chains than pixels) would leave
/// its length out of the image; its weights need b fixed by the bootstrap.
fn check_fixed_lengths(settings: &ChainSettings, scene: &Scene, max_depth: u32) -> Result<()> {
    let window = scene.description.sensor.film.window();
    let pixels = window.width as u64 * window.height as u64;
    let usable = moving_chains(settings.chains, pixels);
    if usable < max_depth as u64 {
        return Err(Error::usage(format!(
            "--set lengths=fixed: {usable} chains that move every pass (chains = {}, {pixels} \
             pixels) for max_depth = {max_depth} path lengths; raise chains, lower max_depth \
             or set lengths=mutable",
            settings.chains
        )));
    }
    if settings.normalisation == Normalisation::LargeSteps {
        return Err(Error::usage(
            "--set normalisation=large_steps: not with lengths=fixed (each length's chains \
             are weighed by the bootstrap's b of that length)",
        ));
    }
    Ok(())
}

/// Chains per stratum for `lengths=fixed`: in proportion to the strata's mean importances
/// `means` (largest remainders), at least one for every stratum whose mean is above 0 and
/// none for the others. `chains` must be at least the number of strata.
pub fn chains_per_stratum(means: &[f64], chains: usize) -> Vec<usize> {
    let total: f64 = means.iter().sum();
    let lit = means.iter().filter(|&&m| m > 0.0).count();
    if lit == 0 {
        return vec![0; means.len()];
    }
    // One chain each for the lit strata, the rest in proportion.
    let rest = chains.saturating_sub(lit);
    let exact: Vec<f64> = means.iter().map(|&m| m / total * rest as f64).collect();
    let mut counts: Vec<usize> = means
        .iter()
        .zip(&exact)
        .map(|(&m, &x)| if m > 0.0 { 1 + x as usize } else { 0 })
        .collect();
    // The floors leave fewer chains than lit strata: one more each to the largest
    // remainders (ties to the lower stratum).
    let left = chains.saturating_sub(counts.iter().sum::<usize>());
    let mut order: Vec<usize> = (0..means.len()).filter(|&k| means[k] > 0.0).collect();
    order.sort_by(|&i, &j| {
        let (ri, rj) = (exact[i] - exact[i].floor(), exact[j] - exact[j].floor());
        rj.total_cmp(&ri).then(i.cmp(&j))
    });
    for &k in order.iter().take(left) {
        counts[k] += 1;
    }
    counts
}

/// A scene without a light has nothing to explore: an error naming the scene.
fn check_lights(scene: &Scene, name: &str) -> Result<()> {
    if scene.lights.is_empty() {
        return Err(Error::usage(format!(
            "{}: the scene has no light, so {name} has no path to start a chain from",
            scene.description.source.display()
        )));
    }
    Ok(())
}

/// Adds `lists` to `film` in order and empties them.
fn merge(film: &mut Film, lists: &mut [SplatList]) {
    for list in lists {
        film.merge_splats(list);
        list.clear();
    }
}

/// Where a group of chains starts and how its splats are weighed (`Metropolis::start`).
struct ChainPlacement {
    /// The bootstrap points they start from (by systematic resampling in proportion to
    /// importance).
    range: std::ops::Range<usize>,
    chains: usize,
    /// The stratum they keep (`lengths=fixed`), or None.
    fixed: Option<usize>,
    /// `Chain::scale`.
    scale: f64,
}

/// Chains that take a mutation in every pass of `pixels` mutations (`share` gives none to
/// chains beyond the pixel count).
fn moving_chains(chains: u32, pixels: u64) -> u64 {
    (chains as u64).min(pixels)
}

/// Mutations chain `k` of `chains` takes in one pass of `pixels` mutations.
fn share(pixels: u64, chains: u64, k: u64) -> u64 {
    pixels / chains + u64::from(k < pixels % chains)
}

impl<T: PathTarget> Metropolis<T> {
    pub fn new(
        name: &'static str,
        base: Option<&'static str>,
        scene: &Scene,
        seed: u64,
        settings: ChainSettings,
        target: T,
    ) -> Result<Self> {
        let window = scene.description.sensor.film.window();
        let film = Film::new(
            window.width,
            window.height,
            scene.description.sensor.film.filter,
        )?;
        Ok(Metropolis {
            name,
            base,
            settings,
            target,
            seed,
            film,
            pending: Vec::new(),
            fresh: Vec::new(),
            chains: Vec::new(),
            bootstrap: None,
            pilot: None,
            stats: Stats::default(),
            seconds: 0.0,
            bootstrap_seconds: 0.0,
        })
    }

    /// The path function the chains explore.
    pub fn target(&self) -> &T {
        &self.target
    }

    /// What the bootstrap found (after the first pass).
    pub fn bootstrap(&self) -> Option<&Bootstrap> {
        self.bootstrap.as_ref()
    }

    /// The chains (their counts and recorded importances).
    pub fn chains(&self) -> &[Chain] {
        &self.chains
    }

    fn sampler(&self, key: &[u64]) -> PrimarySampleSampler {
        PrimarySampleSampler::new(key, self.settings.large_step, self.settings.mutation)
    }

    /// Evaluates `bootstrap` independent points per stratum, keyed by (seed, `key`, index),
    /// and returns `keep` of each (its contributions) in index order; adds their rays to the
    /// counts. Each point's numbers come from its own key, so the order of evaluation does
    /// not matter.
    fn independent_points<R: Send>(
        &mut self,
        scene: &Scene,
        key: u64,
        keep: impl Fn(&Contributions) -> R + Sync,
    ) -> Vec<R> {
        let n = self.settings.bootstrap as u64;
        let (seed, this) = (self.seed, &*self);
        let evaluated: Vec<(R, u64)> = (0..self.target.strata() as u64 * n)
            .into_par_iter()
            .map_init(
                || (T::Scratch::default(), Contributions::default()),
                |(scratch, out), j| {
                    let mut sampler = this.sampler(&[seed, key, j]);
                    let stratum = (j / n) as usize;
                    let e = this
                        .target
                        .evaluate(scene, &mut sampler, Some(stratum), scratch, out);
                    (keep(out), e.rays)
                },
            )
            .collect();
        self.stats.rays += evaluated.iter().map(|e| e.1).sum::<u64>();
        evaluated.into_iter().map(|e| e.0).collect()
    }

    /// `importance=relative`'s pilot: `bootstrap` independent points per stratum of their
    /// own (not the bootstrap's: b must be estimated from points the pilot did not see, or
    /// the blocks where the pilot found no light, whose importance is largest, would be
    /// missing from b by construction and the image would come out too dark).
    fn make_pilot(&mut self, scene: &Scene) {
        let entries = self.independent_points(scene, PILOT_KEY, |out| {
            let entries = out.entries.iter();
            let entries = entries.map(|&(raster, v)| (raster, v.luminance() as f64));
            entries.collect::<Vec<(Vec2, f64)>>()
        });
        let n = self.settings.bootstrap as u64;
        let (width, height) = (self.film.width(), self.film.height());
        let all = entries.iter().flatten().copied();
        self.pilot = Some(PilotMap::new(width, height, entries.len() as u64, n, all));
    }

    /// The bootstrap (after the pilot, with `importance=relative`), then the chains' first
    /// states.
    fn start(&mut self, scene: &Scene) {
        if self.settings.importance == ImportanceKind::Relative {
            self.make_pilot(scene);
        }
        let strata = self.target.strata();
        let n = self.settings.bootstrap as u64;
        let seed = self.seed;
        // Importance of every bootstrap point, stratum by stratum.
        let pilot = self.pilot.clone();
        let importance: Vec<f32> =
            self.independent_points(scene, BOOTSTRAP_KEY, |out| match &pilot {
                Some(map) => map.importance(out) as f32,
                None => out.luminance as f32,
            });
        let bootstrap = Bootstrap::new(&importance, strata, n);
        self.target.set_stratum_means(&bootstrap.stratum_means);
        if !(bootstrap.b > 0.0 && bootstrap.b.is_finite()) {
            eprintln!(
                "warning: {}: none of the {} bootstrap samples carried light to the film; \
                 the image stays black",
                self.name,
                importance.len()
            );
            self.bootstrap = Some(bootstrap);
            return;
        }
        // Systematic resampling in proportion to importance: chain k takes the point where
        // the running sum crosses (k + ξ_k)/chains of the total.
        let prefix: Vec<f64> = importance
            .iter()
            .scan(0.0f64, |acc, &x| {
                *acc += x as f64;
                Some(*acc)
            })
            .collect();
        let placements = match self.settings.lengths {
            Lengths::Mutable => {
                let chains = self.settings.chains as usize;
                let everywhere = ChainPlacement {
                    range: 0..prefix.len(),
                    chains,
                    fixed: None,
                    scale: 1.0,
                };
                vec![everywhere]
            }
            Lengths::Fixed => self.fixed_placements(&bootstrap, n as usize),
        };
        let this = &*self;
        let chain_list: Vec<(u64, u64, &ChainPlacement)> = placements
            .iter()
            .flat_map(|p| (0..p.chains as u64).map(move |i| (i, p)))
            .enumerate()
            .map(|(k, (i, p))| (k as u64, i, p))
            .collect();
        let started: Vec<Chain> = chain_list
            .into_par_iter()
            .map(|(k, i, placement)| {
                // Systematic resampling within the placement's bootstrap points.
                let range = &placement.range;
                let below = if range.start == 0 {
                    0.0
                } else {
                    prefix[range.start - 1]
                };
                let span = prefix[range.end - 1] - below;
                let xi = to_unit_f32(hash_words(&[seed, SELECT_KEY, k])) as f64;
                let target_sum = below + (i as f64 + xi) / placement.chains as f64 * span;
                let j = prefix[range.clone()]
                    .partition_point(|&p| p <= target_sum)
                    .min(range.len() - 1)
                    + range.start;
                let j = j as u64;
                let stratum = (j / n) as usize;
                let mut sampler = this.sampler(&[seed, BOOTSTRAP_KEY, j]);
                let mut scratch = T::Scratch::default();
                let mut out = Contributions::default();
                this.target
                    .evaluate(scene, &mut sampler, Some(stratum), &mut scratch, &mut out);
                if placement.fixed.is_none() {
                    // The same point in the chain's coordinates, evaluated as a chain state.
                    this.target.to_chain_state(&mut sampler, stratum);
                    sampler.restart_evaluation();
                    this.target
                        .evaluate(scene, &mut sampler, None, &mut scratch, &mut out);
                }
                if let Some(map) = &this.pilot {
                    out.luminance = map.importance(&out);
                }
                sampler.start_chain(&[seed, CHAIN_KEY, k]);
                let mut chain = Chain::new(sampler, out);
                chain.stratum = placement.fixed;
                chain.scale = placement.scale;
                chain
            })
            .collect();
        self.chains = started;
        self.bootstrap = Some(bootstrap);
    }

    /// `lengths=fixed`: where each stratum's chains start and how they weigh their splats.
    /// Stratum k gets chains in proportion to its mean importance b_k, each placed among
    /// its own `per_stratum` bootstrap points; with m_k of a pass's mutations, its splats
    /// are scaled by (b_k / b)·(mutations / m_k), so that it adds b_k times its chains'
    /// mean (b × splats / mutations per pixel, as every chain's image is read).
    fn fixed_placements(&self, bootstrap: &Bootstrap, per_stratum: usize) -> Vec<ChainPlacement> {
        let pixels = self.film.width() as u64 * self.film.height() as u64;
        let usable = moving_chains(self.settings.chains, pixels);
        let counts = chains_per_stratum(&bootstrap.stratum_means, usable as usize);
        let mut first = 0u64;
        let mut placements = Vec::new();
        for (k, &c) in counts.iter().enumerate() {
            if c == 0 {
                continue;
            }
            let mutations: u64 = (first..first + c as u64)
                .map(|i| share(pixels, usable, i))
                .sum();
            first += c as u64;
            let b_k = bootstrap.stratum_means[k];
            placements.push(ChainPlacement {
                range: k * per_stratum..(k + 1) * per_stratum,
                chains: c,
                fixed: Some(k),
                scale: b_k / bootstrap.b * pixels as f64 / mutations as f64,
            });
        }
        placements
    }

    /// The counts of every chain, summed.
    pub fn counts(&self) -> ChainCounts {
        let mut total = ChainCounts::default();
        for c in &self.chains {
            total.add(&c.counts);
        }
        total
    }

    /// The diagnostics so far (None before the first pass).
    /// `normalisation=large_steps`: b from the bootstrap's points and every large step's
    /// proposal so far, pooled by their counts (chain by chain, in chain order).
    pub fn pooled_b(&self) -> Option<f64> {
        let bootstrap = self.bootstrap.as_ref()?;
        let mut sum = bootstrap.b * bootstrap.samples as f64;
        let mut count = bootstrap.samples as f64;
        for chain in &self.chains {
            sum += chain.counts.large_importance;
            count += chain.counts.large_proposed as f64;
        }
        Some(if count > 0.0 { sum / count } else { 0.0 })
    }

    /// The image of `film`'s splats: per mutation, times b where the splats carry b = 1.
    fn read_film(&self, film: &Film) -> Image {
        let samples = self.stats.samples;
        match self.settings.normalisation {
            Normalisation::Bootstrap => film.image_with_light_paths(samples),
            Normalisation::LargeSteps if samples > 0 => {
                let pixels = film.width() as f64 * film.height() as f64;
                let b = self.pooled_b().unwrap_or(0.0);
                film.image(pixels / samples as f64 * b)
            }
            Normalisation::LargeSteps => film.image(0.0),
        }
    }

    pub fn diagnostics_report(&self) -> Option<Diagnostics> {
        let bootstrap = self.bootstrap.as_ref()?;
        let mut report = Diagnostics::new(
            self.name,
            self.base,
            &self.settings,
            bootstrap,
            &self.chains,
            self.seconds,
            self.bootstrap_seconds,
        );
        report.pilot_block = self.pilot.as_ref().map(PilotMap::block_size);
        if self.settings.normalisation == Normalisation::LargeSteps {
            report.b_pooled = self.pooled_b();
        }
        Some(report)
    }
}

impl<T: PathTarget> Estimator for Metropolis<T> {
    fn name(&self) -> &str {
        self.name
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        self.run_passes(scene, pass_index, 1);
    }

    fn run_passes(&mut self, scene: &Scene, _first: u32, count: u32) {
        let start = Instant::now();
        if self.bootstrap.is_none() {
            self.start(scene);
            self.bootstrap_seconds = start.elapsed().as_secs_f64();
        }
        self.stats.passes += count as u64;
        if self.chains.is_empty() {
            self.seconds += start.elapsed().as_secs_f64();
            return;
        }
        let pixels = self.film.width() as u64 * self.film.height() as u64;
        let n_chains = self.chains.len() as u64;
        let settings = self.settings;
        // With b pooled from the large steps, the splats are scaled by it when the image is
        // read (`image`), so they carry b = 1 here.
        let b = match settings.normalisation {
            Normalisation::Bootstrap => self.bootstrap.as_ref().map_or(0.0, |s| s.b),
            Normalisation::LargeSteps => 1.0,
        };
        let Metropolis {
            target,
            chains,
            film,
            pending,
            fresh,
            pilot,
            ..
        } = self;
        let pilot = &*pilot;
        for _ in 0..count {
            // One list per chain (after a swap `fresh` holds the lists just merged, or none
            // before the first pass).
            fresh.resize_with(chains.len(), SplatList::new);
            // The previous pass's splats go to the film (in chain order) while the chains
            // take this pass's steps: the merge is serial, and overlapping it keeps the
            // second thread busy.
            rayon::join(
                || merge(film, pending),
                || {
                    chains
                        .par_iter_mut()
                        .zip(fresh.par_iter_mut())
                        .enumerate()
                        .for_each_init(T::Scratch::default, |scratch, (k, (chain, list))| {
                            list.clear();
                            let stratum = chain.stratum;
                            for _ in 0..share(pixels, n_chains, k as u64) {
                                chain.step(&settings, b, list, |sampler, out| {
                                    let e = target.evaluate(scene, sampler, stratum, scratch, out);
                                    if let Some(map) = pilot {
                                        out.luminance = map.importance(out);
                                    }
                                    (e.rays, e.invalid)
                                });
                            }
                        })
                },
            );
            std::mem::swap(pending, fresh);
        }
        let counts = self.counts();
        self.stats.samples = counts.steps();
        self.stats.invalid_samples = counts.invalid;
        self.seconds += start.elapsed().as_secs_f64();
    }

    fn image(&self) -> Image {
        if self.pending.iter().all(SplatList::is_empty) {
            return self.read_film(&self.film);
        }
        let mut film = self.film.clone();
        for list in &self.pending {
            film.merge_splats(list);
        }
        self.read_film(&film)
    }

    fn stats(&self) -> Stats {
        let mut stats = self.stats.clone();
        stats.rays += self.counts().rays;
        stats
    }

    fn diagnostics(&self) -> Option<serde_json::Value> {
        serde_json::to_value(self.diagnostics_report()?).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_are_shared_out_over_strata_in_proportion() {
        // In proportion where the shares are whole.
        assert_eq!(chains_per_stratum(&[1.0, 2.0, 1.0], 4 + 3), vec![2, 3, 2]);
        // Every lit stratum one chain at least, dark ones none; the total is kept.
        let counts = chains_per_stratum(&[0.0, 100.0, 1e-6, 0.0, 5.0], 10);
        assert_eq!(counts.iter().sum::<usize>(), 10);
        assert_eq!((counts[0], counts[3]), (0, 0));
        assert!(
            counts[2] == 1 && counts[1] > counts[4] && counts[4] >= 1,
            "{counts:?}"
        );
        // Largest remainders: 3 chains left after one each over shares 0.5, 0.3, 0.2
        // make 1.5, 0.9, 0.6, rounded to 2, 1, 0 … and then the remainders 0.9 and 0.6.
        assert_eq!(chains_per_stratum(&[5.0, 3.0, 2.0], 6), vec![2, 2, 2]);
        assert_eq!(chains_per_stratum(&[0.0, 0.0], 8), vec![0, 0]);
        for chains in 4..200 {
            let means = [0.3, 0.0, 2.0, 0.01, 1.0];
            let counts = chains_per_stratum(&means, chains);
            assert_eq!(counts.iter().sum::<usize>(), chains);
            // Within one chain of the proportional share of the chains beyond the first.
            let rest = (chains - 4) as f64 / 3.31;
            for (k, &m) in means.iter().enumerate() {
                if m > 0.0 {
                    let want = 1.0 + m * rest;
                    assert!(
                        (counts[k] as f64 - want).abs() < 1.0,
                        "{chains}: {counts:?}"
                    );
                }
            }
        }
    }
}
