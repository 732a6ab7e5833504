//! The primary-sample-space sampler of Metropolis light transport (Kelemen et al. 2002).
//!
//! A path is a deterministic function of the uniform numbers its estimator draws; this
//! sampler hands out those numbers from a state that a Markov chain mutates. Each stream
//! (`Stream::Camera`, `Light`, `Connect`) is a vector of its own, so a proposal that makes
//! the light subpath longer does not shift the camera subpath's coordinates.
//!
//! Coordinates are created and mutated lazily (as in Kelemen et al. 2002, §4): each one
//! remembers the iteration it was last brought up to date, and is caught up only when an
//! evaluation reads it. A coordinate untouched since before the last accepted large step
//! is redrawn uniformly (the large step replaced it); one untouched for n small steps gets
//! the composition of those n steps (`Mutation::compose`).

use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

use super::independent::hash_words;
use super::{Sampler, Stream};

/// A small step's perturbation of one coordinate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mutation {
    /// Kelemen et al. 2002, §4.1: an offset s2·exp(−ln(s2/s1)·u) of random sign, between
    /// `s1` and `s2`, wrapped around [0, 1).
    Kelemen { s1: f64, s2: f64 },
    /// A normal offset of standard deviation `sigma`, wrapped around [0, 1).
    Gaussian { sigma: f64 },
}

/// A mutation with what its small steps need computed once (two logarithms per step were a
/// tenth of `mmlt`'s time).
#[derive(Clone, Copy, Debug)]
struct SmallStep {
    mutation: Mutation,
    /// ln(s2/s1) for Kelemen's step.
    log_ratio: f64,
    /// Steps beyond which their composition is uniform to double precision.
    uniform_after: u64,
}

impl SmallStep {
    fn new(mutation: Mutation) -> Self {
        match mutation {
            Mutation::Kelemen { s1, s2 } => {
                // The sum's first Fourier coefficient is E[cos 2πΔ]^n ≈ exp(−2π²·E[Δ²]·n),
                // below e^−40 from here on (higher frequencies decay faster); E[Δ²] for
                // Δ = s2·exp(−L·u), L = ln(s2/s1), u uniform.
                let log_ratio = (s2 / s1).ln();
                let second_moment = (s2 * s2 - s1 * s1) / (2.0 * log_ratio);
                let rate = 2.0 * std::f64::consts::PI.powi(2) * second_moment;
                SmallStep {
                    mutation,
                    log_ratio,
                    uniform_after: (40.0 / rate).ceil() as u64,
                }
            }
            Mutation::Gaussian { .. } => SmallStep {
                mutation,
                log_ratio: 0.0,
                uniform_after: u64::MAX,
            },
        }
    }

    /// `value` after `n` ≥ 1 small steps, drawing from `rng`: exactly their composition
    /// (for the Gaussian, one normal of variance n·σ²; for Kelemen's, the steps one by one,
    /// or a uniform once they make one).
    fn compose(&self, value: f64, n: u64, rng: &mut Xoshiro256PlusPlus) -> f64 {
        match self.mutation {
            Mutation::Kelemen { s2, .. } => {
                if n >= self.uniform_after {
                    return unit_f64(rng);
                }
                let mut v = value;
                for _ in 0..n {
                    let u = unit_f64(rng);
                    // One number gives both the sign and the size.
                    let (sign, u) = if u < 0.5 {
                        (1.0, 2.0 * u)
                    } else {
                        (-1.0, 2.0 * u - 1.0)
                    };
                    // The size in f32 (the coordinate is read as f32): expf is the cheaper
                    // exponential, and any size distribution keeps the step symmetric.
                    let size = ((-self.log_ratio * u) as f32).exp() as f64;
                    v = wrap(v + sign * s2 * size);
                }
                v
            }
            Mutation::Gaussian { sigma } => {
                let z = standard_normal(rng);
                wrap(value + sigma * (n as f64).sqrt() * z)
            }
        }
    }
}

/// `v` wrapped into [0, 1) (the primary sample space is a torus).
fn wrap(v: f64) -> f64 {
    let w = v - v.floor();
    if w < 1.0 { w } else { 0.0 }
}

/// A uniform double in [0, 1) from the top 53 bits.
fn unit_f64(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A standard normal number (Box–Muller, one of the pair).
fn standard_normal(rng: &mut Xoshiro256PlusPlus) -> f64 {
    let u1 = 1.0 - unit_f64(rng); // (0, 1]: the logarithm stays finite
    let u2 = unit_f64(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// One coordinate of the state, with what a rejection restores.
#[derive(Clone, Copy, Debug)]
struct Coordinate {
    value: f64,
    /// The iteration the value is up to date with.
    modified: u64,
    backup_value: f64,
    backup_modified: u64,
}

const STREAMS: usize = 3;

fn stream_index(stream: Stream) -> usize {
    match stream {
        Stream::Camera => 0,
        Stream::Light => 1,
        Stream::Connect => 2,
    }
}

/// The chain's state in primary sample space and the mutations that move it.
pub struct PrimarySampleSampler {
    coordinates: [Vec<Coordinate>; STREAMS],
    /// The next coordinate each stream hands out in this evaluation.
    next: [usize; STREAMS],
    stream: usize,
    /// Coordinates this iteration changed, (stream, index), for `reject`.
    touched: Vec<(u8, u32)>,
    iteration: u64,
    /// The iteration of the last accepted large step (0: the first state, which is one).
    last_large_step: u64,
    large_step: bool,
    large_step_probability: f64,
    small_step: SmallStep,
    rng: Xoshiro256PlusPlus,
}

impl PrimarySampleSampler {
    /// A sampler whose first evaluation is a large step (every coordinate uniform) drawn
    /// from the stream keyed by `key`: the same key gives the same first state.
    pub fn new(key: &[u64], large_step_probability: f64, mutation: Mutation) -> Self {
        PrimarySampleSampler {
            coordinates: Default::default(),
            next: [0; STREAMS],
            stream: 0,
            touched: Vec::new(),
            iteration: 0,
            last_large_step: 0,
            large_step: true,
            large_step_probability,
            small_step: SmallStep::new(mutation),
            rng: Xoshiro256PlusPlus::seed_from_u64(hash_words(key)),
        }
    }

    /// Accepts the first state (the evaluation made since `new`) and draws every later
    /// mutation from the stream keyed by `key`: two chains that start from the same
    /// bootstrap sample then move apart.
    pub fn start_chain(&mut self, key: &[u64]) {
        self.accept();
        self.rng = Xoshiro256PlusPlus::seed_from_u64(hash_words(key));
    }

    /// Starts the next proposal: a large step with the large-step probability, else a small
    /// step. The evaluation that follows reads the proposed state.
    pub fn start_iteration(&mut self) {
        self.iteration += 1;
        self.large_step = unit_f64(&mut self.rng) < self.large_step_probability;
        self.next = [0; STREAMS];
        self.stream = 0;
        self.touched.clear();
    }

    /// Reads the state from its first coordinates again, without mutating it (within one
    /// iteration every coordinate keeps the value it was brought to).
    pub fn restart_evaluation(&mut self) {
        self.next = [0; STREAMS];
        self.stream = 0;
    }

    /// True when the current proposal is a large step.
    pub fn is_large_step(&self) -> bool {
        self.large_step
    }

    /// A uniform number from the chain's own stream (for the acceptance test).
    pub fn uniform(&mut self) -> f64 {
        unit_f64(&mut self.rng)
    }

    /// Keeps the proposal as the new state.
    pub fn accept(&mut self) {
        if self.large_step {
            self.last_large_step = self.iteration;
        }
        self.touched.clear();
    }

    /// Restores the state from before the proposal.
    pub fn reject(&mut self) {
        for &(s, i) in &self.touched {
            let c = &mut self.coordinates[s as usize][i as usize];
            c.value = c.backup_value;
            c.modified = c.backup_modified;
        }
        self.touched.clear();
        self.iteration -= 1;
    }

    /// Re-expresses coordinate `index` of `stream` by `map` (the multiplexed estimator
    /// turns a bootstrap sample's strategy number into the chain's, `mmlt`). The result is
    /// clamped into [0, 1).
    pub fn map_value(&mut self, stream: Stream, index: usize, map: impl FnOnce(f64) -> f64) {
        if let Some(c) = self.coordinates[stream_index(stream)].get_mut(index) {
            c.value = map(c.value).clamp(0.0, 1.0f64.next_down());
        }
    }

    /// The number of coordinates each stream has created so far.
    pub fn dimensions(&self) -> [usize; STREAMS] {
        std::array::from_fn(|s| self.coordinates[s].len())
    }

    /// Brings coordinate `index` of the current stream up to date with this iteration's
    /// proposal and returns it.
    fn coordinate(&mut self, index: usize) -> f64 {
        let s = self.stream;
        if index >= self.coordinates[s].len() {
            // A coordinate no evaluation has read yet is independent of the state: a
            // uniform, current as of the iteration before this one.
            let value = unit_f64(&mut self.rng);
            let modified = self.iteration.saturating_sub(1).max(self.last_large_step);
            self.coordinates[s].push(Coordinate {
                value,
                modified,
                backup_value: value,
                backup_modified: modified,
            });
        }
        let (large_step, iteration, last_large) =
            (self.large_step, self.iteration, self.last_large_step);
        let small_step = self.small_step;
        let rng = &mut self.rng;
        let c = &mut self.coordinates[s][index];
        if c.modified == iteration {
            return c.value;
        }
        // A large step accepted after the last update replaced this coordinate too.
        if c.modified < last_large {
            c.value = unit_f64(rng);
            c.modified = last_large;
        }
        c.backup_value = c.value;
        c.backup_modified = c.modified;
        if large_step {
            c.value = unit_f64(rng);
        } else if iteration > c.modified {
            c.value = small_step.compose(c.value, iteration - c.modified, rng);
        }
        c.modified = iteration;
        self.touched.push((s as u8, index as u32));
        c.value
    }
}

impl Sampler for PrimarySampleSampler {
    fn start_stream(&mut self, stream: Stream) {
        self.stream = stream_index(stream);
    }

    fn next_1d(&mut self) -> f32 {
        let index = self.next[self.stream];
        self.next[self.stream] += 1;
        let v = self.coordinate(index) as f32;
        // Rounding to f32 may reach 1.
        if v < 1.0 { v } else { 1.0f32.next_down() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KELEMEN: Mutation = Mutation::Kelemen {
        s1: 1.0 / 1024.0,
        s2: 1.0 / 64.0,
    };

    /// Reads `n` numbers from each stream.
    fn read(sampler: &mut PrimarySampleSampler, n: usize) -> Vec<f32> {
        let mut out = Vec::new();
        for stream in [Stream::Camera, Stream::Light, Stream::Connect] {
            sampler.start_stream(stream);
            out.extend((0..n).map(|_| sampler.next_1d()));
        }
        out
    }

    /// A rejected proposal leaves the state exactly as it was, and the same key gives the
    /// same first state.
    #[test]
    fn rejection_restores_the_state_and_keys_replay() {
        let mut a = PrimarySampleSampler::new(&[1, 2], 0.3, KELEMEN);
        let first = read(&mut a, 5);
        let mut b = PrimarySampleSampler::new(&[1, 2], 0.3, KELEMEN);
        assert_eq!(read(&mut b, 5), first);
        a.start_chain(&[9]);
        for _ in 0..50 {
            a.start_iteration();
            let proposal = read(&mut a, 5);
            assert_ne!(proposal, first);
            a.reject();
        }
        // A proposal that reads nothing new leaves the state; reading it again without a
        // mutation (a repeated read in one iteration) gives the same numbers.
        a.start_iteration();
        let p1 = read(&mut a, 5);
        a.next = [0; STREAMS];
        assert_eq!(read(&mut a, 5), p1);
        a.reject();
        // The restored state, read at an iteration that changes nothing: compare the
        // stored values.
        let stored: Vec<f32> = a
            .coordinates
            .iter()
            .flat_map(|c| c.iter().map(|c| c.value as f32))
            .collect();
        assert_eq!(stored, first);
    }

    /// Small steps move a coordinate by at most s2 each (on the torus), and the lazy
    /// catch-up of n steps equals n steps taken one by one in distribution: after n skipped
    /// small steps the mean squared displacement is n·E[Δ²].
    #[test]
    fn lazy_small_steps_compose() {
        let (s1, s2) = (1.0f64 / 1024.0, 1.0f64 / 64.0);
        let second_moment = (s2 * s2 - s1 * s1) / (2.0 * (s2 / s1).ln());
        let torus = |a: f64, b: f64| {
            let d = (a - b).abs();
            d.min(1.0 - d)
        };
        for n in [1u64, 7] {
            let mut sum = 0.0;
            let mut sum_sq = 0.0;
            let trials = 20_000;
            for k in 0..trials {
                let mut s = PrimarySampleSampler::new(&[k], 0.0, KELEMEN);
                s.start_stream(Stream::Camera);
                let x0 = s.next_1d() as f64;
                s.start_chain(&[k, 1]);
                // n − 1 iterations that do not read the coordinate, then one that does.
                for _ in 0..n - 1 {
                    s.start_iteration();
                    s.accept();
                }
                s.start_iteration();
                s.start_stream(Stream::Camera);
                let x1 = s.next_1d() as f64;
                let d = torus(x0, x1);
                if n == 1 {
                    assert!(d <= s2 + 1e-6 && d >= s1 - 1e-6, "step {d}");
                }
                sum += d * d;
                sum_sq += d.powi(4);
            }
            let mean = sum / trials as f64;
            let var = sum_sq / trials as f64 - mean * mean;
            let expected = n as f64 * second_moment;
            let sigma = (var / trials as f64).sqrt();
            assert!(
                (mean - expected).abs() < 4.0 * sigma,
                "n {n}: mean squared step {mean:e}, expected {expected:e} ± {sigma:e}"
            );
        }
    }

    /// A coordinate skipped past an accepted large step is redrawn; streams are apart.
    #[test]
    fn large_steps_and_streams() {
        let mut s = PrimarySampleSampler::new(&[3], 1.0, KELEMEN);
        let first = read(&mut s, 3);
        s.start_chain(&[4]);
        s.start_iteration();
        assert!(s.is_large_step());
        // Read the light stream only: the camera stream is left behind.
        s.start_stream(Stream::Light);
        let light: Vec<f32> = (0..3).map(|_| s.next_1d()).collect();
        assert_ne!(light, first[3..6]);
        s.accept();
        s.start_iteration();
        let next = read(&mut s, 3);
        assert_ne!(next[..3], first[..3]);
        assert_eq!(s.dimensions(), [3, 3, 3]);
    }

    #[test]
    fn values_stay_in_the_unit_interval() {
        for mutation in [KELEMEN, Mutation::Gaussian { sigma: 0.3 }] {
            let mut s = PrimarySampleSampler::new(&[5], 0.1, mutation);
            read(&mut s, 4);
            s.start_chain(&[6]);
            for _ in 0..2000 {
                s.start_iteration();
                for v in read(&mut s, 4) {
                    assert!((0.0..1.0).contains(&v));
                }
                if s.uniform() < 0.5 {
                    s.accept()
                } else {
                    s.reject()
                }
            }
        }
        assert!(SmallStep::new(KELEMEN).uniform_after > 10_000);
    }
}
