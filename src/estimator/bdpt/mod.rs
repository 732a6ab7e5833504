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

use super::Params;
use super::camera_pass::{CameraEstimator, CameraSampleFn, start_camera_sample};
use crate::error::{Error, Result};
use crate::film::{Film, SplatList};
use crate::geometry::Ray;
use crate::geometry::packet::RayLanes;
use crate::math::Rgb;
use crate::math::lanes::{LANES, Mask16};
use crate::path::connection::{
    self, Connection, ConnectionEnds, EndpointDensities, Sampled, SubpathWeights,
};
pub use crate::path::mis::Heuristic;
use crate::path::settings::PathSettings;
use crate::path::subpath::{camera_subpath, light_subpath};
use crate::path::vertex::Vertex;
use crate::sampler::pixel_samples::CameraSampler;
use crate::sampler::{Sampler, Stream};
use crate::scene::Scene;

/// The longest path length `strategies_max_depth` may ask for: (L + 1)(L + 2) − 2 images.
const MAX_STRATEGIES_DEPTH: u32 = 16;

/// `bdpt`'s settings: the path settings, `mis`, and the strategy images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BdptSettings {
    pub path: PathSettings,
    pub mis: Heuristic,
    /// Also write one image per strategy (s, t), weighted and unweighted (`render` only).
    pub strategies: bool,
    /// The longest path length (segments) that gets strategy images, whatever `max_depth`.
    pub strategies_max_depth: u32,
}

impl BdptSettings {
    pub fn from_params(params: &Params, scene: &Scene) -> Result<BdptSettings> {
        let path = PathSettings::from_params(params, scene)?;
        let mis = mis_from_params(params)?;
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

/// The `mis` parameter: `balance` (the default) or `power`.
pub fn mis_from_params(params: &Params) -> Result<Heuristic> {
    match params.get("mis", "balance".to_string())?.as_str() {
        "balance" => Ok(Heuristic::Balance),
        "power" => Ok(Heuristic::Power),
        other => Err(Error::usage(format!(
            "--set mis={other}: expected balance or power"
        ))),
    }
}

/// The `bdpt` estimator: camera samples (`camera_pass`) of `BdptSample`.
pub type Bdpt = CameraEstimator<BdptSample>;

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
    CameraEstimator::new(
        "bdpt",
        scene,
        seed,
        BdptSample {
            settings,
            strategy_images,
        },
    )
}

/// One camera sample of `bdpt`: both subpaths, every strategy.
pub struct BdptSample {
    settings: BdptSettings,
    /// With `strategies=true`.
    strategy_images: Option<StrategyImages>,
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

/// What a tile's samples add beyond their pixels.
#[derive(Default)]
pub struct BdptTile {
    /// Light tracing's contributions (t = 1), in the order they were made.
    splats: SplatList,
    /// Contributions dropped as not finite.
    invalid: u64,
    /// The strategy images' share (with `strategies=true`).
    strategies: strategy_images::TileRecords,
}

/// Buffers reused by every camera sample of a tile: no allocation per sample.
#[derive(Default)]
pub struct Scratch<'a> {
    camera_path: Vec<Vertex<'a>>,
    light_path: Vec<Vertex<'a>>,
    weights: SubpathWeights,
    /// Connections waiting for their visibility test (`BdptSample::settle`).
    group: ConnectionGroup<'a>,
}

impl<'a> Scratch<'a> {
    /// The last camera sample's camera subpath.
    pub fn camera_path(&self) -> &[Vertex<'a>] {
        &self.camera_path
    }

    /// The last camera sample's light subpath.
    pub fn light_path(&self) -> &[Vertex<'a>] {
        &self.light_path
    }
}

impl BdptSample {
    /// One camera sample's strategies under `settings`, without strategy images (for
    /// estimators that evaluate samples through their own sampler: `pssmlt base=bdpt`).
    pub fn without_images(settings: BdptSettings) -> BdptSample {
        BdptSample {
            settings: BdptSettings {
                strategies: false,
                ..settings
            },
            strategy_images: None,
        }
    }

    pub fn settings(&self) -> &BdptSettings {
        &self.settings
    }

    /// The most vertices a walk adds to a subpath: `max_depth` on the camera side (the
    /// camera point and those vertices make paths of at most `max_depth` segments), one
    /// fewer on the light side, whose light vertex counts.
    fn max_walk_vertices(&self, light: bool) -> usize {
        let max_depth = self.settings.path.max_segments() as usize;
        if light {
            max_depth.saturating_sub(1)
        } else {
            max_depth
        }
    }

    /// One camera sample along `ray`: both subpaths, every strategy. Returns the pixel's
    /// value; splats go to `splats`. `observe` sees every strategy that contributes; with
    /// `every_strategy`, also those whose weight is 0 (their visibility is tested anyway).
    #[allow(clippy::too_many_arguments)]
    pub fn trace<'a>(
        &self,
        scene: &'a Scene,
        ray: Ray,
        sampler: &mut impl Sampler,
        scratch: &mut Scratch<'a>,
        splats: &mut SplatList,
        counts: &mut (u64, u64),
        every_strategy: bool,
        mut observe: impl FnMut(&StrategyEvent),
    ) -> Rgb {
        let Scratch {
            camera_path,
            light_path,
            weights,
            group,
        } = scratch;
        let (rays, invalid) = counts;
        let rr_depth = self.settings.path.rr_depth;
        let camera_vertices = self.max_walk_vertices(false);
        // The camera stream began with the camera sample's raster position.
        *rays += camera_subpath(scene, ray, camera_vertices, rr_depth, sampler, camera_path);
        sampler.start_stream(Stream::Light);
        let light_vertices = self.max_walk_vertices(true);
        let (start, light_rays) =
            light_subpath(scene, light_vertices, rr_depth, sampler, light_path);
        *rays += light_rays;
        sampler.start_stream(Stream::Connect);
        let settings = &self.settings;
        weights.fill(light_path, camera_path, settings.mis);
        let max_vertices = camera_vertices.saturating_add(1);
        let hide = settings.path.hide_emitters;
        let mut tally = Tally {
            pixel: Rgb::BLACK,
            rays,
            invalid,
            splats,
            every_strategy,
            observe: &mut observe,
        };
        // Connections wait in groups of sixteen so that their shadow rays are cast together
        // (`Geometry::occluded_lanes`: sixteen rays per triangle test on a small scene);
        // each group is then weighed in strategy order, so sums and splats keep their order.
        for t in 1..=camera_path.len() {
            for s in 0..=light_path.len() {
                if s + t < 2 || s + t > max_vertices || (s == 0 && t == 1) {
                    continue;
                }
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
                if !c.value.is_valid_radiance() {
                    *tally.invalid += 1;
                    continue;
                }
                group.push(s, t, c);
                if group.is_full() {
                    self.settle(scene, light_path, camera_path, weights, group, &mut tally);
                }
            }
        }
        self.settle(scene, light_path, camera_path, weights, group, &mut tally);
        tally.pixel
    }

    /// Tests the visibility of `group`'s connections (as one packet of shadow rays), then
    /// weighs the visible ones in order and adds them to the pixel or the splats; empties
    /// the group.
    fn settle<'a>(
        &self,
        scene: &'a Scene,
        light_path: &[Vertex<'a>],
        camera_path: &[Vertex<'a>],
        weights: &SubpathWeights,
        group: &mut ConnectionGroup<'a>,
        tally: &mut Tally<'_, impl FnMut(&StrategyEvent)>,
    ) {
        if group.entries.is_empty() {
            return;
        }
        // Visibility before the weights: their densities are spent only on connections
        // that carry light.
        let blocked = group.cast_shadows(scene, tally.rays);
        let settings = &self.settings;
        for (k, c) in group.entries.iter().enumerate() {
            if blocked.get(k) {
                continue;
            }
            let (s, t) = (c.s as usize, c.t as usize);
            let sampled = c.sampled.map(|i| &group.sampled[i as usize]);
            let ends = ConnectionEnds {
                sampled,
                densities: c.densities,
            };
            let w = connection::weight(
                scene,
                light_path,
                camera_path,
                ends,
                s,
                t,
                settings.mis,
                settings.path.hide_emitters,
                weights,
            );
            let value = c.value * w;
            if value.is_black() && !tally.every_strategy {
                continue;
            }
            if !value.is_valid_radiance() {
                *tally.invalid += 1;
                continue;
            }
            (tally.observe)(&StrategyEvent {
                s,
                t,
                light_path: &light_path[..s],
                camera_path: &camera_path[..t],
                sampled,
                weight: w,
                value: c.value,
                raster: c.raster,
            });
            match c.raster {
                Some(raster) => tally.splats.push(raster, value),
                None => tally.pixel += value,
            }
        }
        group.clear();
    }
}

/// What a camera sample's strategies add up to, and where they go.
struct Tally<'x, F> {
    pixel: Rgb,
    rays: &'x mut u64,
    invalid: &'x mut u64,
    splats: &'x mut SplatList,
    every_strategy: bool,
    observe: &'x mut F,
}

/// Up to sixteen connections waiting for their visibility test, in the order they were
/// made. The endpoints that s = 1 and t = 1 strategies sample are kept apart, in
/// `sampled`: a vertex is most of a connection's size, and copying whole connections
/// into the group cost a few percent of `bdpt`.
#[derive(Default)]
struct ConnectionGroup<'a> {
    entries: Vec<WaitingConnection>,
    sampled: Vec<Sampled<'a>>,
}

/// A connection of strategy (s, t) without its sampled endpoint (`sampled`: its index in
/// the group's list).
struct WaitingConnection {
    s: u32,
    t: u32,
    value: Rgb,
    shadow: Option<Ray>,
    raster: Option<Vec2>,
    densities: EndpointDensities,
    sampled: Option<u32>,
}

impl<'a> ConnectionGroup<'a> {
    #[inline(always)]
    fn push(&mut self, s: usize, t: usize, c: Connection<'a>) {
        let sampled = c.sampled.map(|v| {
            self.sampled.push(v);
            self.sampled.len() as u32 - 1
        });
        self.entries.push(WaitingConnection {
            s: s as u32,
            t: t as u32,
            value: c.value,
            shadow: c.shadow,
            raster: c.raster,
            densities: c.densities,
            sampled,
        });
    }

    fn is_full(&self) -> bool {
        self.entries.len() == LANES
    }

    fn clear(&mut self) {
        self.entries.clear();
        self.sampled.clear();
    }

    /// The entries whose shadow ray is blocked (counting each ray cast in `rays`).
    fn cast_shadows(&self, scene: &Scene, rays: &mut u64) -> Mask16 {
        let (shadows, m) = RayLanes::from_rays(self.entries.len(), |k| self.entries[k].shadow);
        if m.none() {
            return Mask16::NONE;
        }
        *rays += m.count() as u64;
        scene.geometry.occluded_lanes(&shadows, m)
    }
}

impl Bdpt {
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
        let mut sampler = self.camera_sampler(scene);
        let (_, ray) = start_camera_sample(&scene.camera, &mut sampler, x, y, index);
        let mut scratch = Scratch::default();
        let mut splats = SplatList::new();
        self.sample_fn().trace(
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
}

impl CameraSampleFn for BdptSample {
    type Scratch<'a> = Scratch<'a>;
    type Extra = BdptTile;

    fn radiance<'a>(
        &self,
        scene: &'a Scene,
        ray: &Ray,
        raster: Vec2,
        sampler: &mut CameraSampler,
        scratch: &mut Scratch<'a>,
        tile: &mut BdptTile,
    ) -> (Rgb, u64) {
        let mut counts = (0u64, 0u64);
        let value = match &self.strategy_images {
            None => self.trace(
                scene,
                *ray,
                sampler,
                scratch,
                &mut tile.splats,
                &mut counts,
                false,
                |_| {},
            ),
            Some(images) => {
                let records = &mut tile.strategies;
                records.start_sample();
                let value = self.trace(
                    scene,
                    *ray,
                    sampler,
                    scratch,
                    &mut tile.splats,
                    &mut counts,
                    true,
                    |e| records.record(images, e, raster),
                );
                records.end_sample(value.is_valid_radiance());
                value
            }
        };
        tile.invalid += counts.1;
        (value, counts.0)
    }

    fn merge_extra(&mut self, film: &mut Film, tile: &mut BdptTile) -> u64 {
        film.merge_splats(&tile.splats);
        if let Some(images) = &mut self.strategy_images {
            images.merge(&tile.strategies);
        }
        tile.invalid
    }

    fn splats(&self) -> bool {
        true
    }

    fn keeps_strategy_images(&self) -> bool {
        self.strategy_images.is_some()
    }

    fn strategy_images(&self, film: &Film, samples: u64) -> Option<Vec<StrategyImage>> {
        Some(self.strategy_images.as_ref()?.images(film, samples))
    }
}
