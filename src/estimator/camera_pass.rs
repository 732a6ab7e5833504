//! One pass of a camera-side estimator: every pixel takes one sample, tile by tile.
//!
//! Tiles have a fixed size (not tied to the thread count), each pixel sample seeds its own
//! random stream from (seed, pixel, sample index), and finished tiles merge into the film in
//! tile order: the image is bit-identical for any number of threads (DESIGN.md §3).

use rayon::prelude::*;

use super::{Estimator, Stats};
use crate::camera::{Camera, raster_in_pixel};
use crate::error::Result;
use crate::film::{Film, FilmTile, PixelRect};
use crate::geometry::Ray;
use crate::image::Image;
use crate::math::Rgb;
use glam::Vec2;
use std::sync::Arc;

use crate::sampler::Sampler;
use crate::sampler::pixel_samples::{CameraSampler, PixelSamples};
use crate::scene::Scene;

/// Edge length of a tile in pixels.
pub const TILE_SIZE: u32 = 16;

/// Per-pass counters returned by `camera_pass`.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassCounts {
    pub samples: u64,
    pub rays: u64,
    pub invalid: u64,
}

/// What an estimator computes for one camera sample: the radiance along `ray`,
/// and the number of rays it cast.
pub trait CameraSampleFn: Sync {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut CameraSampler) -> (Rgb, u64);

    /// Tiles that one task renders together (`render_tiles`); 1 unless the estimator keeps
    /// several paths in flight and wants a longer queue of samples to draw them from.
    fn tiles_per_task(&self) -> usize {
        1
    }

    /// Takes the pass's sample of every pixel of `rects` (consecutive tiles, in order) and
    /// returns one finished tile with its counts per rect. By default one sample after the
    /// other (`render_tile`); an estimator may trace them otherwise, but must return the
    /// tile `render_tile` would (the same samples added in the same order).
    fn render_tiles(&self, pass: &PassContext, rects: &[PixelRect]) -> Vec<(FilmTile, PassCounts)> {
        rects
            .iter()
            .map(|&rect| render_tile(pass, rect, self))
            .collect()
    }
}

/// What every task of a pass shares.
pub struct PassContext<'a> {
    pub scene: &'a Scene,
    pub film: &'a Film,
    pub seed: u64,
    pub pass_index: u32,
    pub pixel_samples: &'a Arc<PixelSamples>,
}

impl PassContext<'_> {
    /// A sampler for this pass's camera samples (lens samples when the camera has a lens).
    pub fn camera_sampler(&self) -> CameraSampler {
        CameraSampler::new(self.seed, self.pixel_samples.clone())
            .with_lens_samples(self.scene.camera.has_lens())
    }
}

/// Takes the pass's sample of every pixel of `rect`, row by row, one after the other.
pub fn render_tile(
    pass: &PassContext,
    rect: PixelRect,
    estimate: &(impl CameraSampleFn + ?Sized),
) -> (FilmTile, PassCounts) {
    let mut tile = pass.film.tile(rect);
    let mut counts = PassCounts::default();
    let mut sampler = pass.camera_sampler();
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let (raster, ray) =
                start_camera_sample(&pass.scene.camera, &mut sampler, x, y, pass.pass_index);
            let (value, rays) = estimate.radiance(pass.scene, &ray, &mut sampler);
            counts.add_sample(&mut tile, raster, value, rays);
        }
    }
    (tile, counts)
}

impl PassCounts {
    /// Counts one finished camera sample and adds it to `tile`, unless it is NaN, infinite
    /// or negative (then it is counted as invalid and dropped).
    pub fn add_sample(&mut self, tile: &mut FilmTile, raster: Vec2, value: Rgb, rays: u64) {
        self.samples += 1;
        self.rays += rays;
        if value.is_valid_radiance() {
            tile.add_sample(raster, value);
        } else {
            self.invalid += 1;
        }
    }
}

/// Takes sample number `pass_index` of every pixel and adds it to `film`.
/// Samples that are NaN, infinite or negative are dropped and counted.
pub fn camera_pass(
    scene: &Scene,
    film: &mut Film,
    seed: u64,
    pass_index: u32,
    pixel_samples: &Arc<PixelSamples>,
    estimate: &impl CameraSampleFn,
) -> PassCounts {
    let rects = film.tiles(TILE_SIZE);
    let pass = PassContext {
        scene,
        film,
        seed,
        pass_index,
        pixel_samples,
    };
    let finished: Vec<Vec<(FilmTile, PassCounts)>> = rects
        .par_chunks(estimate.tiles_per_task().max(1))
        .map(|batch| estimate.render_tiles(&pass, batch))
        .collect();
    film.merge_tiles(finished.iter().flatten().map(|(tile, _)| tile));
    let mut total = PassCounts::default();
    for (tile, counts) in finished.into_iter().flatten() {
        film.recycle(tile);
        total.samples += counts.samples;
        total.rays += counts.rays;
        total.invalid += counts.invalid;
    }
    total
}

/// Starts sample `pass_index` of pixel (x, y): the raster position and the camera ray. The
/// pixel position, then (only for a lens) the lens sample are the first two 2D samples of
/// the pixel sample (`CameraSampler`).
pub fn start_camera_sample(
    camera: &Camera,
    sampler: &mut CameraSampler,
    x: u32,
    y: u32,
    pass_index: u32,
) -> (Vec2, Ray) {
    sampler.start_pixel_sample((x, y), pass_index as u64);
    let raster = raster_in_pixel(x, y, sampler.next_2d());
    let ray = if camera.has_lens() {
        camera.sample_ray(raster, sampler.next_2d())
    } else {
        camera.generate_ray(raster)
    };
    (raster, ray)
}

/// An estimator that takes one camera sample per pixel and pass, computed by `S`
/// (`eyelight`, `pt`): the film, the seed and the counters they all keep.
pub struct CameraEstimator<S> {
    name: &'static str,
    film: Film,
    seed: u64,
    stats: Stats,
    sample: S,
    pixel_samples: Arc<PixelSamples>,
}

impl<S: CameraSampleFn + Send> CameraEstimator<S> {
    /// An error when the film does not fit in memory.
    pub fn new(name: &'static str, scene: &Scene, seed: u64, sample: S) -> Result<Self> {
        let film = &scene.description.sensor.film;
        Ok(CameraEstimator {
            name,
            film: Film::new(film.window().width, film.window().height, film.filter)?,
            seed,
            stats: Stats::default(),
            sample,
            pixel_samples: Arc::new(PixelSamples::Independent),
        })
    }

    /// Places the camera samples inside their pixels with `pixel_samples`.
    pub fn with_pixel_samples(mut self, pixel_samples: PixelSamples) -> Self {
        self.pixel_samples = Arc::new(pixel_samples);
        self
    }

    /// The per-sample computation (its settings).
    pub fn sample_fn(&self) -> &S {
        &self.sample
    }
}

impl<S: CameraSampleFn + Send> Estimator for CameraEstimator<S> {
    fn name(&self) -> &str {
        self.name
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        let counts = camera_pass(
            scene,
            &mut self.film,
            self.seed,
            pass_index,
            &self.pixel_samples,
            &self.sample,
        );
        self.stats.passes += 1;
        self.stats.samples += counts.samples;
        self.stats.rays += counts.rays;
        self.stats.invalid_samples += counts.invalid;
    }

    fn image(&self) -> Image {
        self.film.image(0.0)
    }

    fn stats(&self) -> Stats {
        self.stats.clone()
    }
}
