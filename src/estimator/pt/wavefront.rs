//! `pt` sixteen paths at a time: a wavefront in SIMD lanes.
//!
//! A task takes a batch of consecutive tiles and queues their camera samples. Sixteen
//! lanes each trace one path; every round advances all of them by one vertex (closest
//! hit, emission, scattering), and a lane whose path has ended takes the next sample from
//! the queue, so the lanes stay full until the queue runs dry.
//!
//! Each path draws its random numbers from its own stream (a lane of `LaneStreams`,
//! continuing the camera sample's `CameraSampler`), performs the scalar path tracer's
//! operations in the same order, and its result is added to its tile in the queue's order.
//! So the image is the scalar `pt`'s, bit for bit (`tests/pt.rs` checks it on every
//! built-in scene); the wavefront changes only the speed. What the lane code does not
//! cover is done by the scalar code for that lane (`PathSample::arrive` / `scatter`).

use std::cell::RefCell;

use glam::Vec2;

use super::PathSample;
use super::PathState;
use super::hit_lanes::HitLanes;
use super::lane_scene::NO_LIGHT;
use super::lane_share::Coverage;
use super::next_event_lanes::power_heuristic_lanes;
use super::path_lanes::PathLanes;
use super::shadow_queue::ShadowQueue;
use crate::camera::raster_in_pixel_lanes;
use crate::estimator::camera_pass::{FinishedTile, PassContext, PassCounts, start_camera_sample};
use crate::film::PixelRect;
use crate::geometry::packet::RayLanes;
use crate::math::Rgb;
use crate::math::lanes::{F32x16, LANES, Mask16, U32x16};
use crate::sampler::IndependentSampler;
use crate::sampler::pixel_samples::PixelSamples;
use crate::scene::Scene;

/// Tiles of 16×16 pixels per task: 1024 paths keep the lanes full for most of a batch.
pub(super) const TILES_PER_TASK: usize = 4;

/// One camera sample of a batch: where it is, the radiance its path has found so far, and
/// the rays it cast.
#[derive(Clone, Copy)]
pub(super) struct QueuedSample {
    pixel: (u32, u32),
    /// The pass: the sample's index among its pixel's samples.
    pass: u32,
    raster: Vec2,
    pub value: Rgb,
    rays: u64,
}

impl PathSample {
    /// `CameraSampleFn::render_tiles` for `pt`: the same tiles, traced in lanes (the samples
    /// of all passes of `ctx` in one queue).
    pub(super) fn render_tiles_in_lanes(
        &self,
        ctx: &PassContext,
        rects: &[PixelRect],
    ) -> Vec<FinishedTile<()>> {
        // Each worker thread keeps its queue from batch to batch (no allocation per batch).
        thread_local! {
            static QUEUE: RefCell<Vec<QueuedSample>> = const { RefCell::new(Vec::new()) };
            static SHADOWS: RefCell<ShadowQueue> = RefCell::new(ShadowQueue::default());
        }
        QUEUE.with_borrow_mut(|queue| {
            SHADOWS.with_borrow_mut(|shadows| {
                queue.clear();
                // Pass by pass, tile by tile, row by row: the order `render_tile` takes them.
                for pass in ctx.passes.clone() {
                    queue.extend(
                        rects
                            .iter()
                            .flat_map(|r| {
                                (r.y0..r.y1).flat_map(move |y| (r.x0..r.x1).map(move |x| (x, y)))
                            })
                            .map(|pixel| QueuedSample {
                                pixel,
                                pass,
                                raster: Vec2::ZERO,
                                value: Rgb::BLACK,
                                rays: 0,
                            }),
                    );
                }
                self.trace_queue(ctx, queue, shadows);
                // Finished samples go to their tiles in queue order, as `render_tile` adds them.
                let mut samples = queue.iter();
                ctx.passes
                    .clone()
                    .flat_map(|_| rects.iter())
                    .map(|&rect| {
                        let mut tile = ctx.film.tile(rect);
                        let mut counts = PassCounts::default();
                        let n = ((rect.x1 - rect.x0) * (rect.y1 - rect.y0)) as usize;
                        for q in samples.by_ref().take(n) {
                            counts.add_sample(&mut tile, q.raster, q.value, q.rays);
                        }
                        FinishedTile {
                            tile,
                            counts,
                            extra: (),
                        }
                    })
                    .collect()
            })
        })
    }

    /// Traces every camera sample of `queue` in lanes, filling in its result.
    fn trace_queue(
        &self,
        pass: &PassContext,
        queue: &mut [QueuedSample],
        shadows: &mut ShadowQueue,
    ) {
        debug_assert!(shadows.is_empty());
        let mut lanes = PathLanes::default();
        let mut hits = HitLanes::default();
        let mut next = 0usize;
        let mut sampler = pass.camera_sampler();
        let mut coverage = Coverage::default();
        // Camera samples start in lanes where they can: independent pixel (and lens)
        // samples, paths of at least one segment.
        let start_in_lanes =
            matches!(**pass.pixel_samples, PixelSamples::Independent) && self.max_depth() > 0;
        loop {
            if start_in_lanes {
                next = self.start_in_lanes(pass, &mut lanes, queue, next);
            }
            // Empty lanes take the next camera samples.
            for lane in (!lanes.live).lanes() {
                while next < queue.len() && !lanes.live.get(lane) {
                    let q = &mut queue[next];
                    let (x, y) = q.pixel;
                    let (raster, ray) =
                        start_camera_sample(&pass.scene.camera, &mut sampler, x, y, q.pass);
                    q.raster = raster;
                    if self.max_depth() > 0 {
                        lanes.put(lane, &self.start(&ray));
                        lanes.streams.set_lane(lane, sampler.stream_state());
                        lanes.sample[lane] = next as u32;
                        lanes.live.set(lane, true);
                    }
                    next += 1;
                }
            }
            if lanes.live.none() {
                break;
            }
            self.advance_lanes(pass, &mut lanes, &mut hits, queue, shadows, &mut coverage);
        }
        shadows.flush(&pass.scene.geometry, queue);
        self.lane_share.add(coverage);
    }

    /// Empty lanes take the next camera samples of `queue` (from index `next`), started in
    /// lanes as `start_camera_sample` and `start` would; returns the new `next`.
    fn start_in_lanes(
        &self,
        pass: &PassContext,
        lanes: &mut PathLanes,
        queue: &mut [QueuedSample],
        mut next: usize,
    ) -> usize {
        let (mut x, mut y, mut index) = ([0u32; LANES], [0u32; LANES], [0u32; LANES]);
        let mut m = Mask16::NONE;
        for lane in (!lanes.live).lanes() {
            if next == queue.len() {
                break;
            }
            (x[lane], y[lane]) = queue[next].pixel;
            index[lane] = queue[next].pass;
            lanes.sample[lane] = next as u32;
            m.set(lane, true);
            next += 1;
        }
        if m.none() {
            return next;
        }
        let (x, y) = (U32x16::from_array(x), U32x16::from_array(y));
        lanes
            .streams
            .start_pixel_samples(m, pass.seed, x, y, U32x16::from_array(index));
        // The pixel sample, then (for a lens only) the lens sample: `start_camera_sample`.
        let camera = &pass.scene.camera;
        let (ux, uy) = lanes.streams.next_2d(m);
        let (rx, ry) = raster_in_pixel_lanes(x, y, ux, uy);
        let lens = if camera.has_lens() {
            lanes.streams.next_2d(m)
        } else {
            (F32x16::splat(0.0), F32x16::splat(0.0))
        };
        let rays = camera.sample_ray_lanes(rx, ry, lens);
        lanes.start(m, &rays, self.settings.path.hide_emitters);
        let (rx, ry) = (rx.to_array(), ry.to_array());
        for lane in m.lanes() {
            queue[lanes.sample[lane] as usize].raster = Vec2::new(rx[lane], ry[lane]);
        }
        next
    }

    /// Lane `lane`'s path for the scalar code, with its sample's radiance so far (its
    /// queued shadow rays resolved first, so that what the scalar code adds comes after).
    fn take_path(
        &self,
        scene: &Scene,
        lanes: &PathLanes,
        lane: usize,
        queue: &mut [QueuedSample],
        shadows: &mut ShadowQueue,
    ) -> PathState {
        let sample = lanes.sample[lane];
        shadows.resolve(sample, &scene.geometry, queue);
        let mut state = lanes.get(lane);
        state.result = queue[sample as usize].value;
        state
    }

    /// Puts back a path `take_path` took, after the scalar code advanced it.
    fn give_back(
        lanes: &mut PathLanes,
        lane: usize,
        state: &PathState,
        queue: &mut [QueuedSample],
    ) {
        queue[lanes.sample[lane] as usize].value = state.result;
        lanes.put(lane, state);
    }

    /// The emission `arrive` adds for the lanes of `emitter` (hitting the area light
    /// `light` of their shape, emitters shown): computed in lanes and queued in order with
    /// the shadow rays (`ShadowQueue`, a term without a ray). Returns the lanes left to the
    /// scalar code (lights whose emission is not done in lanes).
    fn emission_in_lanes(
        &self,
        scene: &Scene,
        lanes: &PathLanes,
        hits: &HitLanes,
        light: U32x16,
        emitter: Mask16,
        shadows: &mut ShadowQueue,
    ) -> Mask16 {
        let mut scalar = Mask16::NONE;
        let towards_camera = -lanes.direction.normalize();
        let chosen = light.to_array();
        let mut todo = emitter;
        while let Some(first) = todo.lanes().next() {
            let same = todo & light.eq(U32x16::splat(chosen[first]));
            todo &= !same;
            let index = chosen[first] as usize;
            let Some(e) = scene.lights.get(index).emission_lanes(
                hits.p,
                hits.ng,
                hits.ns,
                towards_camera,
                lanes.prev_p,
            ) else {
                scalar |= same;
                continue;
            };
            // `arrive` adds nothing where `le` is black: behind the light, or a light of
            // zero radiance.
            let zero = F32x16::splat(0.0);
            let black = e.radiance.x.eq(zero) & e.radiance.y.eq(zero) & e.radiance.z.eq(zero);
            let adds = same & e.emits & !black;
            // `emission_weight`: 1 after a camera ray or a delta component, else the power
            // heuristic against choosing this light and sampling the point.
            let pdf_light = F32x16::splat(scene.lights.pmf(index)) * e.pdf_li;
            let weight = F32x16::select(
                lanes.prev_specular,
                F32x16::splat(1.0),
                power_heuristic_lanes(lanes.prev_pdf, pdf_light, adds & !lanes.prev_specular),
            );
            let term = lanes.throughput.mul_v(e.radiance) * weight;
            let no_ray = RayLanes {
                o: lanes.origin,
                d: lanes.direction,
                t_max: zero,
            };
            shadows.push(
                adds,
                &no_ray,
                &term,
                &term,
                U32x16::from_array(lanes.sample),
            );
        }
        scalar
    }

    /// Advances every live lane by one vertex; lanes whose path ends write it to `queue`.
    #[inline(always)]
    fn advance_lanes(
        &self,
        pass: &PassContext,
        lanes: &mut PathLanes,
        hits: &mut HitLanes,
        queue: &mut [QueuedSample],
        shadows: &mut ShadowQueue,
        coverage: &mut Coverage,
    ) {
        let scene = pass.scene;
        coverage.vertices += lanes.live.count() as u64;
        let tables = self
            .lane_scene
            .as_ref()
            .expect("pt built its lane tables with the wavefront on");
        let live = lanes.live;
        let one = U32x16::splat(1);
        let zero = U32x16::splat(0);

        // The closest hits.
        hits.trace(scene, lanes);
        lanes.rays = lanes.rays + U32x16::select(live, one, zero);

        // Arriving (`arrive`): emission found by the rays, in lanes for area lights on
        // meshes and disks and for lights at infinity; other emitters by the scalar code.
        // Every hit lane then checks the depth.
        let light = U32x16::gather(&tables.light, hits.shape, hits.hit);
        let emitter = hits.hit & !light.eq(U32x16::splat(NO_LIGHT)) & lanes.shows_emitters;
        let scalar_emitters = self.emission_in_lanes(scene, lanes, hits, light, emitter, shadows);
        // An escaped ray ends the path; only the environment's lights add to it.
        let escaped = live & !hits.hit;
        let mut ended = escaped;
        let sees_environment = if scene.lights.environment().is_empty() {
            Mask16::NONE
        } else {
            escaped & lanes.shows_environment
        };
        self.environment_in_lanes(scene, lanes, sees_environment, shadows);
        coverage.scalar += scalar_emitters.count() as u64;
        for lane in scalar_emitters.lanes() {
            let mut state = self.take_path(scene, lanes, lane, queue, shadows);
            if !self.arrive(scene, &mut state, hits.interaction(scene, lane).as_ref()) {
                ended.set(lane, true);
            }
            Self::give_back(lanes, lane, &state, queue);
        }
        let deep = !(lanes.depth + one).lt(U32x16::splat(self.max_depth()));
        ended |= hits.hit & !scalar_emitters & deep;

        // Scattering: diffuse and smooth specular surfaces in lanes, the other BSDFs in lanes
        // around their scalar calls, `null` ones one by one.
        let going = live & !ended;
        let diffuse = going & U32x16::gather(&tables.diffuse, hits.shape, going).eq(one);
        ended |= self.scatter_diffuse(scene, tables, lanes, hits, diffuse, shadows);
        let specular = if tables.specular.any {
            let kind = U32x16::gather(&tables.specular.kind, hits.shape, going & !diffuse);
            going & !diffuse & !kind.eq(zero)
        } else {
            Mask16::NONE
        };
        if specular.any() {
            ended |= self.scatter_specular(&tables.specular, lanes, hits, specular);
        }
        // Every other BSDF but `null`: in lanes around the scalar BSDF calls.
        let rest = going & !diffuse & !specular;
        let general = rest & U32x16::gather(&tables.general, hits.shape, rest).eq(one);
        if general.any() {
            ended |= self.scatter_general(scene, lanes, hits, general, shadows);
        }
        shadows.cast_full(&scene.geometry, queue);
        let scalar = rest & !general;
        coverage.scalar += scalar.count() as u64;
        for lane in scalar.lanes() {
            let mut state = self.take_path(scene, lanes, lane, queue, shadows);
            let mut sampler = IndependentSampler::with_state(0, lanes.streams.lane(lane));
            let si = hits
                .interaction(scene, lane)
                .expect("a lane that scatters has a hit");
            if !self.scatter(scene, &mut state, &si, &mut sampler) {
                ended.set(lane, true);
            }
            Self::give_back(lanes, lane, &state, queue);
            lanes.streams.set_lane(lane, sampler.state());
        }

        // Finished paths leave their lanes (their samples hold their radiance; shadow rays
        // still queued add to it later).
        let rays = lanes.rays.to_array();
        for lane in ended.lanes() {
            queue[lanes.sample[lane] as usize].rays = rays[lane] as u64;
        }
        lanes.live = live & !ended;
    }
}
