//! `lt`: light tracing (particle tracing). Paths start on the lights, scatter through the
//! scene by importance-transport BSDF sampling, and every vertex is joined to the camera;
//! what reaches it is splatted onto the film where it lands (Veach 1997, §10.2: the
//! t = 1 strategies only, each with weight 1).
//!
//! * A pass traces as many light paths as the film (window) has pixels, so `--spp N`
//!   means N × pixels paths (docs/DESIGN.md §3). The image is the splats times pixels / paths:
//!   the camera's importance is normalised over the whole window, so a pixel's share of a
//!   path's contribution is 1/pixels of its measurement.
//! * Lights are chosen by power (`LightSet::sample`), a ray leaves the chosen light by
//!   `Light::sample_le`; the light vertex itself is joined to the camera (the emitter seen
//!   directly, skipped under `hide_emitters`), then each surface the path meets that has a
//!   non-delta component.
//! * `max_depth` counts the segments of the complete path, camera connection included
//!   (Mitsuba 3's convention: 1 = emitters seen directly); Russian roulette as `pt`, from
//!   the vertex where the light path has `rr_depth` segments.
//! * Point and spot lights are invisible to the camera, as in `pt` and Mitsuba 3 (whose
//!   camera rays never hit them); only the light they send into the scene counts.
//! * What light tracing cannot see, by construction: emitters at infinity seen directly,
//!   and whatever the camera sees through a delta reflection or refraction (a mirror, glass)
//!   or a `null` surface, since the connection to the camera is a shadow ray and delta
//!   components give 0 for it. On such scenes `lt` and `pt` differ by those paths.
//! * Determinism: paths are cut into fixed blocks, each path seeds its own random stream
//!   from (seed, pass, path index), and the blocks' splats merge in block order, so the
//!   image does not depend on the thread count.

use glam::Vec2;
use rayon::prelude::*;

use super::{Estimator, Stats};
use crate::error::Result;
use crate::film::{Film, SplatList};
use crate::geometry::Ray;
use crate::geometry::packet::RayLanes;
use crate::image::Image;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::math::lanes::LANES;
use crate::path::camera_connection::{self, CameraSplat};
use crate::path::random_walk::{Step, Walk, WalkHook, random_walk};
use crate::path::settings::PathSettings;
use crate::path::subpath::start_light;
use crate::path::vertex::{Vertex, VertexKind};
use crate::sampler::{IndependentSampler, Sampler, Stream};
use crate::scene::Scene;

/// `lt` reads the path settings: `max_depth`, `rr_depth`, `hide_emitters`.
pub type LtSettings = PathSettings;

/// Light paths per block: the unit of parallel work and of the merge order.
const PATHS_PER_BLOCK: u64 = 4096;

/// Tags the light-path streams, so that they never coincide with a camera estimator's
/// per-pixel streams of the same seed.
const STREAM_TAG: u32 = 0x4C54_0000;

/// The `lt` estimator.
pub struct LightTracer {
    film: Film,
    seed: u64,
    settings: LtSettings,
    stats: Stats,
    /// Light paths per pass: the film window's pixel count.
    paths_per_pass: u64,
    /// One splat list per block, kept across passes.
    blocks: Vec<SplatList>,
}

/// Makes `lt` for `scene` with `settings`; an error when its film does not fit in memory.
pub fn new(scene: &Scene, seed: u64, settings: LtSettings) -> Result<LightTracer> {
    let film = &scene.description.sensor.film;
    let window = film.window();
    let paths_per_pass = window.width as u64 * window.height as u64;
    Ok(LightTracer {
        film: Film::new(window.width, window.height, film.filter)?,
        seed,
        settings,
        stats: Stats::default(),
        paths_per_pass,
        blocks: Vec::new(),
    })
}

/// What one block of paths counted.
#[derive(Clone, Copy, Default)]
struct BlockCounts {
    rays: u64,
    invalid: u64,
}

impl LightTracer {
    /// Traces one light path from `sampler`'s current sample, recording its splats.
    fn trace(
        &self,
        scene: &Scene,
        sampler: &mut impl Sampler,
        splats: &mut PendingSplats,
        counts: &mut BlockCounts,
    ) {
        let max_depth = self.settings.max_segments();
        if max_depth == 0 {
            return;
        }
        sampler.start_stream(Stream::Light);
        let Some(start) = start_light(scene, sampler) else {
            return;
        };
        // s = 1: the light seen by the camera (a path of one segment).
        let u_lens = lens_sample(scene, sampler);
        if !self.settings.hide_emitters
            && let Some(splat) = camera_connection::connect_emitter(
                scene,
                scene.lights.get(start.light),
                start.pmf,
                &start.emission,
                u_lens,
            )
        {
            self.record(scene, &splat, splats, counts);
        }
        let mut hook = CameraJoin {
            tracer: self,
            scene,
            splats,
            counts,
            max_depth,
        };
        let rays = random_walk(
            scene,
            start.walk(),
            TransportMode::Importance,
            self.settings.rr_depth,
            sampler,
            &mut hook,
        );
        hook.counts.rays += rays;
    }

    /// Queues `splat` for its shadow ray (it is kept if the camera sees its vertex); a value
    /// that is NaN, infinite or negative is dropped and counted instead.
    fn record(
        &self,
        scene: &Scene,
        splat: &CameraSplat,
        splats: &mut PendingSplats,
        counts: &mut BlockCounts,
    ) {
        if !splat.value.is_valid_radiance() {
            counts.invalid += 1;
            return;
        }
        counts.rays += 1;
        splats.push(scene, splat);
    }
}

/// A block's splats, each waiting for its shadow ray until sixteen wait: they are then cast
/// as one packet (`Geometry::occluded_lanes`: sixteen rays per triangle test on a small
/// scene), and the visible ones join the block's list in the order they were made, so the
/// list is the one casting them one by one would give.
struct PendingSplats<'s> {
    splats: &'s mut SplatList,
    waiting: Vec<(Vec2, Rgb, Ray)>,
}

impl<'s> PendingSplats<'s> {
    fn new(splats: &'s mut SplatList) -> Self {
        PendingSplats {
            splats,
            waiting: Vec::with_capacity(LANES),
        }
    }

    fn push(&mut self, scene: &Scene, splat: &CameraSplat) {
        self.waiting.push((splat.raster, splat.value, splat.shadow));
        if self.waiting.len() == LANES {
            self.settle(scene);
        }
    }

    /// Casts the waiting splats' shadow rays and keeps the visible ones.
    fn settle(&mut self, scene: &Scene) {
        if self.waiting.is_empty() {
            return;
        }
        let waiting = &self.waiting;
        let (rays, m) = RayLanes::from_rays(waiting.len(), |k| Some(waiting[k].2));
        let blocked = scene.geometry.occluded_lanes(&rays, m);
        for (k, &(raster, value, _)) in waiting.iter().enumerate() {
            if !blocked.get(k) {
                self.splats.push(raster, value);
            }
        }
        self.waiting.clear();
    }
}

/// The lens point of a connection to the camera, drawn from the connection stream (two
/// numbers for a thin lens, none for a pinhole).
fn lens_sample(scene: &Scene, sampler: &mut impl Sampler) -> Vec2 {
    if !scene.camera.has_lens() {
        return Vec2::ZERO;
    }
    sampler.start_stream(Stream::Connect);
    let u = sampler.next_2d();
    sampler.start_stream(Stream::Light);
    u
}

/// Joins every vertex of a light walk to the camera (the walk's hook).
struct CameraJoin<'t, 'o, 's> {
    tracer: &'t LightTracer,
    scene: &'t Scene,
    splats: &'o mut PendingSplats<'s>,
    counts: &'o mut BlockCounts,
    max_depth: u32,
}

impl<'a> WalkHook<'a> for CameraJoin<'_, '_, '_> {
    fn arrive(&mut self, v: &Vertex<'a>, walk: &Walk, sampler: &mut impl Sampler) -> Step {
        // Joining `v` to the camera makes a path of the emitted segment, the walk's
        // scatterings and the connection.
        let segments = walk.depth.saturating_add(2);
        if segments > self.max_depth {
            return Step::Stop;
        }
        let u_lens = lens_sample(self.scene, sampler);
        if let VertexKind::Surface { si, bsdf, frame } = &v.kind
            && v.is_connectible()
            && let Some(splat) = camera_connection::connect_surface(
                self.scene, si, frame, bsdf, v.wo, walk.beta, u_lens, false,
            )
        {
            self.tracer
                .record(self.scene, &splat, self.splats, self.counts);
        }
        // The next vertex would make a path too long.
        if segments == self.max_depth {
            Step::Stop
        } else {
            Step::Continue
        }
    }
}

impl Estimator for LightTracer {
    fn name(&self) -> &str {
        "lt"
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        let n = self.paths_per_pass;
        let block_count = n.div_ceil(PATHS_PER_BLOCK) as usize;
        let mut blocks = std::mem::take(&mut self.blocks);
        blocks.resize_with(block_count, SplatList::new);
        let counts: Vec<BlockCounts> = blocks
            .par_iter_mut()
            .enumerate()
            .map(|(b, splats)| {
                splats.clear();
                let mut counts = BlockCounts::default();
                let mut sampler = IndependentSampler::new(self.seed);
                let mut pending = PendingSplats::new(splats);
                let first = b as u64 * PATHS_PER_BLOCK;
                for path in first..(first + PATHS_PER_BLOCK).min(n) {
                    sampler.start_light_path(path, STREAM_TAG, pass_index as u64);
                    self.trace(scene, &mut sampler, &mut pending, &mut counts);
                }
                pending.settle(scene);
                counts
            })
            .collect();
        for (splats, c) in blocks.iter().zip(&counts) {
            self.film.merge_splats(splats);
            self.stats.rays += c.rays;
            self.stats.invalid_samples += c.invalid;
        }
        self.blocks = blocks;
        self.stats.passes += 1;
        self.stats.samples += n;
    }

    fn image(&self) -> Image {
        self.film.image_with_light_paths(self.stats.samples)
    }

    fn stats(&self) -> Stats {
        self.stats.clone()
    }
}
