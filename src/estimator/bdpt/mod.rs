//! `bdpt`: bidirectional path tracing (Veach 1997, ch. 10; Lafortune and Willems 1993).
//!
//! Every camera sample traces a camera subpath z0 z1 … and a light subpath y0 y1 …, and
//! joins every prefix pair: the strategy (s, t) uses s light and t camera vertices, for a
//! path of s + t vertices and s + t − 1 segments (at most `max_depth`, Mitsuba's count).
//! The strategies themselves (`path::connection`) and their weights (`path::mis`: the
//! balance heuristic, `mis=balance`, the default, or the power heuristic, `mis=power`) are
//! the path space module's; this file runs them over the film.
//!
//! Lights at infinity take part as the path space module defines them: a camera subpath
//! that escapes ends at the environment (found by s = 0), next-event estimation samples
//! them (s = 1), and light subpaths start from the scene's bounding disk.
//!
//! With `strategies=true` every (s, t) of path length up to `strategies_max_depth` also
//! goes to an image of its own, weighted and unweighted (`strategy_images`).

mod strategy_images;

pub use strategy_images::{StrategyImage, StrategyImages};

use glam::Vec2;
use rayon::prelude::*;

use super::pt::PtSettings;
use super::{Estimator, Params, Stats};
use crate::error::{Error, Result};
use crate::film::{Film, FilmTile, SplatList};
use crate::geometry::Ray;
use crate::image::Image;
use crate::math::Rgb;
use crate::path::connection::{self, Sampled};
pub use crate::path::mis::Heuristic;
use crate::path::mis::PathDensity;
use crate::path::random_walk::WalkLimits;
use crate::path::subpath::{camera_subpath, light_subpath};
use crate::path::vertex::Vertex;
use crate::sampler::pixel_samples::{CameraSampler, PixelSamples};
use crate::scene::Scene;
use std::sync::Arc;

use super::camera_pass::{TILE_SIZE, start_camera_sample};

/// The longest path length `strategies_max_depth` may ask for: (L + 1)(L + 2) − 2 images.
const MAX_STRATEGIES_DEPTH: u32 = 16;

/// `bdpt`'s settings: `pt`'s three, `mis`, and the strategy images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BdptSettings {
    pub path: PtSettings,
    pub mis: Heuristic,
    /// Also write one image per strategy (s, t), weighted and unweighted (`render` only).
    pub strategies: bool,
    /// The longest path length (segments) that gets strategy images, whatever `max_depth`.
    pub strategies_max_depth: u32,
}

impl BdptSettings {
    pub fn from_params(params: &Params, scene: &Scene) -> Result<BdptSettings> {
        let path = PtSettings::from_params(params, scene)?;
        let mis = match params.get("mis", "balance".to_string())?.as_str() {
            "balance" => Heuristic::Balance,
            "power" => Heuristic::Power,
            other => {
                return Err(Error::usage(format!(
                    "--set mis={other}: expected balance or power"
                )));
            }
        };
        let strategies = params.get("strategies", false)?;
        let strategies_max_depth: u32 = params.get("strategies_max_depth", 8)?;
        if !(1..=MAX_STRATEGIES_DEPTH).contains(&strategies_max_depth) {
            return Err(Error::usage(format!(
                "--set strategies_max_depth={strategies_max_depth}: must be between 1 and \
                 {MAX_STRATEGIES_DEPTH}"
            )));
        }
        Ok(BdptSettings {
            path,
            mis,
            strategies,
            strategies_max_depth,
        })
    }
}

/// The `bdpt` estimator.
pub struct Bdpt {
    film: Film,
    seed: u64,
    settings: BdptSettings,
    stats: Stats,
    pixel_samples: Arc<PixelSamples>,
    /// With `strategies=true`.
    strategy_images: Option<StrategyImages>,
}

/// Makes `bdpt` for `scene`; an error for a film too large.
pub fn new(scene: &Scene, seed: u64, settings: BdptSettings) -> Result<Bdpt> {
    let film = &scene.description.sensor.film;
    let (width, height) = (film.window().width, film.window().height);
    let strategy_images = if settings.strategies {
        let depth = settings
            .path
            .max_depth
            .map_or(settings.strategies_max_depth, |d| {
                d.min(settings.strategies_max_depth)
            });
        Some(StrategyImages::new(width, height, film.filter, depth)?)
    } else {
        None
    };
    Ok(Bdpt {
        film: Film::new(width, height, film.filter)?,
        seed,
        settings,
        stats: Stats::default(),
        pixel_samples: Arc::new(PixelSamples::Independent),
        strategy_images,
    })
}

impl Bdpt {
    /// Places the camera samples inside their pixels with `pixel_samples`.
    pub fn with_pixel_samples(mut self, pixel_samples: PixelSamples) -> Self {
        self.pixel_samples = Arc::new(pixel_samples);
        self
    }

    /// The strategy images so far (with `strategies=true`).
    pub fn strategy_images(&self) -> Option<Vec<StrategyImage>> {
        let images = self.strategy_images.as_ref()?;
        Some(images.images(&self.film, self.stats.samples))
    }
}

/// What one strategy contributed to one camera sample: the path it made, its weight and
/// its unweighted contribution (visibility included). The strategy images are made of
/// these, and tests read them to check the weights path by path.
pub struct StrategyEvent<'p, 'a> {
    pub s: usize,
    pub t: usize,
    /// The subpaths the strategy joined (their first s and t vertices), and the endpoint it
    /// sampled itself in place of the first vertex of one of them (s = 1 or t = 1).
    pub light_path: &'p [Vertex<'a>],
    pub camera_path: &'p [Vertex<'a>],
    pub sampled: Option<&'p Sampled<'a>>,
    pub weight: f32,
    pub value: Rgb,
    /// Where a t = 1 contribution lands; None for the camera sample's own pixel.
    pub raster: Option<Vec2>,
}

/// What one tile of one pass produced.
struct TileResult {
    tile: FilmTile,
    splats: SplatList,
    rays: u64,
    invalid: u64,
    /// The strategy images' share (with `strategies=true`).
    strategies: strategy_images::TileRecords,
}

/// Per-thread buffers reused by every camera sample: no allocation per sample.
#[derive(Default)]
struct Scratch<'a> {
    camera_path: Vec<Vertex<'a>>,
    light_path: Vec<Vertex<'a>>,
    densities: Vec<PathDensity>,
}

impl Bdpt {
    fn walk_limits(&self, light: bool) -> WalkLimits {
        let max_depth = self
            .settings
            .path
            .max_depth
            .map_or(usize::MAX / 4, |d| d as usize);
        WalkLimits {
            // The light's own vertex counts on the light side.
            max_vertices: if light {
                max_depth.saturating_sub(1)
            } else {
                max_depth
            },
            rr_depth: self.settings.path.rr_depth,
        }
    }

    /// One camera sample along `ray`: both subpaths, every strategy. Returns the pixel's
    /// value; splats go to `splats`. `observe` sees every strategy that contributes; with
    /// `every_strategy`, also those whose weight is 0 (their visibility is tested anyway).
    #[allow(clippy::too_many_arguments)]
    fn sample<'a>(
        &self,
        scene: &'a Scene,
        ray: Ray,
        sampler: &mut CameraSampler,
        scratch: &mut Scratch<'a>,
        splats: &mut SplatList,
        counts: &mut (u64, u64),
        every_strategy: bool,
        mut observe: impl FnMut(&StrategyEvent),
    ) -> Rgb {
        let Scratch {
            camera_path,
            light_path,
            densities,
        } = scratch;
        let (rays, invalid) = counts;
        *rays += camera_subpath(scene, ray, sampler, self.walk_limits(false), camera_path);
        let (start, light_rays) = light_subpath(scene, sampler, self.walk_limits(true), light_path);
        *rays += light_rays;
        let settings = &self.settings;
        let max_vertices = self.walk_limits(false).max_vertices.saturating_add(1);
        let mut pixel = Rgb::BLACK;
        for t in 1..=camera_path.len() {
            for s in 0..=light_path.len() {
                if s + t < 2 || s + t > max_vertices || (s == 0 && t == 1) {
                    continue;
                }
                let hide = settings.path.hide_emitters;
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
                    continue;
                };
                if c.value.is_black() {
                    continue;
                }
                let w = connection::weight(
                    scene,
                    light_path,
                    camera_path,
                    c.sampled.as_ref(),
                    s,
                    t,
                    settings.mis,
                    hide,
                    densities,
                );
                let value = c.value * w;
                if value.is_black() && !every_strategy {
                    continue;
                }
                if !c.value.is_valid_radiance() || !value.is_valid_radiance() {
                    *invalid += 1;
                    continue;
                }
                if let Some(shadow) = &c.shadow {
                    *rays += 1;
                    if scene.geometry.occluded(shadow) {
                        continue;
                    }
                }
                observe(&StrategyEvent {
                    s,
                    t,
                    light_path: &light_path[..s],
                    camera_path: &camera_path[..t],
                    sampled: c.sampled.as_ref(),
                    weight: w,
                    value: c.value,
                    raster: c.raster,
                });
                match c.raster {
                    Some(raster) => splats.push(raster, value),
                    None => pixel += value,
                }
            }
        }
        pixel
    }

    /// Runs the camera sample `index` of pixel (x, y) as `run_pass` does for pass `index`
    /// (the same random numbers), calling `observe` for every strategy that contributes,
    /// including those of weight 0. For tests and diagnostics.
    pub fn observe_sample(
        &self,
        scene: &Scene,
        (x, y): (u32, u32),
        index: u32,
        mut observe: impl FnMut(&StrategyEvent),
    ) {
        let camera = &scene.camera;
        let mut sampler = CameraSampler::new(self.seed, self.pixel_samples.clone())
            .with_lens_samples(camera.has_lens());
        let (_, ray) = start_camera_sample(camera, &mut sampler, x, y, index);
        let mut scratch = Scratch::default();
        let mut splats = SplatList::new();
        self.sample(
            scene,
            ray,
            &mut sampler,
            &mut scratch,
            &mut splats,
            &mut (0, 0),
            true,
            &mut observe,
        );
    }

    /// One tile of one pass.
    fn render_tile(
        &self,
        scene: &Scene,
        rect: crate::film::PixelRect,
        pass_index: u32,
    ) -> TileResult {
        let mut out = TileResult {
            tile: self.film.tile(rect),
            splats: SplatList::new(),
            rays: 0,
            invalid: 0,
            strategies: strategy_images::TileRecords::default(),
        };
        let camera = &scene.camera;
        let mut sampler = CameraSampler::new(self.seed, self.pixel_samples.clone())
            .with_lens_samples(camera.has_lens());
        let mut scratch = Scratch::default();
        let mut counts = (0u64, 0u64);
        for y in rect.y0..rect.y1 {
            for x in rect.x0..rect.x1 {
                let (raster, ray) = start_camera_sample(camera, &mut sampler, x, y, pass_index);
                let value = match &self.strategy_images {
                    None => self.sample(
                        scene,
                        ray,
                        &mut sampler,
                        &mut scratch,
                        &mut out.splats,
                        &mut counts,
                        false,
                        |_| {},
                    ),
                    Some(images) => {
                        let records = &mut out.strategies;
                        records.start_sample();
                        let value = self.sample(
                            scene,
                            ray,
                            &mut sampler,
                            &mut scratch,
                            &mut out.splats,
                            &mut counts,
                            true,
                            |e| records.record(images, e, raster),
                        );
                        records.end_sample(value.is_valid_radiance());
                        value
                    }
                };
                if value.is_valid_radiance() {
                    out.tile.add_sample(raster, value);
                } else {
                    counts.1 += 1;
                }
            }
        }
        (out.rays, out.invalid) = counts;
        out
    }
}

impl Estimator for Bdpt {
    fn name(&self) -> &str {
        "bdpt"
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        let rects = self.film.tiles(TILE_SIZE);
        let results: Vec<TileResult> = rects
            .par_iter()
            .map(|&rect| self.render_tile(scene, rect, pass_index))
            .collect();
        for r in results {
            self.film.merge_tile(&r.tile);
            self.film.merge_splats(&r.splats);
            if let Some(images) = &mut self.strategy_images {
                images.merge(&r.strategies);
            }
            self.stats.rays += r.rays;
            self.stats.invalid_samples += r.invalid;
            self.film.recycle(r.tile);
        }
        self.stats.passes += 1;
        self.stats.samples += self.film.width() as u64 * self.film.height() as u64;
    }

    fn image(&self) -> Image {
        // One light subpath per camera sample.
        self.film.image_with_light_paths(self.stats.samples)
    }

    fn stats(&self) -> Stats {
        self.stats.clone()
    }

    fn keeps_strategy_images(&self) -> bool {
        self.strategy_images.is_some()
    }

    fn strategy_images(&self) -> Option<Vec<StrategyImage>> {
        Bdpt::strategy_images(self)
    }
}
