//! `ppm`: progressive photon mapping (Hachisuka, Ogaki and Jensen 2008) and, with
//! `stochastic=true`, stochastic progressive photon mapping (Hachisuka and Jensen 2009).
//!
//! A pass is an eye pass (`eye_pass`: one eye path per pixel to its first non-delta vertex,
//! the hit point), a photon pass (`photons`: `photons` light paths by the shared light
//! walk), a kd-tree over the photons (`kd_tree`) and a gather: each pixel's hit point sums
//! f·Φ over the photons within its radius R and updates its statistics (`statistics`),
//!
//!   N' = N + αM,  R' = R·√((N + αM)/(N + M)),  τ' = (τ + Φ)·R'²/R²
//!
//! (Hachisuka et al. 2008, eqs. 7, 11 and 12), so that R shrinks and the estimate
//! τ/(πR²·N_emitted) converges to the radiance while its bias fades. The pixel's value adds
//! the emission the eye paths met, averaged over passes.
//!
//! * PPM keeps each pixel's eye path (its random numbers are those of pass 0, so every pass
//!   retraces the same path): it converges to the radiance at those points, one per pixel,
//!   and keeps their aliasing. SPPM draws new eye paths every pass (the raster position from
//!   the film's filter, a lens point, glass's reflect-or-refract choice), sharing N, R and τ
//!   per pixel: anti-aliasing, depth of field and glossy surfaces converge too.
//! * A photon is gathered only from the hit point's own side of the surface (a wall's
//!   back does not light its front), except where the BSDF transmits; paths longer than
//!   `max_depth` (eye segments + photon segments) are left out.
//! * `radius=auto` starts R at two pixel footprints at the hit point (the camera's angle
//!   per pixel times the eye path's length), where the pixel first finds a hit point.
//! * Determinism: photons come in fixed blocks concatenated in order, the tree does not
//!   depend on the thread count, and each pixel's gather is its own: the image is the same
//!   for any number of threads.

pub mod eye_pass;
pub mod kd_tree;
pub mod photons;
pub mod settings;
pub mod statistics;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::{Estimator, Stats};
use crate::error::{Error, Result};
use crate::film::ReconstructionFilter;
use crate::image::Image;
use crate::material::TransportMode;
use crate::sampler::IndependentSampler;
use crate::scene::Scene;
use eye_pass::{EyeSample, HitPoint, trace_eye};
use kd_tree::KdTree;
use photons::{Photon, trace_photons};
pub use settings::{InitialRadius, PpmSettings};
use statistics::PixelStatistics;

/// The `ppm` estimator.
pub struct PhotonMapper {
    settings: PpmSettings,
    seed: u64,
    width: u32,
    height: u32,
    filter: ReconstructionFilter,
    /// The camera's angle per pixel at the image centre (for `radius=auto`).
    pixel_angle: f32,
    pixels: Vec<PixelStatistics>,
    stats: Stats,
    photons_stored: u64,
    /// Light paths traced so far (N_emitted).
    light_paths: u64,
}

/// Makes `ppm` for `scene`; an error when the scene has no light.
pub fn new(scene: &Scene, seed: u64, settings: PpmSettings) -> Result<PhotonMapper> {
    if scene.lights.lights().is_empty() {
        return Err(Error::usage(format!(
            "{}: the scene has no light (ppm traces its photons from the lights)",
            scene.description.source.display()
        )));
    }
    let window = scene.description.sensor.film.window();
    let (width, height) = (window.width, window.height);
    let pixel_count = width as u64 * height as u64;
    if pixel_count > crate::image::MAX_PIXELS {
        return Err(Error::usage(format!(
            "{}: a {width}x{height} film is too large",
            scene.description.source.display()
        )));
    }
    Ok(PhotonMapper {
        settings,
        seed,
        width,
        height,
        filter: ReconstructionFilter::new(scene.description.sensor.film.filter),
        pixel_angle: pixel_angle(scene),
        pixels: vec![PixelStatistics::default(); pixel_count as usize],
        stats: Stats::default(),
        photons_stored: 0,
        light_paths: 0,
    })
}

/// The angle between the camera rays through the image centre and the pixel beside it;
/// a scene-size fallback (its bounding sphere's diameter over the film's width, seen from
/// unit distance) where that is not a positive finite number.
fn pixel_angle(scene: &Scene) -> f32 {
    let camera = &scene.camera;
    let centre = Vec2::new(camera.width() as f32 / 2.0, camera.height() as f32 / 2.0);
    let a = camera.generate_ray(centre).d.normalize();
    let b = camera.generate_ray(centre + Vec2::X).d.normalize();
    let angle = a.angle_between(b);
    if angle > 0.0 && angle.is_finite() {
        angle
    } else {
        let (_, radius) = scene.geometry.bounds().bounding_sphere();
        (2.0 * radius / camera.width().max(1) as f32).max(f32::MIN_POSITIVE)
    }
}

/// What one pixel's gather found in one pass.
#[derive(Clone, Copy, Default)]
struct Gathered {
    /// Σ β_eye · f · Φ_photon (the shading-normal ratio included).
    flux: [f64; 3],
    photons: u64,
}

impl PhotonMapper {
    /// The pixel's hit point and the initial radius it would get.
    fn initial_radius(&self, hit: &HitPoint) -> f64 {
        match self.settings.radius {
            InitialRadius::Fixed(r) => r as f64,
            InitialRadius::Auto => {
                settings::AUTO_FOOTPRINTS as f64 * self.pixel_angle as f64 * hit.distance as f64
            }
        }
    }

    /// Bytes a stored photon costs: the photon and its kd-tree entry.
    pub const BYTES_PER_PHOTON: usize = std::mem::size_of::<Photon>() + KdTree::BYTES_PER_POINT;

    /// Photons stored so far.
    pub fn photons_stored(&self) -> u64 {
        self.photons_stored
    }

    /// Each pixel's current gather radius (0 where no hit point was found yet).
    pub fn radii(&self) -> Vec<f64> {
        self.pixels.iter().map(|p| p.radius).collect()
    }
}

/// Sums f·Φ over the photons within `radius` of `hit`.
fn gather(
    hit: &HitPoint,
    radius: f64,
    tree: &KdTree,
    photons: &[Photon],
    max_segments: u32,
) -> Gathered {
    let mut out = Gathered::default();
    let Some((si, bsdf, frame)) = hit.vertex.connectible_surface() else {
        return out;
    };
    let wo = hit.vertex.wo;
    let wo_local = frame.to_local(wo);
    let eye_side = wo.dot(si.ng);
    let transmits = bsdf.has_transmission();
    tree.within_radius(hit.vertex.p, radius as f32, |id, _| {
        let photon = &photons[id as usize];
        if photon.segments.saturating_add(hit.segments) > max_segments {
            return;
        }
        let cos_g = photon.wi.dot(si.ng);
        // A photon from behind a reflecting surface lit its other side.
        if cos_g == 0.0 || (!transmits && cos_g * eye_side <= 0.0) {
            return;
        }
        let f = bsdf.eval(wo_local, frame.to_local(photon.wi), TransportMode::Radiance);
        // Photons count flux per unit area (|cos| to the geometric normal); the shading
        // normal's cosine replaces it in the reflected radiance.
        let factor = photon.wi.dot(si.ns).abs() / cos_g.abs();
        let value = hit.beta * f * photon.power * factor;
        if !value.is_valid_radiance() {
            return;
        }
        for c in 0..3 {
            out.flux[c] += value.0[c] as f64;
        }
        out.photons += 1;
    });
    out
}

impl Estimator for PhotonMapper {
    fn name(&self) -> &str {
        "ppm"
    }

    fn run_pass(&mut self, scene: &Scene, pass_index: u32) {
        let settings = self.settings;
        let (width, height) = (self.width, self.height);
        // PPM retraces pass 0's eye paths; SPPM draws new ones.
        let eye_key = if settings.stochastic {
            pass_index as u64
        } else {
            0
        };
        let camera = &scene.camera;
        let filter = self.filter;
        let seed = self.seed;
        let eyes: Vec<EyeSample> = (0..height)
            .into_par_iter()
            .flat_map_iter(|y| {
                let mut sampler = IndependentSampler::new(seed);
                (0..width)
                    .map(|x| {
                        sampler.start_pixel_sample((x, y), eye_key);
                        trace_eye(scene, camera, &filter, (x, y), &settings.path, &mut sampler)
                    })
                    .collect::<Vec<_>>()
            })
            .collect();

        let max_segments = settings.path.max_segments();
        let traced = trace_photons(
            scene,
            seed,
            pass_index as u64,
            settings.photons,
            max_segments,
            settings.path.rr_depth,
        );
        let positions: Vec<Vec3> = traced.photons.iter().map(|p| p.p).collect();
        // Photon positions are surface points: always finite.
        let tree = KdTree::build(&positions).unwrap_or_default();
        drop(positions);

        let initial: Vec<f64> = eyes
            .iter()
            .map(|e| e.hit.as_ref().map_or(0.0, |h| self.initial_radius(h)))
            .collect();
        let alpha = settings.alpha;
        let photons = &traced.photons;
        self.pixels
            .par_iter_mut()
            .zip(eyes.par_iter().zip(initial.par_iter()))
            .for_each(|(stats, (eye, &r0))| {
                stats.add_emitted(eye.emitted);
                let Some(hit) = &eye.hit else {
                    return;
                };
                if stats.radius == 0.0 {
                    stats.radius = r0;
                }
                let found = gather(hit, stats.radius, &tree, photons, max_segments);
                stats.progress(alpha, found.photons, found.flux);
            });

        self.light_paths += settings.photons;
        self.photons_stored += traced.photons.len() as u64;
        self.stats.passes += 1;
        self.stats.samples += settings.photons;
        self.stats.rays += traced.rays + eyes.iter().map(|e| e.rays).sum::<u64>();
    }

    fn image(&self) -> Image {
        let mut image = Image::new(self.width, self.height);
        let passes = self.stats.passes.max(1) as f64;
        for (pixel, stats) in image.pixels.iter_mut().zip(&self.pixels) {
            *pixel = stats.radiance(self.light_paths, passes);
        }
        image
    }

    fn stats(&self) -> Stats {
        self.stats.clone()
    }

    fn diagnostics(&self) -> Option<serde_json::Value> {
        let radii: Vec<f64> = self
            .pixels
            .iter()
            .map(|p| p.radius)
            .filter(|&r| r > 0.0)
            .collect();
        let mean_radius = radii.iter().sum::<f64>() / radii.len().max(1) as f64;
        Some(serde_json::json!({
            "photons_stored": self.photons_stored,
            "light_paths": self.light_paths,
            "mean_radius": mean_radius,
            "bytes_per_photon": Self::BYTES_PER_PHOTON,
            // The pass's eye sample and the pixel's statistics (a BSDF with textures
            // may own a copy beyond this).
            "bytes_per_hit_point": std::mem::size_of::<EyeSample>()
                + std::mem::size_of::<PixelStatistics>(),
        }))
    }
}
