//! Sixteen camera paths side by side: `PathState` with each field as sixteen lanes, so the
//! wavefront (`wavefront.rs`) can advance all paths with lane arithmetic, and move any one
//! of them out to the scalar code and back (`get` / `put`).

use glam::Vec3;

use super::{PathState, PreviousVertex};
use crate::geometry::Ray;
use crate::geometry::packet::RayLanes;
use crate::math::Rgb;
use crate::math::lanes::{F32x16, LANES, Mask16, U32x16, V3};
use crate::path::random_walk::Walk;
use crate::sampler::lane_streams::LaneStreams;

/// Lane `i` of `v`.
#[inline(always)]
pub(super) fn lane(v: F32x16, i: usize) -> f32 {
    v.to_array()[i]
}

/// `v` with lane `i` replaced by `x`.
#[inline(always)]
pub(super) fn with_lane(v: F32x16, i: usize, x: f32) -> F32x16 {
    F32x16::select(Mask16(1 << i), F32x16::splat(x), v)
}

/// Lane `i` of a lane vector as a `Vec3`.
#[inline(always)]
pub(super) fn lane3(v: &V3<F32x16>, i: usize) -> Vec3 {
    Vec3::new(lane(v.x, i), lane(v.y, i), lane(v.z, i))
}

/// Replaces lane `i` of `v` by `x`.
#[inline(always)]
pub(super) fn put3(v: &mut V3<F32x16>, i: usize, x: Vec3) {
    v.x = with_lane(v.x, i, x.x);
    v.y = with_lane(v.y, i, x.y);
    v.z = with_lane(v.z, i, x.z);
}

/// Sixteen `PathState`s (one per lane), the random stream each draws from, and which
/// camera sample each lane is tracing.
pub(super) struct PathLanes {
    /// Lanes that hold a path in progress.
    pub live: Mask16,
    /// Per lane: the index of its camera sample in the batch's queue.
    pub sample: [u32; LANES],
    pub origin: V3<F32x16>,
    pub direction: V3<F32x16>,
    pub t_max: F32x16,
    /// Throughput (r, g, b).
    pub throughput: V3<F32x16>,
    pub eta: F32x16,
    pub prev_p: V3<F32x16>,
    pub prev_pdf: F32x16,
    pub prev_specular: Mask16,
    pub shows_emitters: Mask16,
    pub shows_environment: Mask16,
    pub depth: U32x16,
    pub rays: U32x16,
    pub streams: LaneStreams,
}

impl Default for PathLanes {
    fn default() -> Self {
        let zero = F32x16::splat(0.0);
        let zero3 = V3 {
            x: zero,
            y: zero,
            z: zero,
        };
        PathLanes {
            live: Mask16::NONE,
            sample: [0; LANES],
            origin: zero3,
            direction: zero3,
            t_max: zero,
            throughput: zero3,
            eta: zero,
            prev_p: zero3,
            prev_pdf: zero,
            prev_specular: Mask16::NONE,
            shows_emitters: Mask16::NONE,
            shows_environment: Mask16::NONE,
            depth: U32x16::splat(0),
            rays: U32x16::splat(0),
            streams: LaneStreams::default(),
        }
    }
}

impl PathLanes {
    /// Lanes `m` start paths along camera rays `rays` (as `PathSample::start`), emitters
    /// and the environment shown to the camera unless `hide_emitters`.
    pub fn start(&mut self, m: Mask16, rays: &RayLanes, hide_emitters: bool) {
        let one = F32x16::splat(1.0);
        self.origin = V3::select(m, rays.o, self.origin);
        self.direction = V3::select(m, rays.d, self.direction);
        self.t_max = F32x16::select(m, rays.t_max, self.t_max);
        self.throughput = V3::select(m, V3::new(one, one, one), self.throughput);
        self.eta = F32x16::select(m, one, self.eta);
        self.prev_p = V3::select(m, rays.o, self.prev_p);
        self.prev_pdf = F32x16::select(m, one, self.prev_pdf);
        self.prev_specular |= m;
        if hide_emitters {
            self.shows_emitters &= !m;
            self.shows_environment &= !m;
        } else {
            self.shows_emitters |= m;
            self.shows_environment |= m;
        }
        self.depth = U32x16::select(m, U32x16::splat(0), self.depth);
        self.rays = U32x16::select(m, U32x16::splat(0), self.rays);
        self.live |= m;
    }

    /// The path in lane `i`. Its radiance so far is its sample's (`wavefront.rs`): here
    /// black.
    pub fn get(&self, i: usize) -> PathState {
        let rgb = |v: &V3<F32x16>| {
            let c = lane3(v, i);
            Rgb::new(c.x, c.y, c.z)
        };
        PathState {
            walk: Walk {
                ray: Ray {
                    o: lane3(&self.origin, i),
                    d: lane3(&self.direction, i),
                    t_max: lane(self.t_max, i),
                },
                beta: rgb(&self.throughput),
                eta: lane(self.eta, i),
                depth: self.depth.to_array()[i],
            },
            result: Rgb::BLACK,
            prev: PreviousVertex {
                shows_emitters: self.shows_emitters.get(i),
                shows_environment: self.shows_environment.get(i),
                p: lane3(&self.prev_p, i),
                bsdf_pdf: lane(self.prev_pdf, i),
                specular: self.prev_specular.get(i),
            },
            rays: self.rays.to_array()[i] as u64,
        }
    }

    /// Lane `i` holds path `state` from now on (all but its radiance so far, which its
    /// sample keeps).
    pub fn put(&mut self, i: usize, state: &PathState) {
        let rgb = |c: Rgb| Vec3::new(c.r(), c.g(), c.b());
        let walk = &state.walk;
        put3(&mut self.origin, i, walk.ray.o);
        put3(&mut self.direction, i, walk.ray.d);
        self.t_max = with_lane(self.t_max, i, walk.ray.t_max);
        put3(&mut self.throughput, i, rgb(walk.beta));
        self.eta = with_lane(self.eta, i, walk.eta);
        self.shows_emitters.set(i, state.prev.shows_emitters);
        self.shows_environment.set(i, state.prev.shows_environment);
        put3(&mut self.prev_p, i, state.prev.p);
        self.prev_pdf = with_lane(self.prev_pdf, i, state.prev.bsdf_pdf);
        self.prev_specular.set(i, state.prev.specular);
        let m = Mask16(1 << i);
        self.depth = U32x16::select(m, U32x16::splat(walk.depth), self.depth);
        // A camera path casts at most a few thousand rays (max_depth bounds it, Russian
        // roulette ends unbounded ones): u32 holds any count a path reaches.
        let rays = state.rays.min(u32::MAX as u64) as u32;
        self.rays = U32x16::select(m, U32x16::splat(rays), self.rays);
    }
}
