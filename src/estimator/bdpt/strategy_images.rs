//! The strategy images (`--set strategies=true`): what each strategy (s, t) of `bdpt`
//! contributes, weighted (its share of the image: the weighted images of all strategies sum
//! to `bdpt`'s image) and unweighted (its own estimate of all light of path length
//! s + t − 1, which it alone would give, as far as it can sample those paths). Researchers
//! read them as the pyramid of Veach 1997, fig. 10.4: which strategy carries which light.
//!
//! A strategy's contribution to the camera sample's own pixel goes through the
//! reconstruction filter like the sample (without its weight: the pixel divides by the
//! weights of the `bdpt` film, which took the whole samples); t = 1 contributions are
//! splats, as in `bdpt`. Tiles record their contributions in sample order and are merged in
//! tile order: the images are bit-identical for any thread count.

use glam::Vec2;

use super::StrategyEvent;
use crate::error::Result;
use crate::film::Film;
use crate::image::Image;
use crate::math::Rgb;
use crate::scene::FilterDesc;

/// One strategy's images.
pub struct StrategyImage {
    pub s: usize,
    pub t: usize,
    /// Its contribution multiplied by its MIS weight.
    pub weighted: Image,
    /// Its contribution alone.
    pub unweighted: Image,
}

/// The films of every strategy (s, t) with path length 1 ≤ s + t − 1 ≤ `max_depth` and
/// t ≥ 1: (L + 1) strategies of each length L.
pub struct StrategyImages {
    max_depth: u32,
    /// Weighted and unweighted film of each strategy, in `index` order.
    films: Vec<(Film, Film)>,
}

/// Strategy index, raster position, weighted and unweighted value.
type Record = (u32, Vec2, Rgb, Rgb);

/// One tile's contributions to the strategy images, in the order they were made.
#[derive(Default)]
pub struct TileRecords {
    pixel: Vec<Record>,
    splats: Vec<Record>,
    /// Where the current camera sample's pixel records start.
    sample_start: usize,
}

impl StrategyImages {
    pub fn new(width: u32, height: u32, filter: FilterDesc, max_depth: u32) -> Result<Self> {
        // Σ_{L=1}^{D} (L + 1) = D (D + 3) / 2.
        let d = max_depth as usize;
        let count = d * (d + 3) / 2;
        let films = (0..count)
            .map(|_| {
                Ok((
                    Film::new(width, height, filter)?,
                    Film::new(width, height, filter)?,
                ))
            })
            .collect::<Result<_>>()?;
        Ok(StrategyImages { max_depth, films })
    }

    /// The position of (s, t) in `films`: lengths in order, s in order within a length.
    fn index_of(s: usize, t: usize) -> usize {
        let length = s + t - 1;
        // Σ_{l=1}^{L−1} (l + 1) strategies come before length L.
        (length - 1) * (length + 2) / 2 + s
    }

    /// The index of (s, t), if its path length has images.
    fn index(&self, s: usize, t: usize) -> Option<usize> {
        let length = s + t - 1;
        (t >= 1 && length >= 1 && length <= self.max_depth as usize).then(|| Self::index_of(s, t))
    }

    /// Adds a tile's records, pixel values first, then splats, each in recorded order.
    pub fn merge(&mut self, records: &TileRecords) {
        for &(i, raster, weighted, unweighted) in &records.pixel {
            let (w, u) = &mut self.films[i as usize];
            w.add_value(raster, weighted);
            u.add_value(raster, unweighted);
        }
        for &(i, raster, weighted, unweighted) in &records.splats {
            let (w, u) = &mut self.films[i as usize];
            w.splat(raster, weighted);
            u.splat(raster, unweighted);
        }
    }

    /// Every strategy's images, normalised as `bdpt`'s own image: pixel values by the
    /// weights of `samples` (the `bdpt` film), splats by the `light_paths` traced.
    pub fn images(&self, samples: &Film, light_paths: u64) -> Vec<StrategyImage> {
        let scale = if light_paths == 0 {
            0.0
        } else {
            samples.width() as f64 * samples.height() as f64 / light_paths as f64
        };
        let mut out = Vec::with_capacity(self.films.len());
        for length in 1..=self.max_depth as usize {
            for s in 0..=length {
                let t = length + 1 - s;
                let (w, u) = &self.films[Self::index_of(s, t)];
                out.push(StrategyImage {
                    s,
                    t,
                    weighted: w.image_normalized_by(samples, scale),
                    unweighted: u.image_normalized_by(samples, scale),
                });
            }
        }
        out
    }
}

impl TileRecords {
    /// Marks the start of a camera sample.
    pub fn start_sample(&mut self) {
        self.sample_start = self.pixel.len();
    }

    /// Records what strategy event `e` of the camera sample at `raster` contributes.
    pub fn record(&mut self, images: &StrategyImages, e: &StrategyEvent, raster: Vec2) {
        let Some(i) = images.index(e.s, e.t) else {
            return;
        };
        let entry = |at: Vec2| (i as u32, at, e.value * e.weight, e.value);
        match e.raster {
            Some(at) => self.splats.push(entry(at)),
            None => self.pixel.push(entry(raster)),
        }
    }

    /// Ends the camera sample: its pixel records are dropped when the sample was (its
    /// value was not finite, and `bdpt`'s film dropped it).
    pub fn end_sample(&mut self, kept: bool) {
        if !kept {
            self.pixel.truncate(self.sample_start);
        }
    }
}
