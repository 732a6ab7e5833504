//! `mmlt`'s path function: one path length and one bidirectional strategy per point of
//! primary sample space (Hachisuka et al. 2014, "Multiplexed Metropolis light transport").
//!
//! The first number of the connection stream picks the path length d (segments, Mitsuba's
//! count) with probability p(d), the second one of its d + 1 strategies (s, t),
//! s + t = d + 1, t ≥ 1, uniformly. Two numbers, not one: a small step moves each by about
//! 1/256 (Kelemen's), while one number's interval per strategy would be only p(d)/(d + 1)
//! wide (about 0.01 for the longer paths of door-ajar), so most small steps would have
//! switched strategy, which leaves nothing of the path in place, and been rejected. Only
//! that strategy is traced: a camera subpath of t
//! vertices and a light subpath of s. Its contribution is the strategy's MIS-weighted
//! value over the probability of picking it, C·w_(s,t)·(d + 1)/p(d), so the expected value
//! over the first two numbers is the sum over all strategies and lengths: the image.
//!
//! With `lengths=fixed` (the default) a chain keeps the length it started with: it is
//! evaluated with that length as its stratum, so the first number is read but not used and
//! the value carries no 1/p(d) (`Metropolis::start` weighs each length's chains by b_d
//! instead). With `lengths=mutable` the first number picks the length: p(d) comes from the
//! bootstrap, which runs per path length: p(d) ∝ b_d, the mean importance of length d,
//! mixed with a uniform share (`UNIFORM_SHARE`) so that a length the bootstrap found dark
//! can still be reached. p only changes how often large steps land on each length; the
//! chain's stationary distribution spends time ∝ b_d on length d whatever p is, but it
//! moves between lengths only by large steps that are accepted (rarely, where light takes
//! one narrow way), so each length's share of the image is left to chance for long
//! stretches. Fixing the lengths fixes those shares by the bootstrap: on the door-ajar
//! rooms (30 s, 5 runs each) `mmlt`'s relMSE fell by a fifth (door-ajar) and a tenth
//! (door-ajar-indirect), part of it from 7–12% more mutations per second.

use crate::estimator::bdpt::Heuristic;
use crate::estimator::camera_pass::camera_ray_in_image;
use crate::estimator::mlt::target::{Contributions, Evaluation, PathTarget};
use crate::path::connection::{self, SubpathWeights};
use crate::path::settings::PathSettings;
use crate::path::subpath::{camera_subpath, light_subpath};
use crate::path::vertex::Vertex;
use crate::sampler::primary_sample::PrimarySampleSampler;
use crate::sampler::{Sampler, Stream};
use crate::scene::Scene;

/// The share of large steps spread uniformly over path lengths.
const UNIFORM_SHARE: f64 = 0.05;

pub struct MultiplexedTarget {
    pub path: PathSettings,
    pub mis: Heuristic,
    /// The longest path length, `path.max_depth`.
    max_depth: usize,
    /// cdf[k] = p(1) + … + p(k) (cdf[0] = 0, cdf[max_depth] = 1).
    cdf: Vec<f64>,
}

/// `MultiplexedTarget`'s buffers.
#[derive(Default)]
pub struct MultiplexedScratch<'a> {
    camera_path: Vec<Vertex<'a>>,
    light_path: Vec<Vertex<'a>>,
    weights: SubpathWeights,
}

impl MultiplexedTarget {
    /// `max_depth` must be finite (`mmlt::new` checks).
    pub fn new(path: PathSettings, mis: Heuristic, max_depth: u32) -> MultiplexedTarget {
        let max_depth = max_depth as usize;
        MultiplexedTarget {
            path,
            mis,
            max_depth,
            cdf: (0..=max_depth)
                .map(|k| k as f64 / max_depth.max(1) as f64)
                .collect(),
        }
    }

    /// The probability of path length d (1-based).
    pub fn length_probability(&self, d: usize) -> f64 {
        self.cdf[d] - self.cdf[d - 1]
    }

    /// The path length d, the strategy's s and the probability of picking length d, from
    /// the connection stream's first number `u_length` (ignored for a bootstrap `stratum`,
    /// which is the length) and its second `u_strategy`. The strategy depends on
    /// `u_strategy` alone: s = ⌊u_strategy·(d + 1)⌋.
    fn choose(
        &self,
        u_length: f64,
        u_strategy: f64,
        stratum: Option<usize>,
    ) -> (usize, usize, f64) {
        let (d, pick) = match stratum {
            Some(k) => (k + 1, 1.0),
            None => {
                let d = self.length_of(u_length);
                (d, self.length_probability(d))
            }
        };
        let s = ((u_strategy * (d + 1) as f64) as usize).min(d);
        (d, s, pick)
    }

    /// The path length whose interval of the cdf holds u.
    fn length_of(&self, u: f64) -> usize {
        // The first k with cdf[k] > u, skipping lengths of probability 0.
        let k = self.cdf.partition_point(|&c| c <= u);
        k.clamp(1, self.max_depth)
    }
}

impl PathTarget for MultiplexedTarget {
    type Scratch<'a> = MultiplexedScratch<'a>;

    fn strata(&self) -> usize {
        self.max_depth
    }

    fn evaluate<'a>(
        &self,
        scene: &'a Scene,
        sampler: &mut impl Sampler,
        stratum: Option<usize>,
        scratch: &mut MultiplexedScratch<'a>,
        out: &mut Contributions,
    ) -> Evaluation {
        out.clear();
        let mut eval = Evaluation::default();
        if self.max_depth == 0 {
            return eval;
        }
        // The path length and the strategy from the connection stream's first two numbers.
        sampler.start_stream(Stream::Connect);
        let u_length = sampler.next_1d() as f64;
        let u_strategy = sampler.next_1d() as f64;
        let (d, s, pick) = self.choose(u_length, u_strategy, stratum);
        let strategies = d + 1;
        let t = d + 1 - s;
        if s == 0 && t == 1 {
            return eval;
        }
        let rr_depth = self.path.rr_depth;
        let MultiplexedScratch {
            camera_path,
            light_path,
            weights,
        } = scratch;
        let (raster, ray) = camera_ray_in_image(
            &scene.camera,
            {
                let w = scene.description.sensor.film.window();
                (w.width, w.height)
            },
            sampler,
        );
        eval.rays += camera_subpath(scene, ray, t - 1, rr_depth, sampler, camera_path);
        if camera_path.len() < t {
            return eval;
        }
        sampler.start_stream(Stream::Light);
        let start = if s >= 1 {
            let (start, rays) = light_subpath(scene, s - 1, rr_depth, sampler, light_path);
            eval.rays += rays;
            if light_path.len() < s {
                return eval;
            }
            start
        } else {
            light_path.clear();
            None
        };
        // Past the strategy choice, the connection stream's numbers.
        sampler.start_stream(Stream::Connect);
        let hide = self.path.hide_emitters;
        let Some(c) = connection::connect(
            scene,
            light_path,
            camera_path,
            start.as_ref(),
            s,
            t,
            hide,
            sampler,
        ) else {
            return eval;
        };
        if c.value.is_black() {
            return eval;
        }
        // Visibility before the weight (whose subpath sums cost O(d)).
        if let Some(shadow) = &c.shadow {
            eval.rays += 1;
            if scene.geometry.occluded(shadow) {
                return eval;
            }
        }
        weights.fill(light_path, camera_path, self.mis);
        let w = connection::weight(
            scene,
            light_path,
            camera_path,
            c.ends(),
            s,
            t,
            self.mis,
            hide,
            weights,
        );
        let value = c.value * (w * (strategies as f64 / pick) as f32);
        out.push(c.raster.unwrap_or(raster), value, &mut eval.invalid);
        out.finish();
        eval
    }

    fn set_stratum_means(&mut self, means: &[f64]) {
        let total: f64 = means.iter().sum();
        let n = self.max_depth as f64;
        let mut acc = 0.0;
        self.cdf = std::iter::once(0.0)
            .chain(means.iter().map(|&b| {
                let share = if total > 0.0 { b / total } else { 1.0 / n };
                acc += (1.0 - UNIFORM_SHARE) * share + UNIFORM_SHARE / n;
                acc
            }))
            .collect();
        // The last entry is exactly 1 whatever the rounding.
        if let Some(last) = self.cdf.last_mut() {
            *last = 1.0;
        }
    }

    fn to_chain_state(&self, sampler: &mut PrimarySampleSampler, stratum: usize) {
        let d = stratum + 1;
        let (lo, p) = (self.cdf[d - 1], self.length_probability(d));
        sampler.map_value(Stream::Connect, 0, |local| lo + local * p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The strategy is a function of its own number, in intervals 1/(d + 1) wide whatever
    /// p(d) is: moving the length's number inside its interval never switches strategy,
    /// and every strategy of every length is reached with the probability the weight
    /// divides by. (With one number for both, the strategies' intervals were p(d)/(d + 1)
    /// wide and a small step switched strategy when it moved the length's number.)
    #[test]
    fn the_strategy_has_its_own_number() {
        let path = PathSettings {
            max_depth: Some(10),
            rr_depth: 5,
            hide_emitters: false,
        };
        let mut target = MultiplexedTarget::new(path, Heuristic::Power, 10);
        // Lengths of very unequal weight, as a bootstrap finds them.
        target.set_stratum_means(&[0.0, 5.0, 3.0, 1.0, 0.5, 0.2, 0.1, 0.05, 0.01, 0.0]);
        for d in 1..=10 {
            let (lo, p) = (target.cdf[d - 1], target.length_probability(d));
            assert!(p > 0.0, "length {d} unreachable");
            let mut counts = vec![0usize; d + 1];
            let n = 2000 * (d + 1);
            for k in 0..n {
                let u_strategy = (k as f64 + 0.5) / n as f64;
                let want = (u_strategy * (d + 1) as f64) as usize;
                for f in [0.001, 0.3, 0.5, 0.999] {
                    let (got_d, s, pick) = target.choose(lo + f * p, u_strategy, None);
                    assert_eq!((got_d, s), (d, want), "length {d}, u {u_strategy}, at {f}");
                    assert_eq!(pick, p);
                }
                counts[want] += 1;
            }
            // Each strategy equally often: 1/(d + 1), the factor the value carries.
            assert!(counts.iter().all(|&c| c == 2000), "length {d}: {counts:?}");
            // A bootstrap stratum fixes the length and ignores the length's number.
            assert_eq!(
                target.choose(0.0, 0.7, Some(d - 1)),
                (d, ((0.7 * (d + 1) as f64) as usize).min(d), 1.0)
            );
        }
    }
}
