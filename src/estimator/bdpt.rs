//! `bdpt`: bidirectional path tracing (Veach 1997, ch. 10; Lafortune and Willems 1993).
//!
//! Every camera sample traces a camera subpath z0 z1 … and a light subpath y0 y1 …, and
//! joins every prefix pair: the strategy (s, t) uses s light and t camera vertices, for
//! a path of s + t vertices and s + t − 1 segments (at most `max_depth`, Mitsuba's count).
//!
//! * s = 0: the camera subpath found an emitter (`pt`'s BSDF-sampled emission);
//! * s = 1: a point sampled on a light from z_{t−1} (`pt`'s next-event estimation);
//! * t = 1: y_{s−1} joined to a camera point and splatted where it lands (`lt`);
//! * otherwise y_{s−1} and z_{t−1} joined by a shadow ray.
//!
//! Each contribution is weighted by the balance heuristic (`mis=balance`, the default) or
//! the power heuristic (`mis=power`) over all strategies that could have made the same
//! path, computed from the vertices' area densities (`path::vertex`; Veach 1997, §10.3).
//! Point and spot lights stay invisible to the camera, and `hide_emitters` leaves out the
//! emitter seen directly, as in `pt`. Lights at infinity are not supported yet: a scene
//! with a `constant`, `envmap` or `directional` emitter is refused.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::pt::PtSettings;
use super::{Estimator, Params, Stats};
use crate::error::{Error, Result};
use crate::film::{Film, FilmTile, SplatList};
use crate::geometry::Ray;
use crate::image::Image;
use crate::light::{EmissionSample, LightPoint};
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::camera_connection::{self, adjoint_shading_factor};
use crate::path::random_walk::{WalkLimits, emitted_ray, random_walk};
use crate::path::vertex::{Vertex, VertexKind};
use crate::sampler::Sampler;
use crate::sampler::pixel_samples::{CameraSampler, PixelSamples};
use crate::scene::Scene;
use std::sync::Arc;

use super::camera_pass::{TILE_SIZE, start_camera_sample};

/// Which heuristic weighs the strategies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Heuristic {
    Balance,
    Power,
}

/// `bdpt`'s settings: `pt`'s three, and `mis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BdptSettings {
    pub path: PtSettings,
    pub mis: Heuristic,
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
        if params.get("strategies", false)? {
            return Err(Error::usage(
                "--set strategies=true: one image per (s, t) is not supported yet",
            ));
        }
        Ok(BdptSettings { path, mis })
    }
}

/// The `bdpt` estimator.
pub struct Bdpt {
    film: Film,
    seed: u64,
    settings: BdptSettings,
    stats: Stats,
    pixel_samples: Arc<PixelSamples>,
}

/// Makes `bdpt` for `scene`; an error for lights at infinity or a film too large.
pub fn new(scene: &Scene, seed: u64, settings: BdptSettings) -> Result<Bdpt> {
    if scene.lights.lights().iter().any(|l| l.is_infinite()) {
        return Err(Error::usage(format!(
            "{}: bdpt does not support lights at infinity (constant, envmap, directional) \
             yet; use pt or lt",
            scene.description.source.display()
        )));
    }
    let film = &scene.description.sensor.film;
    Ok(Bdpt {
        film: Film::new(film.window().width, film.window().height, film.filter)?,
        seed,
        settings,
        stats: Stats::default(),
        pixel_samples: Arc::new(PixelSamples::Independent),
    })
}

impl Bdpt {
    /// Places the camera samples inside their pixels with `pixel_samples`.
    pub fn with_pixel_samples(mut self, pixel_samples: PixelSamples) -> Self {
        self.pixel_samples = Arc::new(pixel_samples);
        self
    }
}

/// What one tile of one pass produced.
struct TileResult {
    tile: FilmTile,
    splats: SplatList,
    rays: u64,
    invalid: u64,
    /// Reused by every weight computed in the tile: no allocation per strategy.
    scratch: WeightScratch,
}

/// (pdf_fwd, pdf_rev, delta) of the vertices a strategy uses, endpoints replaced.
#[derive(Default)]
struct WeightScratch {
    light: Vec<(f32, f32, bool)>,
    camera: Vec<(f32, f32, bool)>,
}

/// The light subpath's first vertex as sampled, kept for the s = 1, t = 1 strategy.
struct LightStart {
    pmf: f32,
    emission: EmissionSample,
}

/// A strategy's endpoint sampled by the strategy itself (s = 1: a light point; t = 1: a
/// camera point), standing in for the subpath's own first vertex.
struct Sampled<'a> {
    vertex: Vertex<'a>,
    /// Light subpath side (s = 1) or camera side (t = 1).
    light_side: bool,
}

/// One strategy's unweighted contribution, before its visibility test.
struct Connection<'a> {
    value: Rgb,
    shadow: Option<Ray>,
    /// The film position, for t = 1 (splatted); None for the camera sample's pixel.
    raster: Option<Vec2>,
    sampled: Option<Sampled<'a>>,
}

impl Bdpt {
    fn max_depth(&self) -> usize {
        self.settings
            .path
            .max_depth
            .map_or(usize::MAX / 4, |d| d as usize)
    }

    /// The camera subpath from camera ray `ray`.
    fn camera_subpath<'a>(
        &self,
        scene: &'a Scene,
        ray: Ray,
        sampler: &mut CameraSampler,
        path: &mut Vec<Vertex<'a>>,
    ) -> u64 {
        let camera = &scene.camera;
        let start = camera.ray_start(&ray);
        path.push(Vertex::camera(start, Vec3::ZERO));
        let pdf_dir = camera.pdf_direction_from(start, ray.d.normalize());
        let limits = WalkLimits {
            max_vertices: self.max_depth(),
            rr_depth: self.settings.path.rr_depth,
        };
        random_walk(
            scene,
            ray,
            Rgb::WHITE,
            pdf_dir,
            sampler,
            limits,
            TransportMode::Radiance,
            path,
        )
    }

    /// The light subpath (at most `max_depth` vertices, the light's included).
    fn light_subpath<'a>(
        &self,
        scene: &'a Scene,
        sampler: &mut CameraSampler,
        path: &mut Vec<Vertex<'a>>,
    ) -> (Option<LightStart>, u64) {
        let Some((index, pmf, _)) = scene.lights.sample(sampler.next_1d()) else {
            return (None, 0);
        };
        let light = scene.lights.get(index);
        let (u_pos, u_dir) = (sampler.next_2d(), sampler.next_2d());
        let Some(e) = light.sample_le(u_pos, u_dir) else {
            return (None, 0);
        };
        path.push(Vertex::light(
            index,
            e.delta_pos,
            e.origin,
            e.n,
            e.radiance,
            pmf * e.pdf_pos,
        ));
        let (ray, beta) = emitted_ray(&e, pmf);
        let limits = WalkLimits {
            max_vertices: self.max_depth().saturating_sub(1),
            rr_depth: self.settings.path.rr_depth,
        };
        let rays = random_walk(
            scene,
            ray,
            beta,
            e.pdf_dir,
            sampler,
            limits,
            TransportMode::Importance,
            path,
        );
        (Some(LightStart { pmf, emission: e }), rays)
    }

    /// The unweighted contribution of strategy (s, t); None when it gives nothing.
    #[allow(clippy::too_many_arguments)]
    fn connect<'a>(
        &self,
        scene: &'a Scene,
        light_path: &[Vertex<'a>],
        camera_path: &[Vertex<'a>],
        start: Option<&LightStart>,
        s: usize,
        t: usize,
        sampler: &mut CameraSampler,
    ) -> Option<Connection<'a>> {
        let hide = self.settings.path.hide_emitters;
        if s == 0 {
            // The camera subpath's last vertex lies on an emitter.
            if hide && t == 2 {
                return None;
            }
            let pt = &camera_path[t - 1];
            let light = pt.light_index(scene)?;
            let si = pt.si()?;
            let le = scene.lights.get(light).le(&LightPoint::from(si), pt.wo);
            return Some(Connection {
                value: pt.beta * le,
                shadow: None,
                raster: None,
                sampled: None,
            });
        }
        if t == 1 {
            let qs = &light_path[s - 1];
            if !qs.is_connectible() {
                return None;
            }
            let u_lens = if scene.camera.has_lens() {
                sampler.next_2d()
            } else {
                Vec2::ZERO
            };
            let splat = if s == 1 {
                if hide {
                    return None;
                }
                let start = start?;
                let VertexKind::Light { light, .. } = qs.kind else {
                    return None;
                };
                camera_connection::connect_emitter(
                    scene,
                    scene.lights.get(light),
                    start.pmf,
                    &start.emission,
                    u_lens,
                )?
            } else {
                let VertexKind::Surface { si, bsdf, frame } = &qs.kind else {
                    return None;
                };
                camera_connection::connect_surface(scene, si, frame, bsdf, qs.wo, qs.beta, u_lens)?
            };
            return Some(Connection {
                value: splat.value,
                shadow: Some(splat.shadow),
                raster: Some(splat.raster),
                sampled: Some(Sampled {
                    vertex: Vertex::camera(splat.camera_position, Vec3::ZERO),
                    light_side: false,
                }),
            });
        }
        let pt = &camera_path[t - 1];
        let VertexKind::Surface {
            si: si_pt,
            bsdf: bsdf_pt,
            frame: frame_pt,
        } = &pt.kind
        else {
            return None;
        };
        if !bsdf_pt.has_non_delta() {
            return None;
        }
        if s == 1 {
            // Next-event estimation from z_{t−1}.
            let (index, pmf, _) = scene.lights.sample(sampler.next_1d())?;
            let u = sampler.next_2d();
            let light = scene.lights.get(index);
            let ls = light.sample_li(si_pt.p, u)?;
            let f = bsdf_pt.eval(
                frame_pt.to_local(pt.wo),
                frame_pt.to_local(ls.wi),
                TransportMode::Radiance,
            );
            let cos = ls.wi.dot(si_pt.ns).abs();
            let value = pt.beta * f * ls.radiance * (cos / (pmf * ls.pdf_solid_angle));
            let mut vertex = Vertex::light(index, ls.delta, ls.p, ls.n, ls.radiance, 0.0);
            vertex.pdf_fwd = vertex.pdf_light_origin(scene, pt);
            return Some(Connection {
                value,
                shadow: Some(si_pt.spawn_ray_to_surface(ls.p, ls.p_error, ls.n)),
                raster: None,
                sampled: Some(Sampled {
                    vertex,
                    light_side: true,
                }),
            });
        }
        let qs = &light_path[s - 1];
        let VertexKind::Surface {
            si: si_qs,
            bsdf: bsdf_qs,
            frame: frame_qs,
        } = &qs.kind
        else {
            return None;
        };
        if !bsdf_qs.has_non_delta() {
            return None;
        }
        let d = pt.p - qs.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return None;
        }
        let w = d / dist2.sqrt();
        // f at the light vertex (importance, with the adjoint's shading-normal factor)
        // and at the camera vertex, and G with shading-normal cosines (Veach 1997, §10.2).
        let f_qs = bsdf_qs.eval(
            frame_qs.to_local(qs.wo),
            frame_qs.to_local(w),
            TransportMode::Importance,
        ) * adjoint_shading_factor(qs.wo, w, si_qs.ns, si_qs.ng);
        let f_pt = bsdf_pt.eval(
            frame_pt.to_local(pt.wo),
            frame_pt.to_local(-w),
            TransportMode::Radiance,
        );
        let g = w.dot(si_qs.ns).abs() * w.dot(si_pt.ns).abs() / dist2;
        let value = qs.beta * f_qs * f_pt * pt.beta * g;
        Some(Connection {
            value,
            shadow: Some(si_qs.spawn_ray_to_interaction(si_pt)),
            raster: None,
            sampled: None,
        })
    }

    /// The multiple-importance weight of strategy (s, t) for the path it made, over every
    /// strategy that could have made it (Veach 1997, §10.3: ratios of the area densities
    /// from either side, delta vertices excluded as connection points).
    #[allow(clippy::too_many_arguments)]
    fn mis_weight(
        &self,
        scene: &Scene,
        scratch: &mut WeightScratch,
        light_path: &[Vertex],
        camera_path: &[Vertex],
        sampled: Option<&Sampled>,
        s: usize,
        t: usize,
    ) -> f32 {
        // (pdf_fwd, pdf_rev, delta) of the vertices this strategy uses, endpoints replaced
        // by what the strategy sampled.
        let state = |v: &Vertex| (v.pdf_fwd, v.pdf_rev, v.delta);
        let (lv, cv) = (&mut scratch.light, &mut scratch.camera);
        lv.clear();
        lv.extend(light_path[..s].iter().map(state));
        cv.clear();
        cv.extend(camera_path[..t].iter().map(state));
        // The strategy's endpoints as vertices (the sampled one where there is one).
        let (qs, pt): (Option<&Vertex>, Option<&Vertex>) = match sampled {
            Some(Sampled {
                vertex,
                light_side: true,
            }) => (Some(vertex), Some(&camera_path[t - 1])),
            Some(Sampled {
                vertex,
                light_side: false,
            }) => ((s > 0).then(|| &light_path[s - 1]), Some(vertex)),
            None => (
                (s > 0).then(|| &light_path[s - 1]),
                Some(&camera_path[t - 1]),
            ),
        };
        if let Some(Sampled { vertex, light_side }) = sampled {
            if *light_side {
                lv[0] = state(vertex);
            } else {
                cv[0] = state(vertex);
            }
        }
        let light_is_delta = match sampled {
            Some(Sampled {
                vertex,
                light_side: true,
            }) => vertex.is_delta_light(),
            _ => s > 0 && light_path[0].is_delta_light(),
        };
        let pt = pt.expect("t ≥ 1");
        let pt_minus = (t >= 2).then(|| &camera_path[t - 2]);
        let qs_minus = (s >= 2).then(|| &light_path[s - 2]);
        // The densities the connection creates.
        cv[t - 1].1 = match qs {
            Some(qs) => qs.pdf(scene, qs_minus, pt),
            None => pt.pdf_light_origin(scene, pt_minus.expect("s = 0 has t ≥ 2")),
        };
        if let Some(pt_minus) = pt_minus {
            cv[t - 2].1 = match qs {
                Some(qs) => pt.pdf(scene, Some(qs), pt_minus),
                None => pt.pdf_light_direction(scene, pt_minus),
            };
        }
        if let Some(qs) = qs {
            lv[s - 1].1 = pt.pdf(scene, pt_minus, qs);
            if let Some(qs_minus) = qs_minus {
                lv[s - 2].1 = qs.pdf(scene, Some(pt), qs_minus);
            }
        }
        let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
        let h = |r: f32| match self.settings.mis {
            Heuristic::Balance => r,
            Heuristic::Power => r * r,
        };
        let hidden = |s2: usize, t2: usize| {
            // Strategies this estimator never uses for the path (s + t vertices).
            let direct = s2 + t2 == 2;
            direct && (self.settings.path.hide_emitters || (s2 == 1 && light_is_delta))
        };
        let mut sum = 0.0f32;
        let mut ratio = 1.0f32;
        for i in (1..t).rev() {
            ratio *= remap(cv[i].1) / remap(cv[i].0);
            if !cv[i].2 && !cv[i - 1].2 && !hidden(s + t - i, i) {
                sum += h(ratio);
            }
        }
        let mut ratio = 1.0f32;
        for i in (0..s).rev() {
            ratio *= remap(lv[i].1) / remap(lv[i].0);
            let delta_before = if i > 0 { lv[i - 1].2 } else { light_is_delta };
            if !lv[i].2 && !delta_before && !hidden(i, s + t - i) {
                sum += h(ratio);
            }
        }
        let w = 1.0 / (1.0 + sum);
        if w.is_finite() { w } else { 0.0 }
    }

    /// One camera sample: both subpaths, every strategy. Returns the pixel's value.
    fn sample<'a>(
        &self,
        scene: &'a Scene,
        ray: Ray,
        sampler: &mut CameraSampler,
        paths: &mut (Vec<Vertex<'a>>, Vec<Vertex<'a>>),
        out: &mut TileResult,
    ) -> Rgb {
        let (camera_path, light_path) = paths;
        camera_path.clear();
        light_path.clear();
        out.rays += self.camera_subpath(scene, ray, sampler, camera_path);
        let (start, rays) = self.light_subpath(scene, sampler, light_path);
        out.rays += rays;
        let max_vertices = self.max_depth().saturating_add(1);
        let mut pixel = Rgb::BLACK;
        for t in 1..=camera_path.len() {
            for s in 0..=light_path.len() {
                if s + t < 2 || s + t > max_vertices || (s == 0 && t == 1) {
                    continue;
                }
                let Some(c) = self.connect(
                    scene,
                    light_path,
                    camera_path,
                    start.as_ref(),
                    s,
                    t,
                    sampler,
                ) else {
                    continue;
                };
                if c.value.is_black() {
                    continue;
                }
                let w = self.mis_weight(
                    scene,
                    &mut out.scratch,
                    light_path,
                    camera_path,
                    c.sampled.as_ref(),
                    s,
                    t,
                );
                let value = c.value * w;
                if value.is_black() {
                    continue;
                }
                if !value.is_valid_radiance() {
                    out.invalid += 1;
                    continue;
                }
                if let Some(shadow) = &c.shadow {
                    out.rays += 1;
                    if scene.geometry.occluded(shadow) {
                        continue;
                    }
                }
                match c.raster {
                    Some(raster) => out.splats.push(raster, value),
                    None => pixel += value,
                }
            }
        }
        pixel
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
            .map(|&rect| {
                let mut out = TileResult {
                    tile: self.film.tile(rect),
                    splats: SplatList::new(),
                    rays: 0,
                    invalid: 0,
                    scratch: WeightScratch::default(),
                };
                let camera = &scene.camera;
                let mut sampler = CameraSampler::new(self.seed, self.pixel_samples.clone())
                    .with_lens_samples(camera.has_lens());
                let mut paths = (Vec::new(), Vec::new());
                for y in rect.y0..rect.y1 {
                    for x in rect.x0..rect.x1 {
                        let (raster, ray) =
                            start_camera_sample(camera, &mut sampler, x, y, pass_index);
                        let value = self.sample(scene, ray, &mut sampler, &mut paths, &mut out);
                        if value.is_valid_radiance() {
                            out.tile.add_sample(raster, value);
                        } else {
                            out.invalid += 1;
                        }
                    }
                }
                out
            })
            .collect();
        for r in results {
            self.film.merge_tile(&r.tile);
            self.film.merge_splats(&r.splats);
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
}
