//! Where a camera sample falls inside its pixel: independent uniform offsets, or the points
//! of a 2D pattern (`sampler::pattern`), so that the pixel integral is estimated with
//! stratified, blue-noise or low-discrepancy points (`--set sampler=NAME`).
//!
//! `CameraSampler` is the `Sampler` camera estimators draw from: the first 2D sample of each
//! pixel sample (the position in the pixel) comes from the pattern, every other number from
//! the independent stream.
//!
//! A pattern of M points is generated once and shared by all pixels; each pixel applies its
//! own random toroidal shift (a Cranley–Patterson rotation, Cranley & Patterson 1976) and
//! starts at its own random index, so pixels are independent of each other while the
//! samples within a pixel keep the pattern's structure. Sample number i of a pixel is point
//! (start + i) mod M: the first M samples of a pixel are exactly the (shifted) pattern, which
//! is why M should equal the samples per pixel the render will take.

use std::sync::Arc;

use glam::Vec2;

use super::Sampler;
use super::independent::{IndependentSampler, hash_words};
use super::pattern::{Pattern, points};

/// Tag that keeps the per-pixel shift independent of every other stream of the seed.
const SHIFT_TAG: u64 = 0x5417_F7ED;

/// The pixel-offset strategy of a camera estimator.
#[derive(Clone, Debug, PartialEq)]
pub enum PixelSamples {
    /// Offsets drawn from the sample's own random stream.
    Independent,
    /// Offsets from a shared pattern, rotated per pixel.
    Pattern { pattern: Pattern, points: Vec<Vec2> },
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

    /// The offset in [0, 1)² of sample `index` of pixel `pixel`, or None for independent
    /// offsets (the caller draws them from its sampler).
    pub fn offset(&self, seed: u64, pixel: (u32, u32), index: u64) -> Option<Vec2> {
        let PixelSamples::Pattern { points, .. } = self else {
            return None;
        };
        let h = hash_words(&[seed, SHIFT_TAG, pixel.0 as u64, pixel.1 as u64]);
        let to_unit = |bits: u64| (bits >> 40) as f32 / (1u64 << 24) as f32;
        let shift = Vec2::new(to_unit(h), to_unit(h.rotate_left(24)));
        let start = h.rotate_left(48) % points.len() as u64;
        let p = points[((start + index) % points.len() as u64) as usize] + shift;
        // Wrap into [0, 1): fract can round up to 1.0 for tiny negative or near-1 values.
        let wrap = |v: f32| {
            let f = v.fract();
            if f >= 1.0 { 0.0 } else { f }
        };
        Some(Vec2::new(wrap(p.x), wrap(p.y)))
    }
}

/// The sampler of camera estimators: an `IndependentSampler` whose first 2D sample in each
/// pixel sample is the pixel position from `PixelSamples`.
pub struct CameraSampler {
    rng: IndependentSampler,
    seed: u64,
    pixel_samples: Arc<PixelSamples>,
    /// The pattern's position for the current pixel sample, until `next_2d` hands it out.
    pending: Option<Vec2>,
}

impl CameraSampler {
    pub fn new(seed: u64, pixel_samples: Arc<PixelSamples>) -> CameraSampler {
        CameraSampler {
            rng: IndependentSampler::new(seed),
            seed,
            pixel_samples,
            pending: None,
        }
    }
}

impl Sampler for CameraSampler {
    fn start_pixel_sample(&mut self, pixel: (u32, u32), sample_index: u64) {
        self.rng.start_pixel_sample(pixel, sample_index);
        self.pending = self.pixel_samples.offset(self.seed, pixel, sample_index);
    }

    fn next_1d(&mut self) -> f32 {
        self.rng.next_1d()
    }

    fn next_2d(&mut self) -> Vec2 {
        self.pending.take().unwrap_or_else(|| self.rng.next_2d())
    }
}
