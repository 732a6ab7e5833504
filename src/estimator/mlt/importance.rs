//! What the chains' target density is proportional to (`importance=`).
//!
//! * `luminance` (the default; Kelemen et al. 2002): the luminance of a state's
//!   contributions. A chain then spends its mutations on each pixel in proportion to the
//!   pixel's brightness, so a bright pixel's relative error is small and a dim pixel's large.
//! * `relative`: each contribution's luminance divided by a pilot estimate of its pixel's
//!   brightness, summed (an importance function of the kind Hoberock and Hart 2010,
//!   "Arbitrary importance functions for Metropolis light transport", propose). Mutations
//!   then spread about evenly over the pixels, which is what a per-pixel relative error
//!   (relMSE) rewards: a bright strip no longer draws the chains away from the dim room
//!   around it.
//!
//! Either way the estimator is unbiased: expected-value splatting divides each
//! contribution by the importance of its state, and the importance is positive wherever a
//! contribution is (the pilot is floored at `FLOOR` of its mean). A poor pilot costs
//! variance, never bias.
//!
//! The pilot is `bootstrap` independent samples of the base estimator of its own (the
//! estimator draws them before the bootstrap, `Metropolis::make_pilot`): their
//! contributions, binned into blocks of pixels (about `SAMPLES_PER_BLOCK` samples each)
//! and smoothed over the neighbouring blocks, estimate each block's mean pixel luminance.
//! It must not reuse the bootstrap's samples: b is their mean importance, and the blocks
//! where they found no light are floored, so have the largest importance, which those
//! samples by construction never show: b would come out too small.

use glam::Vec2;

use super::target::Contributions;

/// The pilot's floor, as a fraction of its mean over the film: a block the bootstrap found
/// dark still counts as this bright, so the chains neither ignore it nor, where the pilot
/// only missed its light, stick there.
const FLOOR: f64 = 0.05;

/// About this many bootstrap samples per block of the pilot.
const SAMPLES_PER_BLOCK: f64 = 64.0;

/// `importance=luminance|relative`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImportanceKind {
    Luminance,
    Relative,
}

impl ImportanceKind {
    pub fn name(self) -> &'static str {
        match self {
            ImportanceKind::Luminance => "luminance",
            ImportanceKind::Relative => "relative",
        }
    }
}

/// A coarse estimate of each pixel's luminance: blocks of `block` × `block` pixels.
#[derive(Clone, Debug)]
pub struct PilotMap {
    width: u32,
    height: u32,
    block: u32,
    columns: u32,
    /// Per block (row-major), the smoothed, floored mean pixel luminance; every entry > 0.
    values: Vec<f64>,
}

impl PilotMap {
    /// The map of a `width` × `height` film from `samples` bootstrap samples whose
    /// contributions are `entries` (raster position, luminance), each already divided by
    /// its sample's density; `per_stratum` samples per stratum, so that the image's
    /// estimate is Σ entries / `per_stratum` (the strata's images add up).
    pub fn new(
        width: u32,
        height: u32,
        samples: u64,
        per_stratum: u64,
        entries: impl Iterator<Item = (Vec2, f64)>,
    ) -> PilotMap {
        let pixels = width as f64 * height as f64;
        let blocks_wanted = (samples as f64 / SAMPLES_PER_BLOCK).max(1.0);
        let block = ((pixels / blocks_wanted).sqrt().ceil() as u32).clamp(1, width.max(height));
        let columns = width.div_ceil(block);
        let rows = height.div_ceil(block);
        let mut map = PilotMap {
            width,
            height,
            block,
            columns,
            values: vec![0.0; (columns * rows) as usize],
        };
        let mut sums = vec![0.0f64; map.values.len()];
        for (raster, luminance) in entries {
            if luminance.is_finite() && luminance > 0.0 {
                sums[map.block_of(raster)] += luminance;
            }
        }
        // Mean pixel luminance per block: the image's sum over the block's pixels.
        let mean_per_block: Vec<f64> = (0..rows)
            .flat_map(|r| (0..columns).map(move |c| (c, r)))
            .map(|(c, r)| {
                let w = (width - c * block).min(block) as f64;
                let h = (height - r * block).min(block) as f64;
                sums[(r * columns + c) as usize] / per_stratum.max(1) as f64 / (w * h)
            })
            .collect();
        // Smoothed over the 3 × 3 blocks around each (those inside the film).
        for r in 0..rows {
            for c in 0..columns {
                let (mut sum, mut count) = (0.0, 0.0);
                for rr in r.saturating_sub(1)..(r + 2).min(rows) {
                    for cc in c.saturating_sub(1)..(c + 2).min(columns) {
                        sum += mean_per_block[(rr * columns + cc) as usize];
                        count += 1.0;
                    }
                }
                map.values[(r * columns + c) as usize] = sum / count;
            }
        }
        let mean = map.values.iter().sum::<f64>() / map.values.len() as f64;
        // A black pilot leaves every block alike (the plain luminance target).
        let floor = if mean > 0.0 && mean.is_finite() {
            FLOOR * mean
        } else {
            1.0
        };
        for v in &mut map.values {
            *v = if v.is_finite() { v.max(floor) } else { floor };
        }
        map
    }

    /// Side of a block in pixels.
    pub fn block_size(&self) -> u32 {
        self.block
    }

    /// The block holding raster position `raster` (clamped to the film).
    fn block_of(&self, raster: Vec2) -> usize {
        let pixel = |v: f32, n: u32| (v.max(0.0) as u32).min(n - 1);
        let (x, y) = (pixel(raster.x, self.width), pixel(raster.y, self.height));
        ((y / self.block) * self.columns + x / self.block) as usize
    }

    /// The pilot's estimate of the pixel at `raster` (> 0).
    pub fn at(&self, raster: Vec2) -> f64 {
        self.values[self.block_of(raster)]
    }

    /// Σ luminance / pilot over `state`'s contributions: its importance under
    /// `importance=relative`.
    pub fn importance(&self, state: &Contributions) -> f64 {
        state
            .entries
            .iter()
            .map(|&(raster, value)| value.luminance() as f64 / self.at(raster))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;

    #[test]
    fn blocks_hold_the_mean_pixel_luminance_smoothed_and_floored() {
        // 8 × 4 film, 2 samples per block wanted: 64 samples → 32 blocks of 1 pixel.
        // Left half lit at luminance 2 per pixel, right half black.
        let (w, h) = (8u32, 4u32);
        let n = 64u64;
        let entries = (0..h).flat_map(|y| {
            (0..w / 2).map(move |x| (Vec2::new(x as f32 + 0.5, y as f32 + 0.5), 2.0 * n as f64))
        });
        let map = PilotMap::new(w, h, 64 * 32, n, entries);
        assert_eq!(map.block_size(), 1);
        // Deep in the lit half: all 3 × 3 neighbours lit.
        assert!((map.at(Vec2::new(1.5, 1.5)) - 2.0).abs() < 1e-12);
        // On the edge of the lit half: 2 of 3 columns lit.
        assert!((map.at(Vec2::new(3.5, 1.5)) - 4.0 / 3.0).abs() < 1e-12);
        // Deep in the black half: the floor, 5% of the smoothed blocks' mean (below 2).
        let far = map.at(Vec2::new(7.5, 1.5));
        assert!(far > 0.0 && far < 0.1, "{far}");
        // Rasters on or past the film's edge fall in its border blocks.
        assert_eq!(map.at(Vec2::new(8.0, 4.0)), far);
        assert_eq!(map.at(Vec2::new(-1.0, 0.0)), map.at(Vec2::new(0.5, 0.5)));
        // A state's importance divides each contribution by its own pixel's pilot.
        let state = Contributions {
            entries: vec![
                (Vec2::new(1.5, 1.5), Rgb::new(1.0, 1.0, 1.0)),
                (Vec2::new(7.5, 1.5), Rgb::new(1.0, 1.0, 1.0)),
            ],
            luminance: 2.0,
        };
        let expected = 1.0 / 2.0 + 1.0 / far;
        assert!((map.importance(&state) - expected).abs() < 1e-9 * expected);
    }

    #[test]
    fn a_black_pilot_is_uniform_and_blocks_grow_with_few_samples() {
        let map = PilotMap::new(100, 60, 100, 100, std::iter::empty());
        // 100 samples, 64 per block: about 1.6 blocks, so blocks of ceil(√(6000/1.5625)) = 62 px.
        assert_eq!(map.block_size(), 62);
        assert!(map.values.iter().all(|&v| v == 1.0));
    }
}
