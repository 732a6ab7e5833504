//! Accumulating samples into pixels: filtered per-pixel sums, a splat buffer for light
//! tracing, and a merge order that does not depend on the thread count.
//!
//! Camera samples follow Mitsuba 3's `hdrfilm`: a sample at continuous raster position
//! (x, y) adds w(i + ½ − x) · w(j + ½ − y) · L and the same weight to every pixel (i, j)
//! whose centre lies within the filter radius; the developed pixel is Σ w L / Σ w (0 where
//! nothing landed). Contributions to pixels outside the image are dropped (Mitsuba's film
//! storage has no border), which the per-pixel normalisation absorbs. The box filter adds
//! a sample to the pixel floor(x, y) only, with weight 1.
//!
//! The Gaussian filter is w(t) = max(0, exp(−t² / 2σ²) − exp(−r² / 2σ²)) with radius
//! r = 4σ: a Gaussian shifted down so it reaches 0 at the radius. Mitsuba 3 evaluates this
//! function approximately: its scalar variants with a 31-entry step table (weights off by
//! up to 0.023, peak 1, measured with Mitsuba 3.9.1), its JIT variants with a polynomial
//! fit (off by up to 4·10⁻⁴). mltbench evaluates it exactly, in f64.
//!
//! Splats (light tracing) are unnormalised sums: a splat at (x, y) adds
//! w(i + ½ − x) · w(j + ½ − y) · value / Z(i, j) to pixel (i, j), where Z(i, j) is the
//! filter's mass over the image, ∫∫_image w(i + ½ − x) w(j + ½ − y) dx dy (1 for the box).
//! Then a splat density I(x) gives the pixel value ∫ w I / ∫ w: exactly what camera
//! samples converge to, also at the image border, so light tracing, BDPT and path tracing
//! estimate the same pixel measurement with either filter. (Mitsuba's `ptracer` divides
//! by the filter's sum over all taps instead, so with the Gaussian its border pixels lose
//! the weight that falls outside the image: 22 % of a splat at raster (0.5, 0.5). With the
//! box filter both agree.)
//!
//! Determinism: all sums are f64 and a `Film` only changes through `merge_tile`,
//! `merge_splats` and `splat`, so the same tiles and splat lists merged in the same order
//! give bit-identical images whatever thread rendered them.

use std::sync::Mutex;

use rayon::prelude::*;

use glam::Vec2;

use crate::error::{Error, Result};
use crate::image::Image;
use crate::math::Rgb;
use crate::scene::FilterDesc;

/// A rectangle of pixels [x0, x1) × [y0, y1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    pub fn pixel_count(&self) -> usize {
        self.width() as usize * self.height() as usize
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }
}

/// A separable pixel reconstruction filter, as in Mitsuba 3's `rfilter` plugins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReconstructionFilter {
    /// A sample adds to the pixel it falls in, with weight 1.
    Box,
    /// exp(−t²/2σ²) − exp(−r²/2σ²) for |t| < r = 4σ, else 0.
    Gaussian {
        stddev: f64,
        radius: f64,
        /// 1 / (2σ²).
        alpha: f64,
        /// exp(−r²/2σ²): the value subtracted so the filter reaches 0 at the radius.
        bias: f64,
    },
}

impl ReconstructionFilter {
    /// The filter of `<rfilter>`. A Gaussian whose stddev is not a positive finite number
    /// (which the scene loader should have rejected) falls back to the box.
    pub fn new(desc: FilterDesc) -> Self {
        match desc {
            FilterDesc::Box => ReconstructionFilter::Box,
            FilterDesc::Gaussian { stddev } => {
                let stddev = stddev as f64;
                if !(stddev > 0.0 && stddev.is_finite()) {
                    return ReconstructionFilter::Box;
                }
                let radius = 4.0 * stddev;
                let alpha = 1.0 / (2.0 * stddev * stddev);
                ReconstructionFilter::Gaussian {
                    stddev,
                    radius,
                    alpha,
                    bias: (-alpha * radius * radius).exp(),
                }
            }
        }
    }

    /// Half the filter's support in pixels (0.5 for the box).
    pub fn radius(&self) -> f64 {
        match *self {
            ReconstructionFilter::Box => 0.5,
            ReconstructionFilter::Gaussian { radius, .. } => radius,
        }
    }

    /// The 1D filter at offset `t` (pixels) from a pixel centre.
    pub fn eval(&self, t: f64) -> f64 {
        match *self {
            ReconstructionFilter::Box => {
                if t.abs() <= 0.5 {
                    1.0
                } else {
                    0.0
                }
            }
            ReconstructionFilter::Gaussian {
                radius,
                alpha,
                bias,
                ..
            } => {
                if t.abs() < radius {
                    ((-alpha * t * t).exp() - bias).max(0.0)
                } else {
                    0.0
                }
            }
        }
    }

    /// ∫_a^b of the 1D filter (closed form through erf).
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        let r = self.radius();
        let (a, b) = (a.clamp(-r, r), b.clamp(-r, r));
        if b <= a {
            return 0.0;
        }
        match *self {
            ReconstructionFilter::Box => b - a,
            ReconstructionFilter::Gaussian { alpha, bias, .. } => {
                use statrs::function::erf::erf;
                // ∫ exp(−α t²) dt = √π / (2√α) · erf(√α t)
                let s = alpha.sqrt();
                let gauss = std::f64::consts::PI.sqrt() / (2.0 * s) * (erf(s * b) - erf(s * a));
                gauss - bias * (b - a)
            }
        }
    }

    /// An offset t ∈ [a, b] (pixels from a pixel centre) drawn from `u` with density
    /// ∝ the filter over that interval (which should overlap the support): uniform for the
    /// box, by bisection on `integral` for the Gaussian. Sampling a pixel's positions so
    /// makes each sample's plain mean the filtered pixel value (photon mapping's eye pass).
    pub fn sample_offset(&self, u: f64, a: f64, b: f64) -> f64 {
        let r = self.radius();
        let (a, b) = (a.max(-r), b.min(r));
        if b <= a {
            return a.clamp(-r, r);
        }
        match *self {
            ReconstructionFilter::Box => a + u * (b - a),
            ReconstructionFilter::Gaussian { .. } => {
                let target = u * self.integral(a, b);
                let (mut lo, mut hi) = (a, b);
                for _ in 0..48 {
                    let mid = 0.5 * (lo + hi);
                    if self.integral(a, mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            }
        }
    }

    /// How many pixels beyond a tile's rectangle a sample inside it (edges included) can
    /// reach.
    fn margin(&self) -> u32 {
        match *self {
            ReconstructionFilter::Box => 1,
            ReconstructionFilter::Gaussian { radius, .. } => (radius + 0.5).ceil() as u32,
        }
    }

    /// The pixel indices (in 1D) receiving weight from a sample at coordinate `x`:
    /// [first, last], unclipped.
    fn footprint(&self, x: f64) -> (i64, i64) {
        match *self {
            ReconstructionFilter::Box => {
                let i = x.floor() as i64;
                (i, i)
            }
            ReconstructionFilter::Gaussian { radius, .. } => {
                // Pixel i's centre is i + ½; it is covered when |i + ½ − x| < r.
                let c = x - 0.5;
                (
                    (c - radius).floor() as i64 + 1,
                    (c + radius).ceil() as i64 - 1,
                )
            }
        }
    }
}

/// The 1D weights of a sample at coordinate `x` for the pixels [lo, hi] (part of its
/// footprint), written into `weights`.
fn weights_1d(filter: &ReconstructionFilter, x: f64, lo: i64, hi: i64, weights: &mut Vec<f64>) {
    weights.clear();
    for i in lo..=hi {
        weights.push(filter.eval(i as f64 + 0.5 - x));
    }
}

/// Clips `footprint` to [lo, hi); None when empty.
fn clip(footprint: (i64, i64), lo: i64, hi: i64) -> Option<(i64, i64)> {
    let first = footprint.0.max(lo);
    let last = footprint.1.min(hi - 1);
    (first <= last).then_some((first, last))
}

fn is_finite(value: Rgb) -> bool {
    value.0.iter().all(|c| c.is_finite())
}

/// One pixel's accumulators: the filter-weighted sums of red, green and blue, then of the
/// weights.
type PixelSums = [f64; 4];

/// The whole image's accumulators.
#[derive(Clone, Debug)]
pub struct Film {
    width: u32,
    height: u32,
    filter: ReconstructionFilter,
    /// Per pixel: Σ w·r, Σ w·g, Σ w·b, Σ w.
    sums: Vec<PixelSums>,
    /// Per pixel: Σ w·value of the splats (`image` divides by Z).
    splats: Vec<[f64; 3]>,
    /// The filter's mass over the image per column and per row: Z(i, j) = zx[i] · zy[j].
    splat_mass_x: Vec<f64>,
    splat_mass_y: Vec<f64>,
    samples: u64,
    invalid_samples: u64,
    scratch_x: Vec<f64>,
    scratch_y: Vec<f64>,
    /// Buffers of merged tiles, for `tile` to hand out again.
    spare: SpareTiles,
}

/// The buffers of tiles already merged (`Film::recycle`), handed out again by `Film::tile`:
/// a pass then allocates nothing, where allocating and freeing a few megabytes of tiles
/// per pass made the allocator return pages to the system and fault them in again (7% of
/// `pt`'s time on two threads on the Cornell box, most of it in the kernel).
#[derive(Default)]
struct SpareTiles(Mutex<Vec<TileBuffers>>);

/// A tile's accumulators and its filter-weight scratch space.
type TileBuffers = (Vec<[f64; 4]>, Vec<f64>, Vec<f64>);

impl Clone for SpareTiles {
    fn clone(&self) -> SpareTiles {
        SpareTiles::default()
    }
}

impl std::fmt::Debug for SpareTiles {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SpareTiles")
    }
}

/// The accumulators a tile writes to (its pixels plus the filter's margin), merged into
/// the `Film` in tile order.
#[derive(Clone, Debug)]
pub struct FilmTile {
    rect: PixelRect,
    /// The pixels this tile stores: `rect` grown by the filter margin, clipped to the image.
    buffer: PixelRect,
    image_width: u32,
    image_height: u32,
    filter: ReconstructionFilter,
    sums: Vec<PixelSums>,
    samples: u64,
    invalid_samples: u64,
    scratch_x: Vec<f64>,
    scratch_y: Vec<f64>,
}

/// Splats recorded by one piece of light-tracing work, to be merged into the `Film` in a
/// fixed piece order (`Film::merge_splats`). Reuse it across passes with `clear`.
#[derive(Clone, Debug, Default)]
pub struct SplatList {
    entries: Vec<(Vec2, Rgb)>,
}

impl SplatList {
    pub fn new() -> Self {
        SplatList::default()
    }

    /// Records a splat at raster position `raster`.
    pub fn push(&mut self, raster: Vec2, value: Rgb) {
        self.entries.push((raster, value));
    }

    /// The splats in the order they were recorded.
    pub fn entries(&self) -> &[(Vec2, Rgb)] {
        &self.entries
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    pub fn clear(&mut self) {
        self.entries.clear();
    }
}

/// `n` copies of `value`, or None when the memory cannot be had.
fn try_filled<T: Copy>(n: usize, value: T) -> Option<Vec<T>> {
    let mut buffer = Vec::new();
    buffer.try_reserve_exact(n).ok()?;
    buffer.resize(n, value);
    Some(buffer)
}

impl Film {
    /// A black film; an error when its buffers do not fit in memory.
    pub fn new(width: u32, height: u32, filter: FilterDesc) -> Result<Film> {
        let filter = ReconstructionFilter::new(filter);
        let mass = |n: u32| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    // ∫_0^n w(i + ½ − x) dx = ∫_{i + ½ − n}^{i + ½} w(t) dt
                    let c = i as f64 + 0.5;
                    filter.integral(c - n as f64, c)
                })
                .collect()
        };
        let pixels = width as usize * height as usize;
        // A huge film under a memory limit is an error, not an abort.
        let (Some(sums), Some(splats)) =
            (try_filled(pixels, [0.0; 4]), try_filled(pixels, [0.0; 3]))
        else {
            let bytes = pixels as f64 * (size_of::<[f64; 4]>() + size_of::<[f64; 3]>()) as f64;
            return Err(Error::usage(format!(
                "a {width} × {height} film needs {:.1} GiB, more memory than this process can \
                 allocate; render at a lower resolution (the film's width and height)",
                bytes / (1u64 << 30) as f64
            )));
        };
        Ok(Film {
            width,
            height,
            filter,
            sums,
            splats,
            splat_mass_x: mass(width),
            splat_mass_y: mass(height),
            samples: 0,
            invalid_samples: 0,
            scratch_x: Vec::new(),
            scratch_y: Vec::new(),
            spare: SpareTiles::default(),
        })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn filter(&self) -> ReconstructionFilter {
        self.filter
    }

    /// The whole image as one rectangle.
    pub fn rect(&self) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: self.width,
            y1: self.height,
        }
    }

    /// The image cut into `size` × `size` tiles (smaller at the right and bottom edges), in
    /// row-major order: a fixed order to merge them in.
    pub fn tiles(&self, size: u32) -> Vec<PixelRect> {
        let size = size.max(1);
        let mut tiles = Vec::new();
        for y0 in (0..self.height).step_by(size as usize) {
            for x0 in (0..self.width).step_by(size as usize) {
                tiles.push(PixelRect {
                    x0,
                    y0,
                    x1: (x0 + size).min(self.width),
                    y1: (y0 + size).min(self.height),
                });
            }
        }
        tiles
    }

    /// An empty tile covering `rect` (and the filter margin around it).
    pub fn tile(&self, rect: PixelRect) -> FilmTile {
        let (rect, buffer) = self.tile_rects(rect);
        let (mut sums, scratch_x, scratch_y) = self
            .spare
            .0
            .lock()
            .ok()
            .and_then(|mut spare| spare.pop())
            .unwrap_or_default();
        sums.clear();
        sums.resize(buffer.pixel_count(), [0.0; 4]);
        FilmTile {
            rect,
            buffer,
            image_width: self.width,
            image_height: self.height,
            filter: self.filter,
            sums,
            samples: 0,
            invalid_samples: 0,
            scratch_x,
            scratch_y,
        }
    }

    /// The bytes of pixel sums a tile covering `rect` holds (`tile`).
    pub fn tile_bytes(&self, rect: PixelRect) -> usize {
        self.tile_rects(rect).1.pixel_count() * std::mem::size_of::<PixelSums>()
    }

    /// A tile's own rectangle (`rect` clipped to the image) and the pixels it stores: that
    /// rectangle grown by the filter margin, clipped to the image.
    fn tile_rects(&self, rect: PixelRect) -> (PixelRect, PixelRect) {
        let margin = self.filter.margin();
        let x1 = rect.x1.min(self.width);
        let y1 = rect.y1.min(self.height);
        let rect = PixelRect {
            x0: rect.x0.min(x1),
            y0: rect.y0.min(y1),
            x1,
            y1,
        };
        let buffer = PixelRect {
            x0: rect.x0.saturating_sub(margin),
            y0: rect.y0.saturating_sub(margin),
            x1: rect.x1.saturating_add(margin).min(self.width),
            y1: rect.y1.saturating_add(margin).min(self.height),
        };
        (rect, buffer)
    }

    /// Keeps the buffers of `tile` (already merged) for later `tile` calls.
    pub fn recycle(&self, tile: FilmTile) {
        if let Ok(mut spare) = self.spare.0.lock() {
            spare.push((tile.sums, tile.scratch_x, tile.scratch_y));
        }
    }

    /// `merge_tile` for each of `tiles` in order, the image's rows merged in parallel:
    /// every pixel still receives its tiles' sums in the order of `tiles`, so the result is
    /// bit for bit that of merging them one after the other.
    pub fn merge_tiles<'a>(&mut self, tiles: impl Iterator<Item = &'a FilmTile> + Clone + Sync) {
        let width = self.width as usize;
        self.sums
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| {
                let y = y as u32;
                for tile in tiles.clone() {
                    let b = tile.buffer;
                    if y < b.y0 || y >= b.y1 {
                        continue;
                    }
                    let n = b.width() as usize;
                    let src = (y - b.y0) as usize * n;
                    let dst = &mut row[b.x0 as usize..b.x0 as usize + n];
                    for (d, s) in dst.iter_mut().zip(&tile.sums[src..src + n]) {
                        for k in 0..4 {
                            d[k] += s[k];
                        }
                    }
                }
            });
        for tile in tiles {
            debug_assert_eq!(
                (tile.image_width, tile.image_height),
                (self.width, self.height)
            );
            self.samples += tile.samples;
            self.invalid_samples += tile.invalid_samples;
        }
    }

    /// Adds a finished tile. Call in a fixed tile order for bit-identical results.
    pub fn merge_tile(&mut self, tile: &FilmTile) {
        debug_assert_eq!(
            (tile.image_width, tile.image_height),
            (self.width, self.height)
        );
        let b = tile.buffer;
        for y in b.y0..b.y1 {
            let src = (y - b.y0) as usize * b.width() as usize;
            let dst = y as usize * self.width as usize + b.x0 as usize;
            let n = b.width() as usize;
            for (d, s) in self.sums[dst..dst + n]
                .iter_mut()
                .zip(&tile.sums[src..src + n])
            {
                for k in 0..4 {
                    d[k] += s[k];
                }
            }
        }
        self.samples += tile.samples;
        self.invalid_samples += tile.invalid_samples;
    }

    /// Adds a light-tracing splat at raster position `raster` (filtered as explained in the
    /// module documentation, unnormalised: it is not divided by a weight sum). Splats
    /// outside the image and non-finite values are dropped (the latter counted in
    /// `invalid_samples`).
    pub fn splat(&mut self, raster: Vec2, value: Rgb) {
        if !is_finite(value) {
            self.invalid_samples += 1;
            return;
        }
        let (x, y) = (raster.x as f64, raster.y as f64);
        if !(x >= 0.0 && x <= self.width as f64 && y >= 0.0 && y <= self.height as f64) {
            return;
        }
        self.add_filtered(raster, value, |film, p| {
            let [r, g, b] = &mut film.splats[p];
            [r, g, b]
        });
    }

    /// Adds `value` at raster position `raster` through the filter as a camera sample's, but
    /// without the sample's own filter weight: for images of parts of a camera sample's
    /// value (one strategy's), whose pixels divide by the weights of the film that took the
    /// whole samples (`image_normalized_by`). Non-finite values are dropped and counted.
    pub fn add_value(&mut self, raster: Vec2, value: Rgb) {
        if !is_finite(value) || !raster.is_finite() {
            self.invalid_samples += 1;
            return;
        }
        self.add_filtered(raster, value, |film, p| {
            let [r, g, b, _] = &mut film.sums[p];
            [r, g, b]
        });
    }

    /// Adds w·`value` to the three sums `target(film, pixel)` gives, for every pixel the
    /// filter reaches from `raster` (weight w), clipped to the image.
    fn add_filtered(
        &mut self,
        raster: Vec2,
        value: Rgb,
        target: impl for<'f> Fn(&'f mut Film, usize) -> [&'f mut f64; 3],
    ) {
        let (x, y) = (raster.x as f64, raster.y as f64);
        let v = value.0.map(f64::from);
        if let ReconstructionFilter::Box = self.filter {
            // The one pixel the sample falls in, weight 1 (what the general loop below
            // computes, without its weight tables: Metropolis merges splats on one thread).
            let (i, j) = (x.floor() as i64, y.floor() as i64);
            if (0..self.width as i64).contains(&i) && (0..self.height as i64).contains(&j) {
                let p = j as usize * self.width as usize + i as usize;
                for (s, v) in target(self, p).into_iter().zip(v) {
                    *s += v;
                }
            }
            return;
        }
        let Some((x0, x1)) = clip(self.filter.footprint(x), 0, self.width as i64) else {
            return;
        };
        let Some((y0, y1)) = clip(self.filter.footprint(y), 0, self.height as i64) else {
            return;
        };
        weights_1d(&self.filter, x, x0, x1, &mut self.scratch_x);
        weights_1d(&self.filter, y, y0, y1, &mut self.scratch_y);
        for j in y0..=y1 {
            let wy = self.scratch_y[(j - y0) as usize];
            let row = j as usize * self.width as usize;
            for i in x0..=x1 {
                let w = self.scratch_x[(i - x0) as usize] * wy;
                for (s, v) in target(self, row + i as usize).into_iter().zip(v) {
                    *s += w * v;
                }
            }
        }
    }

    /// Adds the splats of one piece of work, in the order they were recorded.
    pub fn merge_splats(&mut self, splats: &SplatList) {
        for &(raster, value) in &splats.entries {
            self.splat(raster, value);
        }
    }

    /// Forgets everything accumulated so far.
    pub fn clear(&mut self) {
        self.sums.fill([0.0; 4]);
        self.splats.fill([0.0; 3]);
        self.samples = 0;
        self.invalid_samples = 0;
    }

    /// Camera samples added through merged tiles (invalid ones not included).
    pub fn sample_count(&self) -> u64 {
        self.samples
    }

    /// The raw accumulators of pixel (x, y): (Σ w·L per channel, Σ w).
    pub fn pixel_sums(&self, x: u32, y: u32) -> ([f64; 3], f64) {
        let [r, g, b, w] = self.sums[y as usize * self.width as usize + x as usize];
        ([r, g, b], w)
    }

    /// Samples and splats dropped because a channel was NaN or infinite.
    pub fn invalid_samples(&self) -> u64 {
        self.invalid_samples
    }

    /// The current estimate when the splats came from `light_paths` light paths: each
    /// path's splats estimate the measurement of the whole image (the camera's importance
    /// is normalised over it), so a pixel's share is the splats × pixels / paths.
    pub fn image_with_light_paths(&self, light_paths: u64) -> Image {
        if light_paths == 0 {
            return self.image(0.0);
        }
        let pixels = self.width as f64 * self.height as f64;
        self.image(pixels / light_paths as f64)
    }

    /// The current estimate: filtered pixel values plus the splats times `splat_scale`.
    /// The accumulators, per pixel Σ w·r, Σ w·g, Σ w·b, Σ w (for tests of merge order: the
    /// image rounds their last bits away).
    #[cfg(test)]
    pub(crate) fn sums(&self) -> &[[f64; 4]] {
        &self.sums
    }

    pub fn image(&self, splat_scale: f64) -> Image {
        self.image_normalized_by(self, splat_scale)
    }

    /// `image` with the pixel values (`add_value`'s) divided by the filter weights of
    /// `samples`, a film of the same size that took the camera samples whole.
    pub fn image_normalized_by(&self, samples: &Film, splat_scale: f64) -> Image {
        debug_assert_eq!(self.sums.len(), samples.sums.len());
        let mut image = Image::new(self.width, self.height);
        for j in 0..self.height as usize {
            for i in 0..self.width as usize {
                let p = j * self.width as usize + i;
                let [r, g, b, _] = self.sums[p];
                let w = samples.sums[p][3];
                let inv_w = if w != 0.0 { 1.0 / w } else { 0.0 };
                let s = self.splats[p];
                let splat_w = if s == [0.0; 3] {
                    0.0
                } else {
                    splat_scale / (self.splat_mass_x[i] * self.splat_mass_y[j])
                };
                image.pixels[p] = Rgb::new(
                    (r * inv_w + s[0] * splat_w) as f32,
                    (g * inv_w + s[1] * splat_w) as f32,
                    (b * inv_w + s[2] * splat_w) as f32,
                );
            }
        }
        image
    }
}

impl FilmTile {
    /// The tile's own pixels.
    pub fn rect(&self) -> PixelRect {
        self.rect
    }

    /// The pixels this tile's accumulators cover (its rectangle plus the filter margin,
    /// clipped to the image).
    pub fn buffer_rect(&self) -> PixelRect {
        self.buffer
    }

    /// Camera samples added to this tile (invalid ones not included).
    pub fn sample_count(&self) -> u64 {
        self.samples
    }

    /// Empties the tile so it can be reused for the same rectangle.
    pub fn clear(&mut self) {
        self.sums.fill([0.0; 4]);
        self.samples = 0;
        self.invalid_samples = 0;
    }

    /// Adds a camera sample taken at raster position `raster`, weighted by the filter.
    /// `raster` should lie in the tile's rectangle (edges included); with the box filter the
    /// sample goes to pixel floor(raster) (see `camera::raster_in_pixel`). Weight falling
    /// outside the image is dropped, as in Mitsuba. A sample with a NaN or infinite channel
    /// or position is dropped and counted (`Film::invalid_samples`) instead of poisoning
    /// the pixels.
    pub fn add_sample(&mut self, raster: Vec2, value: Rgb) {
        if !is_finite(value) || !raster.is_finite() {
            self.invalid_samples += 1;
            return;
        }
        self.samples += 1;
        let (x, y) = (raster.x as f64, raster.y as f64);
        let fx = self.filter.footprint(x);
        let fy = self.filter.footprint(y);
        debug_assert!(
            clip(fx, 0, self.image_width as i64)
                .is_none_or(|(a, b)| a >= self.buffer.x0 as i64 && b < self.buffer.x1 as i64)
                && clip(fy, 0, self.image_height as i64)
                    .is_none_or(|(a, b)| a >= self.buffer.y0 as i64 && b < self.buffer.y1 as i64),
            "sample at {raster} reaches beyond tile {:?}",
            self.rect
        );
        let Some((x0, x1)) = clip(fx, self.buffer.x0 as i64, self.buffer.x1 as i64) else {
            return;
        };
        let Some((y0, y1)) = clip(fy, self.buffer.y0 as i64, self.buffer.y1 as i64) else {
            return;
        };
        let v = value.0.map(f64::from);
        let stride = self.buffer.width() as usize;
        if self.filter == ReconstructionFilter::Box {
            // One pixel with weight 1 (|i + ½ − x| ≤ ½ for i = ⌊x⌋): the general loop's
            // sums, 1·1·v = v exactly, without evaluating the filter.
            let row = (y0 - self.buffer.y0 as i64) as usize * stride;
            let s = &mut self.sums[row + (x0 - self.buffer.x0 as i64) as usize];
            s[0] += v[0];
            s[1] += v[1];
            s[2] += v[2];
            s[3] += 1.0;
            return;
        }
        weights_1d(&self.filter, x, x0, x1, &mut self.scratch_x);
        weights_1d(&self.filter, y, y0, y1, &mut self.scratch_y);
        for (j, &wy) in (y0..=y1).zip(&self.scratch_y) {
            let row = (j - self.buffer.y0 as i64) as usize * stride;
            for (i, &wx) in (x0..=x1).zip(&self.scratch_x) {
                let w = wx * wy;
                let s = &mut self.sums[row + (i - self.buffer.x0 as i64) as usize];
                s[0] += w * v[0];
                s[1] += w * v[1];
                s[2] += w * v[2];
                s[3] += w;
            }
        }
    }
}
