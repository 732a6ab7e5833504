//! Independent uniform samples from Xoshiro256++.

use glam::Vec2;
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

use super::Sampler;

/// SplitMix64's finaliser (Steele et al. 2014): a bijective 64-bit mix, used to turn
/// (seed, pixel, sample) into well-separated generator seeds.
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Hashes a list of words into one seed; order matters.
pub fn hash_words(words: &[u64]) -> u64 {
    words.iter().fold(HASH_START, |h, &w| mix64(h ^ mix64(w)))
}

/// Where `hash_words` starts (the first 64 bits of the fractional part of √2).
pub(crate) const HASH_START: u64 = 0x6A09_E667_F3BC_C909;

/// Uniform random samples, seeded from (seed, pixel, sample index).
pub struct IndependentSampler {
    seed: u64,
    rng: Xoshiro256PlusPlus,
}

impl IndependentSampler {
    pub fn new(seed: u64) -> Self {
        IndependentSampler {
            seed,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
        }
    }

    /// Re-seeds the stream from any list of words (used for non-pixel streams such as
    /// light paths, keyed by pass and piece).
    pub fn start_keyed(&mut self, key: &[u64]) {
        let mut words = Vec::with_capacity(key.len() + 1);
        words.push(self.seed);
        words.extend_from_slice(key);
        self.rng = Xoshiro256PlusPlus::seed_from_u64(hash_words(&words));
    }

    pub fn next_u64(&mut self) -> u64 {
        self.rng.next_u64()
    }

    /// The generator's state (four words), to continue the same stream elsewhere: in a lane
    /// of `LaneStreams`, or through `with_state`.
    pub fn state(&self) -> [u64; 4] {
        let bytes = self.rng.state();
        std::array::from_fn(|k| u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap()))
    }

    /// A sampler that continues the stream whose state is `state` (from `state`).
    pub fn with_state(seed: u64, state: [u64; 4]) -> IndependentSampler {
        let mut bytes = [0u8; 32];
        for (k, w) in state.iter().enumerate() {
            bytes[8 * k..8 * k + 8].copy_from_slice(&w.to_le_bytes());
        }
        IndependentSampler {
            seed,
            rng: Xoshiro256PlusPlus::from_seed(bytes),
        }
    }
}

/// The top 24 bits of a 64-bit draw as a float in [0, 1): exactly representable, never 1.
pub(crate) fn to_unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

impl IndependentSampler {
    /// Starts the sample with index `sample_index` of pixel `pixel`: what follows depends
    /// only on (seed, pixel, sample_index), never on the thread that runs it.
    pub fn start_pixel_sample(&mut self, pixel: (u32, u32), sample_index: u64) {
        let key = hash_words(&[self.seed, pixel.0 as u64, pixel.1 as u64, sample_index]);
        self.rng = Xoshiro256PlusPlus::seed_from_u64(key);
    }

    /// Starts light path `path` of pass `pass`, its streams kept apart from every pixel
    /// sample and from other light-path estimators' by `tag` (whose low 16 bits are 0):
    /// the pixel-sample key with the path index in place of the pixel.
    pub fn start_light_path(&mut self, path: u64, tag: u32, pass: u64) {
        let key = ((path & 0xFFFF_FFFF) as u32, tag | (path >> 32) as u32);
        self.start_pixel_sample(key, pass);
    }
}

impl Sampler for IndependentSampler {
    fn next_1d(&mut self) -> f32 {
        to_unit_f32(self.rng.next_u64())
    }

    fn next_2d(&mut self) -> Vec2 {
        // One draw for both coordinates would correlate them; take two.
        let x = self.next_1d();
        let y = self.next_1d();
        Vec2::new(x, y)
    }
}
