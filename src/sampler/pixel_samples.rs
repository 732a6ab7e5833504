//! Where a camera sample falls inside its pixel and on the lens: independent uniform points,
//! or the points of a 2D pattern (`sampler::pattern`), so that the pixel (and aperture)
//! integral is estimated with stratified, blue-noise or low-discrepancy points
//! (`--set sampler=NAME`).
//!
//! `CameraSampler` is the `Sampler` camera estimators draw from. In each pixel sample its
//! first 2D sample is the position in the pixel; for a camera with a lens (thin lens) its
//! second 2D sample is the lens sample. Both come from the pattern; every other number comes
//! from the independent stream. A pinhole camera draws no lens sample, and then the second
//! 2D sample is simply the independent stream's, exactly as before lenses existed.
//!
//! Pixel positions: a pattern of M points is generated once and shared by all pixels; each
//! pixel applies its own random toroidal shift (a Cranley–Patterson rotation, Cranley &
//! Patterson 1976) and starts at its own random index, so pixels are independent of each
//! other while the samples within a pixel keep the pattern's structure. Sample number i of a
//! pixel is point (start + i) mod M: the first M samples of a pixel are exactly the
//! (shifted) pattern, which is why M should equal the samples per pixel the render will take.
//!
//! Lens samples: the M lens samples of a pixel again form the pattern, but paired with the
//! pixel positions at random, so that pixel and lens strata are decorrelated (Shirley's and
//! pbrt's "padding" of independently permuted 2D patterns; Kollig & Keller 2002 for the
//! padding of low-discrepancy sets). Per pattern:
//!
//! * `stratified`: sample i falls in lens stratum π(i mod M) of the k×k grid (k² ≤ M),
//!   jittered uniformly inside it, with π a random permutation of the pixel. Every pixel has
//!   exactly one lens sample per stratum among its first k² samples (no toroidal shift, which
//!   would move points across strata); samples whose π(i) ≥ k² are uniform.
//! * `regular`, `poisson`, `ccvt`: point π(i mod M) of the shared pattern under a second,
//!   independent per-pixel toroidal shift. Shifting keeps the grid and the toroidal minimum
//!   distances of the pattern.
//! * `sobol`: dimensions 2 and 3 of the Sobol' point whose dimensions 0 and 1 place the
//!   sample in its pixel (the same index), Owen-scrambled per pixel: pixel and lens samples
//!   are one 4D Sobol' point, jointly stratified (see `sobol`).
//!
//! π and the Sobol' scramble are drawn afresh for every block of M samples of a pixel, so
//! sample i + M does not repeat sample i's pair of pixel and lens positions. Every lens
//! sample is uniform over [0, 1)² (over the random shift, permutation, jitter or scramble).

use std::sync::Arc;

use glam::Vec2;

use super::Sampler;
use super::independent::{IndependentSampler, hash_words, mix64};
use super::pattern::{Pattern, cell_coordinate, grid_side, points};
use super::permutation::permute;
use super::sobol::{owen_scramble, sobol_dims_2_3, to_unit};

/// Tag that keeps the per-pixel shift independent of every other stream of the seed.
const SHIFT_TAG: u64 = 0x5417_F7ED;
/// Tags of the lens samples' streams: the shift, the permutation, the stratified jitter
/// and the Sobol' scramble.
const LENS_SHIFT_TAG: u64 = 0x1E25_5A1F;
const LENS_PERMUTATION_TAG: u64 = 0x1E25_9E12;
const LENS_JITTER_TAG: u64 = 0x1E25_717E;
const LENS_SCRAMBLE_TAG: u64 = 0x1E25_5C2A;

/// The pixel-offset strategy of a camera estimator.
#[derive(Clone, Debug, PartialEq)]
pub enum PixelSamples {
    /// Offsets drawn from the sample's own random stream.
    Independent,
    /// Offsets from a shared pattern, rotated per pixel.
    Pattern { pattern: Pattern, points: Vec<Vec2> },
}

/// The top 24 bits of `bits` as a float in [0, 1).
fn unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 / (1u64 << 24) as f32
}

/// The top 53 bits of `bits` as a float in [0, 1).
fn unit_f64(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// Wraps onto [0, 1): fract can round up to 1.0 for tiny negative or near-1 values.
fn wrap(v: f32) -> f32 {
    let f = v.fract();
    if f >= 1.0 { 0.0 } else { f }
}

/// A toroidal shift in [0, 1)² from one hash.
fn shift_of(h: u64) -> Vec2 {
    Vec2::new(unit_f32(h), unit_f32(h.rotate_left(24)))
}

impl PixelSamples {
    /// `independent`, or `size` points of `pattern` (at least one).
    pub fn new(pattern: Pattern, size: usize, seed: u64) -> PixelSamples {
        if pattern == Pattern::Independent {
            return PixelSamples::Independent;
        }
        let mut pts = points(pattern, size.max(1), seed);
        if pts.is_empty() {
            pts.push(Vec2::splat(0.5));
        }
        PixelSamples::Pattern {
            pattern,
            points: pts,
        }
    }

    /// The per-pixel hash that gives the pixel positions' shift and start index.
    fn pixel_hash(seed: u64, pixel: (u32, u32)) -> u64 {
        hash_words(&[seed, SHIFT_TAG, pixel.0 as u64, pixel.1 as u64])
    }

    /// The index into the pattern of sample `index` of the pixel with hash `h`.
    fn pattern_index(h: u64, index: u64, len: usize) -> usize {
        let start = h.rotate_left(48) % len as u64;
        ((start + index) % len as u64) as usize
    }

    /// The offset in [0, 1)² of sample `index` of pixel `pixel`, or None for independent
    /// offsets (the caller draws them from its sampler).
    pub fn offset(&self, seed: u64, pixel: (u32, u32), index: u64) -> Option<Vec2> {
        let PixelSamples::Pattern { points, .. } = self else {
            return None;
        };
        let h = Self::pixel_hash(seed, pixel);
        let p = points[Self::pattern_index(h, index, points.len())] + shift_of(h);
        Some(Vec2::new(wrap(p.x), wrap(p.y)))
    }

    /// The lens sample in [0, 1)² of sample `index` of pixel `pixel` (see the module
    /// documentation), or None for independent ones (the caller draws them).
    pub fn lens(&self, seed: u64, pixel: (u32, u32), index: u64) -> Option<Vec2> {
        let PixelSamples::Pattern { pattern, points } = self else {
            return None;
        };
        let n = points.len();
        let (px, py) = (pixel.0 as u64, pixel.1 as u64);
        // Which block of n samples this is, and the sample's place in it.
        let (block, slot) = (index / n as u64, (index % n as u64) as u32);
        if *pattern == Pattern::Sobol {
            let j = Self::pattern_index(Self::pixel_hash(seed, pixel), index, n);
            let [x, y] = sobol_dims_2_3(j as u32);
            let scramble = |dim: u64| hash_words(&[seed, LENS_SCRAMBLE_TAG, px, py, block, dim]);
            return Some(Vec2::new(
                to_unit(owen_scramble(x, scramble(2))),
                to_unit(owen_scramble(y, scramble(3))),
            ));
        }
        let key = hash_words(&[seed, LENS_PERMUTATION_TAG, px, py, block]);
        let slot = permute(slot, n as u32, key) as usize;
        if *pattern == Pattern::Stratified {
            let jitter = hash_words(&[seed, LENS_JITTER_TAG, px, py, index]);
            let k = grid_side(n);
            return Some(if slot < k * k {
                Vec2::new(
                    cell_coordinate(slot % k, k, unit_f64(jitter)),
                    cell_coordinate(slot / k, k, unit_f64(mix64(jitter))),
                )
            } else {
                shift_of(jitter)
            });
        }
        let shift = shift_of(hash_words(&[seed, LENS_SHIFT_TAG, px, py]));
        let p = points[slot] + shift;
        Some(Vec2::new(wrap(p.x), wrap(p.y)))
    }
}

/// The sampler of camera estimators: an `IndependentSampler` whose first 2D sample in each
/// pixel sample is the pixel position from `PixelSamples`, and, when lens samples are on
/// (`with_lens_samples`), whose second 2D sample is the lens sample.
pub struct CameraSampler {
    rng: IndependentSampler,
    seed: u64,
    pixel_samples: Arc<PixelSamples>,
    /// 2D samples that belong to the camera: 1 (pixel) or 2 (pixel and lens).
    camera_dimensions: usize,
    /// How many of them the current pixel sample has handed out.
    handed_out: usize,
    /// The pattern's pixel and lens positions for the current pixel sample (None: draw
    /// from the independent stream).
    pending: [Option<Vec2>; 2],
}

impl CameraSampler {
    pub fn new(seed: u64, pixel_samples: Arc<PixelSamples>) -> CameraSampler {
        CameraSampler {
            rng: IndependentSampler::new(seed),
            seed,
            pixel_samples,
            camera_dimensions: 1,
            handed_out: 0,
            pending: [None, None],
        }
    }

    /// Makes the second 2D sample of every pixel sample the lens sample (for a camera with
    /// a lens; a pinhole must leave this off, so that it draws nothing for a lens).
    pub fn with_lens_samples(mut self, on: bool) -> CameraSampler {
        self.camera_dimensions = if on { 2 } else { 1 };
        self
    }

    /// The state of the independent stream that every draw after the camera's comes from
    /// (`IndependentSampler::state`): once the pixel (and lens) samples are handed out, a
    /// `LaneStreams` lane or an `IndependentSampler::with_state` seeded with it continues
    /// this sampler exactly.
    pub fn stream_state(&self) -> [u64; 4] {
        self.rng.state()
    }

    /// Starts sample `sample_index` of pixel `pixel` (see `IndependentSampler`): the pixel
    /// and lens positions of the pattern are the first 2D draws that follow.
    pub fn start_pixel_sample(&mut self, pixel: (u32, u32), sample_index: u64) {
        self.rng.start_pixel_sample(pixel, sample_index);
        self.handed_out = 0;
        self.pending[0] = self.pixel_samples.offset(self.seed, pixel, sample_index);
        self.pending[1] = if self.camera_dimensions > 1 {
            self.pixel_samples.lens(self.seed, pixel, sample_index)
        } else {
            None
        };
    }
}

impl Sampler for CameraSampler {
    fn next_1d(&mut self) -> f32 {
        self.rng.next_1d()
    }

    fn next_2d(&mut self) -> Vec2 {
        if self.handed_out < self.camera_dimensions {
            let slot = self.handed_out;
            self.handed_out += 1;
            if let Some(p) = self.pending[slot].take() {
                return p;
            }
        }
        self.rng.next_2d()
    }
}
