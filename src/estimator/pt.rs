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
use super::camera_pass::{CameraEstimator, CameraSampleFn};
use crate::error::{Error, Result};
use crate::geometry::{Ray, SurfaceInteraction};
use crate::light::LightPoint;
use crate::material::{Bsdf, TransportMode};
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
}

impl PtSettings {
    /// Reads `max_depth`, `rr_depth` and `hide_emitters`, defaulting to the scene's
    /// integrator element.
    pub fn from_params(params: &Params, scene: &Scene) -> Result<PtSettings> {
        let integrator = &scene.description.integrator;
        let max_depth: i64 = params.get("max_depth", integrator.max_depth as i64)?;
        let rr_depth: u32 = params.get("rr_depth", integrator.rr_depth)?;
        let hide_emitters: bool = params.get("hide_emitters", integrator.hide_emitters)?;
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
        })
    }
}

/// The `pt` estimator.
pub type PathTracer = CameraEstimator<PathSample>;

/// Makes `pt` for `scene` with `settings`; an error when its film does not fit in memory.
pub fn new(scene: &Scene, seed: u64, settings: PtSettings) -> Result<PathTracer> {
    CameraEstimator::new("pt", scene, seed, PathSample { settings })
}

/// Traces one camera path.
pub struct PathSample {
    settings: PtSettings,
}

/// What the next vertex needs to weight emission found by the BSDF-sampled ray.
#[derive(Clone, Copy)]
struct PreviousVertex {
    /// Emission of a surface this ray hits counts (false only for a camera ray under
    /// `hide_emitters`).
    shows_emitters: bool,
    /// The environment counts if this ray escapes (under `hide_emitters`, false until the
    /// path has scattered at a surface that is not `null`).
    shows_environment: bool,
    /// Where the ray started (for the light's solid-angle density).
    p: Vec3,
    /// Solid-angle density of the BSDF sample.
    bsdf_pdf: f32,
    /// The ray came from the camera or from a delta component: no light sample could
    /// have produced it, so its emission takes weight 1.
    specular: bool,
}

impl PathSample {
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
        sampler: &mut CameraSampler,
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
}

impl CameraSampleFn for PathSample {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut CameraSampler) -> (Rgb, u64) {
        let max_depth = self.settings.max_depth.unwrap_or(u32::MAX);
        if max_depth == 0 {
            return (Rgb::BLACK, 0);
        }
        let mut ray = *ray;
        let mut result = Rgb::BLACK;
        let mut throughput = Rgb::WHITE;
        // Product of the relative IORs crossed: Russian roulette divides the η² that
        // refraction puts into the throughput back out (Mitsuba 3's rule).
        let mut eta = 1.0f32;
        let mut prev = PreviousVertex {
            shows_emitters: !self.settings.hide_emitters,
            shows_environment: !self.settings.hide_emitters,
            p: ray.o,
            bsdf_pdf: 1.0,
            specular: true,
        };
        let mut rays = 0u64;
        // Segments so far minus one: the vertex `si` below is the end of segment depth + 1.
        let mut depth = 0u32;
        loop {
            rays += 1;
            let Some(si) = scene.geometry.intersect(&ray) else {
                if !prev.shows_environment {
                    break;
                }
                // The ray escaped: lights at infinity.
                let towards_light = ray.d.normalize();
                let point = LightPoint::direction(towards_light);
                for &light in scene.lights.environment() {
                    let le = scene.lights.get(light).le(&point, -towards_light);
                    let w = self.emission_weight(scene, &prev, light, &point);
                    result += throughput * le * w;
                }
                break;
            };
            let wo_world = -ray.d.normalize();

            // Emission from the surface hit (a path of depth + 1 segments).
            if let Some(light) = scene.lights.light_of_shape(si.shape as usize)
                && prev.shows_emitters
            {
                let point = LightPoint::from(&si);
                let le = scene.lights.get(light).le(&point, wo_world);
                if !le.is_black() {
                    let w = self.emission_weight(scene, &prev, light, &point);
                    result += throughput * le * w;
                }
            }
            if depth + 1 >= max_depth {
                break;
            }

            let bsdf = &*scene.bsdf_at(&si);
            let frame = si.frame();
            let wo = frame.to_local(wo_world);

            // Next-event estimation (a path of depth + 2 segments).
            if bsdf.has_non_delta() {
                let (contribution, shadow_rays) =
                    self.sample_light(scene, &si, &frame, bsdf, wo, sampler);
                result += throughput * contribution;
                rays += shadow_rays;
            }

            // BSDF sampling: the next segment.
            let u_lobe = sampler.next_1d();
            let u = sampler.next_2d();
            let Some(bs) = bsdf.sample(wo, u_lobe, u, TransportMode::Radiance) else {
                break;
            };
            throughput *= bs.weight;
            eta *= bs.eta;
            prev = PreviousVertex {
                shows_emitters: true,
                shows_environment: prev.shows_environment || !bsdf.is_null(),
                p: si.p,
                bsdf_pdf: bs.pdf,
                specular: bs.delta,
            };
            ray = si.spawn_ray(frame.to_world(bs.wi));
            depth += 1;

            // Russian roulette.
            let max_throughput = throughput.max_component();
            if max_throughput <= 0.0 {
                break;
            }
            if depth >= self.settings.rr_depth {
                let q = (max_throughput * eta * eta).min(0.95);
                if sampler.next_1d() >= q {
                    break;
                }
                throughput /= q;
            }
        }
        (result, rays)
    }
}
