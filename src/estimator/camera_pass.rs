//! Passes of a camera-side estimator: in each, every pixel takes one sample, tile by tile.
//!
//! Tiles have a fixed size (not tied to the thread count), each pixel sample seeds its own
//! random stream from (seed, pixel, sample index), and finished tiles merge into the film
//! pass by pass, in tile order: the image is bit-identical for any number of threads
//! (docs/DESIGN.md §3), and for passes run one by one or several at once (`camera_passes`).

use rayon::prelude::*;

use super::bdpt::StrategyImage;
use super::{Estimator, Stats};
use crate::camera::{Camera, raster_in_pixel};
use crate::error::Result;
use crate::film::{Film, FilmTile, PixelRect};
use crate::geometry::Ray;
use crate::image::Image;
use crate::math::Rgb;
use glam::Vec2;
use std::ops::Range;
use std::sync::Arc;

use crate::sampler::pixel_samples::{CameraSampler, PixelSamples};
use crate::sampler::{Sampler, Stream};
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

impl std::ops::AddAssign for PassCounts {
    fn add_assign(&mut self, o: PassCounts) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.invalid += o.invalid;
    }
}

/// A tile of one pass, finished: its pixel sums, its counts, and what its samples added
/// elsewhere (`CameraSampleFn::Extra`).
pub struct FinishedTile<E> {
    pub tile: FilmTile,
    pub counts: PassCounts,
    pub extra: E,
}

/// What an estimator computes for one camera sample: the radiance along `ray` for the
/// sample's pixel, the rays it cast, and what it adds elsewhere (to `extra`: splats, the
/// strategy images' records). The driver (`camera_passes`) owns tiles, passes and threads;
/// the sample function knows nothing of them.
pub trait CameraSampleFn: Sync {
    /// Buffers reused by every sample of a tile (no allocation per sample).
    type Scratch<'a>: Default;
    /// What a tile's samples add beyond their pixels; merged in tile order (`merge_extra`).
    type Extra: Default + Send + Sync;

    /// The camera sample along `ray`, which leaves the camera at film position `raster`.
    fn radiance<'a>(
        &self,
        scene: &'a Scene,
        ray: &Ray,
        raster: Vec2,
        sampler: &mut CameraSampler,
        scratch: &mut Self::Scratch<'a>,
        extra: &mut Self::Extra,
    ) -> (Rgb, u64);

    /// Adds a finished tile's `extra` to `film` (and to whatever else the estimator keeps),
    /// tiles in a fixed order; returns the samples it dropped as not finite.
    fn merge_extra(&mut self, _film: &mut Film, _extra: &mut Self::Extra) -> u64 {
        0
    }

    /// True when samples splat light-path contributions (one light path per camera sample):
    /// the image is then `Film::image_with_light_paths` of the samples taken.
    fn splats(&self) -> bool {
        false
    }

    /// True for an estimator that keeps strategy images (`bdpt` with `strategies=true`).
    fn keeps_strategy_images(&self) -> bool {
        false
    }

    /// The strategy images, for an estimator that keeps them.
    fn strategy_images(&self, _film: &Film, _samples: u64) -> Option<Vec<StrategyImage>> {
        None
    }

    /// Tiles that one task renders together (`render_tiles`); 1 unless the estimator keeps
    /// several paths in flight and wants a longer queue of samples to draw them from.
    fn tiles_per_task(&self) -> usize {
        1
    }

    /// Takes each pass's sample of every pixel of `rects` (consecutive tiles, in order) and
    /// returns one finished tile per pass and rect, pass by pass (for each pass of
    /// `ctx.passes`, the rects in order). By default one sample after the other
    /// (`render_tile`); an estimator may trace them otherwise, but must return the tiles
    /// `render_tile` would (the same samples added in the same order).
    fn render_tiles(
        &self,
        ctx: &PassContext,
        rects: &[PixelRect],
    ) -> Vec<FinishedTile<Self::Extra>> {
        render_tiles_one_by_one(ctx, rects, self)
    }
}

/// `CameraSampleFn::render_tiles` by default: `render_tile` for each pass and rect, with
/// one scratch for them all.
pub fn render_tiles_one_by_one<S: CameraSampleFn + ?Sized>(
    ctx: &PassContext,
    rects: &[PixelRect],
    estimate: &S,
) -> Vec<FinishedTile<S::Extra>> {
    let mut scratch = S::Scratch::default();
    let mut out = Vec::with_capacity(ctx.passes.len() * rects.len());
    for pass in ctx.passes.clone() {
        for &rect in rects {
            out.push(render_tile(ctx, rect, pass, estimate, &mut scratch));
        }
    }
    out
}

/// What every task of a run of passes shares.
pub struct PassContext<'a> {
    pub scene: &'a Scene,
    pub film: &'a Film,
    pub seed: u64,
    /// The passes to take (sample indices of every pixel).
    pub passes: Range<u32>,
    pub pixel_samples: &'a Arc<PixelSamples>,
}

impl PassContext<'_> {
    /// A sampler for this pass's camera samples (lens samples when the camera has a lens).
    pub fn camera_sampler(&self) -> CameraSampler {
        CameraSampler::new(self.seed, self.pixel_samples.clone())
            .with_lens_samples(self.scene.camera.has_lens())
    }
}

/// Takes sample `pass` of every pixel of `rect`, row by row, one after the other.
pub fn render_tile<'a, S: CameraSampleFn + ?Sized>(
    ctx: &PassContext<'a>,
    rect: PixelRect,
    pass: u32,
    estimate: &S,
    scratch: &mut S::Scratch<'a>,
) -> FinishedTile<S::Extra> {
    let mut tile = ctx.film.tile(rect);
    let mut counts = PassCounts::default();
    let mut extra = S::Extra::default();
    let mut sampler = ctx.camera_sampler();
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let (raster, ray) = start_camera_sample(&ctx.scene.camera, &mut sampler, x, y, pass);
            let (value, rays) =
                estimate.radiance(ctx.scene, &ray, raster, &mut sampler, scratch, &mut extra);
            counts.add_sample(&mut tile, raster, value, rays);
        }
    }
    FinishedTile {
        tile,
        counts,
        extra,
    }
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

/// The most pixel-sum memory the finished tiles of one group of passes may hold
/// (`camera_passes`). Every pass of a group keeps a tile per rectangle until the group is
/// merged. Memory a process touches for the first time costs a page fault per 4 KiB, and
/// tiles that outgrow the caches are merged from main memory: on a 128 × 128 image, 35
/// passes in one go (the time-based chunk of `render::advance`) took 6,500–7,800 faults,
/// groups of 8 MiB 4,000 (`pt` 7% faster), groups of 2 MiB 1,600 (6% faster again); on
/// 256 × 256 (one pass per group) no slower. The tiles are reused from group to group
/// (`Film::recycle`).
const TILE_MEMORY: usize = 2 << 20;

/// Takes samples `passes` of every pixel and adds them to `film`, pass by pass in tile
/// order (the same bits as one call per pass), each tile's extra after its pass's pixels.
/// Samples that are NaN, infinite or negative are dropped and counted. The passes go in
/// groups whose tiles fit in `TILE_MEMORY`.
pub fn camera_passes<S: CameraSampleFn>(
    scene: &Scene,
    film: &mut Film,
    seed: u64,
    passes: Range<u32>,
    pixel_samples: &Arc<PixelSamples>,
    estimate: &mut S,
) -> PassCounts {
    let rects = film.tiles(TILE_SIZE);
    let group = passes_per_group(film, &rects);
    let mut total = PassCounts::default();
    let mut first = passes.start;
    while first < passes.end {
        let end = passes.end.min(first.saturating_add(group));
        total += pass_group(
            scene,
            film,
            seed,
            first..end,
            &rects,
            pixel_samples,
            estimate,
        );
        first = end;
    }
    total
}

/// How many passes over the tiles `rects` of `film` fit in `TILE_MEMORY` (at least one).
fn passes_per_group(film: &Film, rects: &[PixelRect]) -> u32 {
    let pass_bytes: usize = rects.iter().map(|&r| film.tile_bytes(r)).sum();
    (TILE_MEMORY / pass_bytes.max(1)).clamp(1, u32::MAX as usize) as u32
}

/// `camera_passes` for one group of passes over the tiles `rects`: every task renders its
/// tiles for all of the group's passes, then the tiles merge pass by pass.
fn pass_group<S: CameraSampleFn>(
    scene: &Scene,
    film: &mut Film,
    seed: u64,
    passes: Range<u32>,
    rects: &[PixelRect],
    pixel_samples: &Arc<PixelSamples>,
    estimate: &mut S,
) -> PassCounts {
    let count = passes.len();
    let ctx = PassContext {
        scene,
        film,
        seed,
        passes,
        pixel_samples,
    };
    let shared: &S = estimate;
    let mut finished: Vec<Vec<FinishedTile<S::Extra>>> = rects
        .par_chunks(shared.tiles_per_task().max(1))
        .map(|batch| shared.render_tiles(&ctx, batch))
        .collect();
    let mut total = PassCounts::default();
    // Each batch's tiles are pass by pass: pass k's are its k-th run of equal length.
    for k in 0..count {
        film.merge_tiles(finished.iter().flat_map(move |batch| {
            let n = batch.len() / count;
            batch[k * n..(k + 1) * n].iter().map(|t| &t.tile)
        }));
        for batch in finished.iter_mut() {
            let n = batch.len() / count;
            for t in &mut batch[k * n..(k + 1) * n] {
                total.invalid += estimate.merge_extra(film, &mut t.extra);
            }
        }
    }
    for t in finished.into_iter().flatten() {
        film.recycle(t.tile);
        total += t.counts;
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
    camera_ray(camera, (x, y), sampler)
}

/// The camera sample's first draws, from the camera stream: the raster position within
/// pixel `pixel`, then (only for a lens) the lens point; the raster position and the ray.
pub fn camera_ray(camera: &Camera, (x, y): (u32, u32), sampler: &mut impl Sampler) -> (Vec2, Ray) {
    sampler.start_stream(Stream::Camera);
    let raster = raster_in_pixel(x, y, sampler.next_2d());
    (raster, ray_from_raster(camera, raster, sampler))
}

/// A camera sample anywhere on a `width` × `height` film: the camera stream's first 2D draw
/// spans the whole image (so that a Metropolis sampler moves the sample across pixels),
/// then (only for a lens) the lens point; the raster position and the ray.
pub fn camera_ray_in_image(
    camera: &Camera,
    (width, height): (u32, u32),
    sampler: &mut impl Sampler,
) -> (Vec2, Ray) {
    sampler.start_stream(Stream::Camera);
    let u = sampler.next_2d();
    let (x, y) = (u.x * width as f32, u.y * height as f32);
    // The pixel the position falls in, then the offset in it (guarded against rounding up).
    let (px, py) = ((x as u32).min(width - 1), (y as u32).min(height - 1));
    let raster = raster_in_pixel(px, py, Vec2::new(x - px as f32, y - py as f32));
    (raster, ray_from_raster(camera, raster, sampler))
}

/// The camera ray through `raster`, drawing the lens point for a thin lens.
fn ray_from_raster(camera: &Camera, raster: Vec2, sampler: &mut impl Sampler) -> Ray {
    if camera.has_lens() {
        camera.sample_ray(raster, sampler.next_2d())
    } else {
        camera.generate_ray(raster)
    }
}

/// An estimator that takes one camera sample per pixel and pass, computed by `S`
/// (`eyelight`, `pt`, `bdpt`): the film, the seed and the counters they all keep.
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

    /// A sampler for this estimator's camera samples of `scene`, as its passes use.
    pub fn camera_sampler(&self, scene: &Scene) -> CameraSampler {
        CameraSampler::new(self.seed, self.pixel_samples.clone())
            .with_lens_samples(scene.camera.has_lens())
    }

    /// The film the passes accumulate in.
    #[cfg(test)]
    pub(crate) fn film(&self) -> &Film {
        &self.film
    }
}

impl<S: CameraSampleFn + Send> Estimator for CameraEstimator<S> {
    fn name(&self) -> &str {
        self.name
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        self.run_passes(scene, pass_index, 1);
    }

    fn run_passes(&mut self, scene: &Scene, first: u32, count: u32) {
        let counts = camera_passes(
            scene,
            &mut self.film,
            self.seed,
            first..first + count,
            &self.pixel_samples,
            &mut self.sample,
        );
        self.stats.passes += count as u64;
        self.stats.samples += counts.samples;
        self.stats.rays += counts.rays;
        self.stats.invalid_samples += counts.invalid;
    }

    fn image(&self) -> Image {
        if self.sample.splats() {
            // One light subpath per camera sample.
            self.film.image_with_light_paths(self.stats.samples)
        } else {
            self.film.image(0.0)
        }
    }

    fn stats(&self) -> Stats {
        self.stats.clone()
    }

    fn keeps_strategy_images(&self) -> bool {
        self.sample.keeps_strategy_images()
    }

    fn strategy_images(&self) -> Option<Vec<StrategyImage>> {
        self.sample.strategy_images(&self.film, self.stats.samples)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::pt;
    use crate::scene::mitsuba;

    /// Passes taken several at a time merge into the film in the order of one pass at a
    /// time, down to the f64 accumulators' bits (which the image rounds away): a Gaussian
    /// filter's tiles overlap, so any other order shows.
    #[test]
    fn passes_in_one_go_merge_as_one_pass_at_a_time() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/cbox.xml");
        let text = std::fs::read_to_string(&path)
            .unwrap()
            .replace(r#"<rfilter type="box"/>"#, r#"<rfilter type="gaussian"/>"#);
        let params = [("res".to_string(), "40".to_string())];
        let scene = Scene::build(mitsuba::load_str_with(&text, &path, &params).unwrap()).unwrap();
        for wavefront in [true, false] {
            let settings = pt::PtSettings {
                wavefront,
                ..pt::PtSettings::from_params(&Default::default(), &scene).unwrap()
            };
            let sums = |chunks: &[u32]| {
                let mut e = pt::new(&scene, 5, settings).unwrap();
                let mut first = 0;
                for &count in chunks {
                    e.run_passes(&scene, first, count);
                    first += count;
                }
                e.film()
                    .sums()
                    .iter()
                    .flat_map(|s| s.map(f64::to_bits))
                    .collect::<Vec<_>>()
            };
            let one_at_a_time = sums(&[1; 12]);
            assert!(sums(&[5, 7]) == one_at_a_time, "wavefront {wavefront}");
            assert!(sums(&[12]) == one_at_a_time, "wavefront {wavefront}");
            // A chunk of more passes than one group holds (`TILE_MEMORY`) is split into
            // groups, which merge as one pass at a time too.
            let film = pt::new(&scene, 5, settings).unwrap().film().clone();
            let group = passes_per_group(&film, &film.tiles(TILE_SIZE));
            let passes = 2 * group + 3;
            let one_at_a_time = sums(&vec![1; passes as usize]);
            assert!(sums(&[passes]) == one_at_a_time, "wavefront {wavefront}");
        }
    }
}
