//! `pt`: unidirectional path tracing with next-event estimation, combined with BSDF
//! sampling by multiple importance sampling (power heuristic; Veach 1997, §9.2), and
//! Russian roulette. It is the reference every other estimator is judged against, so it
//! follows Mitsuba 3's `path` integrator in every convention that changes the expected
//! value:
//!
//! * `max_depth` counts path segments (1 = emitters seen directly, 2 = direct lighting,
//!   −1 = unbounded); every scattering vertex counts, specular and `null` ones too.
//! * Shadow rays stop at any surface, `null` ones included.
//! * Russian roulette from the vertex whose depth reaches `rr_depth`: the path continues
//!   with probability q = min(max(throughput) · η², 0.95), where η is the product of the
//!   relative IORs crossed so far, and the throughput is divided by q.
//!
//! Only the light-selection probabilities differ (mltbench picks lights by power, Mitsuba
//! uniformly): a different variance, the same expectation.
//!
//! The estimate for one camera path x0 x1 … is, per vertex, the emission found by the BSDF-
//! sampled ray weighted by w_bsdf and the light sample weighted by w_light, with
//! w = p_a² / (p_a² + p_b²) over the two strategies' solid-angle densities (delta lights and
//! delta BSDF samples take weight 1: the other strategy cannot produce them).

use glam::{Vec2, Vec3};

use super::Params;
mod diffuse_lanes;
mod environment_lanes;
mod general_lanes;
mod hit_lanes;
mod lane_scene;
mod lane_share;
mod next_event_lanes;
mod path_lanes;
mod shadow_queue;
mod specular_lanes;
mod walk_lanes;
mod wavefront;

use super::camera_pass::{
    CameraEstimator, CameraSampleFn, FinishedTile, PassContext, render_tiles_one_by_one,
};
use crate::error::Result;
use crate::film::PixelRect;
use crate::geometry::{Ray, SurfaceInteraction};
use crate::light::LightPoint;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::math::lanes;
use crate::path::mis::power_heuristic;
use crate::path::next_event::{self, LightChoice};
use crate::path::random_walk::Walk;
use crate::path::settings::PathSettings;
use crate::path::vertex::{Vertex, VertexKind};
use crate::sampler::Sampler;
use crate::sampler::pixel_samples::CameraSampler;
use crate::scene::Scene;

/// `pt`'s settings (`--set key=value`; defaults from the scene's `<integrator>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PtSettings {
    pub path: PathSettings,
    /// Trace sixteen paths at a time in SIMD lanes (`wavefront.rs`; the same image bits as
    /// one at a time, faster where the lanes are AVX-512 registers). The default is on
    /// where they are (`lanes::NATIVE`), off elsewhere. On a scene whose vertices the lanes
    /// mostly leave to the scalar code, batches go one path at a time (`lane_share.rs`).
    pub wavefront: bool,
}

impl PtSettings {
    /// Reads the path settings (`max_depth`, `rr_depth`, `hide_emitters`) and `wavefront`.
    pub fn from_params(params: &Params, scene: &Scene) -> Result<PtSettings> {
        Ok(PtSettings {
            path: PathSettings::from_params(params, scene)?,
            wavefront: params.get("wavefront", lanes::NATIVE)?,
        })
    }
}

/// The `pt` estimator.
pub type PathTracer = CameraEstimator<PathSample>;

/// Makes `pt` for `scene` with `settings`; an error when its film does not fit in memory.
pub fn new(scene: &Scene, seed: u64, settings: PtSettings) -> Result<PathTracer> {
    let lane_scene = settings
        .wavefront
        .then(|| lane_scene::LaneScene::new(scene));
    CameraEstimator::new(
        "pt",
        scene,
        seed,
        PathSample {
            settings,
            lane_scene,
            lane_share: Default::default(),
        },
    )
}

/// Traces one camera path.
pub struct PathSample {
    settings: PtSettings,
    /// The scene's tables for the wavefront (with `settings.wavefront`).
    lane_scene: Option<lane_scene::LaneScene>,
    /// The share of vertices the lanes leave to the scalar code, so far.
    lane_share: lane_share::LaneShare,
}

impl PathSample {
    /// `pt`'s camera path one vertex at a time (no lanes), for estimators that evaluate
    /// one path at a time through their own sampler (`pssmlt base=pt`).
    pub fn one_at_a_time(path: PathSettings) -> PathSample {
        PathSample {
            settings: PtSettings {
                path,
                wavefront: false,
            },
            lane_scene: None,
            lane_share: Default::default(),
        }
    }
}

/// What the next vertex needs to weight emission found by the BSDF-sampled ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PreviousVertex {
    /// Emission of a surface this ray hits counts (false only for a camera ray under
    /// `hide_emitters`).
    pub shows_emitters: bool,
    /// The environment counts if this ray escapes (under `hide_emitters`, false until the
    /// path has scattered at a surface that is not `null`).
    pub shows_environment: bool,
    /// Where the ray started (for the light's solid-angle density).
    pub p: Vec3,
    /// Solid-angle density of the BSDF sample.
    pub bsdf_pdf: f32,
    /// The ray came from the camera or from a delta component: no light sample could
    /// have produced it, so its emission takes weight 1.
    pub specular: bool,
}

/// One camera path between two of its vertices: the walk (the ray to trace next, the
/// throughput, the scatterings so far) and what the path has gathered.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    pub walk: Walk,
    /// Radiance found so far.
    pub result: Rgb,
    pub prev: PreviousVertex,
    /// Rays cast so far (closest hits and shadow rays).
    pub rays: u64,
}

impl PathSample {
    /// The longest path in segments (u32::MAX for unbounded).
    pub(crate) fn max_depth(&self) -> u32 {
        self.settings.path.max_segments()
    }

    /// The state of a path that starts with camera ray `ray`.
    pub(crate) fn start(&self, ray: &Ray) -> PathState {
        let hide = self.settings.path.hide_emitters;
        PathState {
            walk: Walk::new(*ray, Rgb::WHITE),
            result: Rgb::BLACK,
            prev: PreviousVertex {
                shows_emitters: !hide,
                shows_environment: !hide,
                p: ray.o,
                bsdf_pdf: 1.0,
                specular: true,
            },
            rays: 0,
        }
    }

    /// Weight of emission from light `light` at `point`, reached by the BSDF-sampled ray
    /// from `prev`.
    fn emission_weight(
        &self,
        scene: &Scene,
        prev: &PreviousVertex,
        light: usize,
        point: &LightPoint,
    ) -> f32 {
        if prev.specular {
            return 1.0;
        }
        let pdf_light = scene.lights.pmf(light) * scene.lights.get(light).pdf_li(prev.p, point);
        power_heuristic(prev.bsdf_pdf, pdf_light)
    }

    /// Next-event estimation's contribution at surface vertex `v` from the light point
    /// `light` (chosen by `next_event::sample_light`): the shadow ray and the MIS-weighted
    /// f · Le · |cos θ| / p (without throughput). Returns the contribution and the rays cast.
    fn light_contribution(&self, scene: &Scene, v: &Vertex, light: &LightChoice) -> (Rgb, u64) {
        let VertexKind::Surface { si, bsdf, frame } = &v.kind else {
            return (Rgb::BLACK, 0);
        };
        let ls = &light.sample;
        let wo = frame.to_local(v.wo);
        let wi = frame.to_local(ls.wi);
        let f = bsdf.eval(wo, wi, TransportMode::Radiance) * wi.z.abs();
        if f.is_black() {
            return (Rgb::BLACK, 0);
        }
        if scene.geometry.occluded(&next_event::shadow_ray(si, ls)) {
            return (Rgb::BLACK, 1);
        }
        let pdf_light = light.pmf * ls.pdf_solid_angle;
        let weight = if ls.delta {
            1.0
        } else {
            power_heuristic(pdf_light, bsdf.pdf(wo, wi))
        };
        (f * ls.radiance * (weight / pdf_light), 1)
    }

    /// The path's ray has been traced: `hit` is its closest hit, if any. Adds the emission
    /// found there (the environment for a ray that escaped, an emitting surface's radiance
    /// otherwise); false when the path ends here (it escaped, or reached `max_depth`).
    pub(crate) fn arrive(
        &self,
        scene: &Scene,
        state: &mut PathState,
        hit: Option<&SurfaceInteraction>,
    ) -> bool {
        let prev = &state.prev;
        let Some(si) = hit else {
            if prev.shows_environment {
                // The ray escaped: lights at infinity.
                let towards_light = state.walk.ray.d.normalize();
                let point = LightPoint::direction(towards_light);
                for &light in scene.lights.environment() {
                    let le = scene.lights.get(light).le(&point, -towards_light);
                    let w = self.emission_weight(scene, prev, light, &point);
                    state.result += state.walk.beta * le * w;
                }
            }
            return false;
        };
        // Emission from the surface hit (a path of depth + 1 segments).
        if let Some(light) = scene.lights.light_of_shape(si.shape as usize)
            && prev.shows_emitters
        {
            let point = LightPoint::from(si);
            let le = scene
                .lights
                .get(light)
                .le(&point, -state.walk.ray.d.normalize());
            if !le.is_black() {
                let w = self.emission_weight(scene, prev, light, &point);
                state.result += state.walk.beta * le * w;
            }
        }
        state.walk.depth + 1 < self.max_depth()
    }

    /// Scatters the path at `si`, the closest hit of its ray: next-event estimation (a path
    /// of depth + 2 segments; its three numbers drawn whatever the BSDF), then the walk's
    /// BSDF sampling and Russian roulette (`Walk::scatter`). False when the path ends here.
    pub(crate) fn scatter(
        &self,
        scene: &Scene,
        state: &mut PathState,
        si: &SurfaceInteraction,
        sampler: &mut impl Sampler,
    ) -> bool {
        let v = Vertex::surface(scene, *si, -state.walk.ray.d.normalize(), state.walk.beta);

        // Next-event estimation.
        let light = next_event::sample_light(scene, si.p, sampler);
        if let Some(light) = light
            && v.is_connectible()
        {
            let (contribution, shadow_rays) = self.light_contribution(scene, &v, &light);
            state.result += state.walk.beta * contribution;
            state.rays += shadow_rays;
        }

        // BSDF sampling (the next segment) and Russian roulette.
        let rr_depth = self.settings.path.rr_depth;
        let Some(scattered) = state
            .walk
            .scatter(&v, TransportMode::Radiance, rr_depth, sampler)
        else {
            return false;
        };
        state.prev = PreviousVertex {
            shows_emitters: true,
            shows_environment: state.prev.shows_environment || !v.is_null_surface(),
            p: si.p,
            bsdf_pdf: scattered.sample.pdf,
            specular: scattered.sample.delta,
        };
        true
    }

    /// One camera path along `ray`, one vertex at a time: its radiance and the rays cast.
    pub fn trace(&self, scene: &Scene, ray: &Ray, sampler: &mut impl Sampler) -> (Rgb, u64) {
        if self.max_depth() == 0 {
            return (Rgb::BLACK, 0);
        }
        let mut state = self.start(ray);
        loop {
            state.rays += 1;
            let hit = scene.geometry.intersect(&state.walk.ray);
            if !self.arrive(scene, &mut state, hit.as_ref()) {
                break;
            }
            if !self.scatter(scene, &mut state, hit.as_ref().unwrap(), sampler) {
                break;
            }
        }
        (state.result, state.rays)
    }
}

impl CameraSampleFn for PathSample {
    type Scratch<'a> = ();
    type Extra = ();

    fn radiance(
        &self,
        scene: &Scene,
        ray: &Ray,
        _raster: Vec2,
        sampler: &mut CameraSampler,
        _scratch: &mut (),
        _extra: &mut (),
    ) -> (Rgb, u64) {
        self.trace(scene, ray, sampler)
    }

    fn tiles_per_task(&self) -> usize {
        if self.settings.wavefront {
            wavefront::TILES_PER_TASK
        } else {
            1
        }
    }

    fn render_tiles(&self, ctx: &PassContext, rects: &[PixelRect]) -> Vec<FinishedTile<()>> {
        if self.settings.wavefront && self.lane_share.lanes_pay() {
            self.render_tiles_in_lanes(ctx, rects)
        } else {
            render_tiles_one_by_one(ctx, rects, self)
        }
    }
}
