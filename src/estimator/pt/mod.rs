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

use glam::Vec3;

use super::Params;
mod diffuse_lanes;
mod hit_lanes;
mod lane_scene;
mod path_lanes;
mod shadow_queue;
mod wavefront;

use super::camera_pass::{
    CameraEstimator, CameraSampleFn, PassContext, PassCounts, render_tiles_one_by_one,
};
use crate::error::{Error, Result};
use crate::film::{FilmTile, PixelRect};
use crate::geometry::{Ray, SurfaceInteraction};
use crate::light::LightPoint;
use crate::material::{Bsdf, TransportMode};
use crate::math::lanes;
use crate::math::{Frame, Rgb};
use crate::path::mis::power_heuristic;
use crate::sampler::Sampler;
use crate::sampler::pixel_samples::CameraSampler;
use crate::scene::Scene;

/// `pt`'s settings (`--set key=value`; defaults from the scene's `<integrator>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PtSettings {
    /// Longest path in segments; `None` = unbounded (Mitsuba's −1).
    pub max_depth: Option<u32>,
    /// Depth from which Russian roulette may end a path.
    pub rr_depth: u32,
    /// Emitters the camera sees are left out, as Mitsuba 3.9's `hide_emitters` does it:
    /// the emission of the surface a camera ray hits first, and the environment for paths
    /// that escape having crossed nothing but `null` surfaces. Emitting surfaces seen
    /// through a `null` surface, anything seen in a mirror, and all light reflected stay.
    pub hide_emitters: bool,
    /// Trace sixteen paths at a time in SIMD lanes (`wavefront.rs`; the same image bits as
    /// one at a time, faster where the lanes are AVX-512 registers). The default is on
    /// where they are (`lanes::NATIVE`), off elsewhere.
    pub wavefront: bool,
}

impl PtSettings {
    /// Reads `max_depth`, `rr_depth` and `hide_emitters`, defaulting to the scene's
    /// integrator element.
    pub fn from_params(params: &Params, scene: &Scene) -> Result<PtSettings> {
        let integrator = &scene.description.integrator;
        let max_depth: i64 = params.get("max_depth", integrator.max_depth as i64)?;
        let rr_depth: u32 = params.get("rr_depth", integrator.rr_depth)?;
        let hide_emitters: bool = params.get("hide_emitters", integrator.hide_emitters)?;
        let wavefront: bool = params.get("wavefront", lanes::NATIVE)?;
        // The same bounds as the scene's <integrator> (Mitsuba's).
        if max_depth < -1 {
            return Err(Error::usage(format!(
                "--set max_depth={max_depth}: must be -1 (unbounded) or at least 0"
            )));
        }
        if rr_depth == 0 {
            return Err(Error::usage("--set rr_depth=0: must be at least 1"));
        }
        let max_depth = if max_depth < 0 {
            None
        } else {
            Some(max_depth.min(u32::MAX as i64) as u32)
        };
        Ok(PtSettings {
            max_depth,
            rr_depth,
            hide_emitters,
            wavefront,
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
        },
    )
}

/// Traces one camera path.
pub struct PathSample {
    settings: PtSettings,
    /// The scene's tables for the wavefront (with `settings.wavefront`).
    lane_scene: Option<lane_scene::LaneScene>,
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

/// One camera path between two of its vertices: the ray to trace next and what the path
/// has gathered so far.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathState {
    pub ray: Ray,
    /// Radiance found so far.
    pub result: Rgb,
    pub throughput: Rgb,
    /// Product of the relative IORs crossed: Russian roulette divides the η² that
    /// refraction puts into the throughput back out (Mitsuba 3's rule).
    pub eta: f32,
    pub prev: PreviousVertex,
    /// Segments so far minus one: the vertex `ray` reaches ends segment depth + 1.
    pub depth: u32,
    /// Rays cast so far (closest hits and shadow rays).
    pub rays: u64,
}

impl PathSample {
    /// The longest path in segments (u32::MAX for unbounded).
    pub(crate) fn max_depth(&self) -> u32 {
        self.settings.max_depth.unwrap_or(u32::MAX)
    }

    /// The state of a path that starts with camera ray `ray`.
    pub(crate) fn start(&self, ray: &Ray) -> PathState {
        PathState {
            ray: *ray,
            result: Rgb::BLACK,
            throughput: Rgb::WHITE,
            eta: 1.0,
            prev: PreviousVertex {
                shows_emitters: !self.settings.hide_emitters,
                shows_environment: !self.settings.hide_emitters,
                p: ray.o,
                bsdf_pdf: 1.0,
                specular: true,
            },
            depth: 0,
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

    /// Next-event estimation at `si`: a light chosen by power, a point on it, the shadow
    /// ray, and the MIS-weighted contribution f · Le · |cos θ| / p (without throughput).
    /// Returns the contribution and the rays cast.
    fn sample_light(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        frame: &Frame,
        bsdf: &Bsdf,
        wo: Vec3,
        sampler: &mut impl Sampler,
    ) -> (Rgb, u64) {
        let u_light = sampler.next_1d();
        let u = sampler.next_2d();
        let Some((index, pmf, _)) = scene.lights.sample(u_light) else {
            return (Rgb::BLACK, 0);
        };
        let Some(ls) = scene.lights.get(index).sample_li(si.p, u) else {
            return (Rgb::BLACK, 0);
        };
        let wi = frame.to_local(ls.wi);
        let f = bsdf.eval(wo, wi, TransportMode::Radiance) * wi.z.abs();
        if f.is_black() {
            return (Rgb::BLACK, 0);
        }
        let shadow = if ls.dist.is_finite() {
            // Point and spot lights have no error box and no normal: no offset at their end.
            si.spawn_ray_to_surface(ls.p, ls.p_error, ls.n)
        } else {
            si.spawn_ray(ls.wi)
        };
        if scene.geometry.occluded(&shadow) {
            return (Rgb::BLACK, 1);
        }
        let pdf_light = pmf * ls.pdf_solid_angle;
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
                let towards_light = state.ray.d.normalize();
                let point = LightPoint::direction(towards_light);
                for &light in scene.lights.environment() {
                    let le = scene.lights.get(light).le(&point, -towards_light);
                    let w = self.emission_weight(scene, prev, light, &point);
                    state.result += state.throughput * le * w;
                }
            }
            return false;
        };
        // Emission from the surface hit (a path of depth + 1 segments).
        if let Some(light) = scene.lights.light_of_shape(si.shape as usize)
            && prev.shows_emitters
        {
            let point = LightPoint::from(si);
            let le = scene.lights.get(light).le(&point, -state.ray.d.normalize());
            if !le.is_black() {
                let w = self.emission_weight(scene, prev, light, &point);
                state.result += state.throughput * le * w;
            }
        }
        state.depth + 1 < self.max_depth()
    }

    /// Scatters the path at `si`, the closest hit of its ray: next-event estimation (a path
    /// of depth + 2 segments), the BSDF-sampled next ray and Russian roulette. False when
    /// the path ends here.
    pub(crate) fn scatter(
        &self,
        scene: &Scene,
        state: &mut PathState,
        si: &SurfaceInteraction,
        sampler: &mut impl Sampler,
    ) -> bool {
        let bsdf = &*scene.bsdf_at(si);
        let frame = si.frame();
        let wo = frame.to_local(-state.ray.d.normalize());

        // Next-event estimation.
        if bsdf.has_non_delta() {
            let (contribution, shadow_rays) =
                self.sample_light(scene, si, &frame, bsdf, wo, sampler);
            state.result += state.throughput * contribution;
            state.rays += shadow_rays;
        }

        // BSDF sampling: the next segment.
        let u_lobe = sampler.next_1d();
        let u = sampler.next_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u, TransportMode::Radiance) else {
            return false;
        };
        state.throughput *= bs.weight;
        state.eta *= bs.eta;
        state.prev = PreviousVertex {
            shows_emitters: true,
            shows_environment: state.prev.shows_environment || !bsdf.is_null(),
            p: si.p,
            bsdf_pdf: bs.pdf,
            specular: bs.delta,
        };
        state.ray = si.spawn_ray(frame.to_world(bs.wi));
        state.depth += 1;

        // Russian roulette.
        let max_throughput = state.throughput.max_component();
        if max_throughput <= 0.0 {
            return false;
        }
        if state.depth >= self.settings.rr_depth {
            let q = (max_throughput * state.eta * state.eta).min(0.95);
            if sampler.next_1d() >= q {
                return false;
            }
            state.throughput /= q;
        }
        true
    }
}

impl CameraSampleFn for PathSample {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut CameraSampler) -> (Rgb, u64) {
        if self.max_depth() == 0 {
            return (Rgb::BLACK, 0);
        }
        let mut state = self.start(ray);
        loop {
            state.rays += 1;
            let hit = scene.geometry.intersect(&state.ray);
            if !self.arrive(scene, &mut state, hit.as_ref()) {
                break;
            }
            if !self.scatter(scene, &mut state, hit.as_ref().unwrap(), sampler) {
                break;
            }
        }
        (state.result, state.rays)
    }

    fn tiles_per_task(&self) -> usize {
        if self.settings.wavefront {
            wavefront::TILES_PER_TASK
        } else {
            1
        }
    }

    fn render_tiles(&self, ctx: &PassContext, rects: &[PixelRect]) -> Vec<(FilmTile, PassCounts)> {
        if self.settings.wavefront {
            self.render_tiles_in_lanes(ctx, rects)
        } else {
            render_tiles_one_by_one(ctx, rects, self)
        }
    }
}
