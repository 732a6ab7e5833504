//! The eye pass of photon mapping: the camera walk (`path::random_walk` in radiance
//! transport) through mirrors, glass and `null` surfaces, stopped at its first vertex with a
//! non-delta component: the hit point where photons are gathered (Hachisuka et al. 2008,
//! §4.1). Emission the walk meets on the way (an emitter seen directly or in a mirror, the
//! environment where it escapes) is the part of the pixel photons do not carry.
//!
//! The sample's position in its pixel is drawn from the film's reconstruction filter
//! (`ReconstructionFilter::sample_offset`, truncated at the film's edges), so the plain mean
//! of a pixel's samples is the filtered pixel value the other estimators compute.

use glam::Vec2;

use crate::camera::Camera;
use crate::film::ReconstructionFilter;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::random_walk::{Scattered, Step, Walk, WalkHook, random_walk};
use crate::path::settings::PathSettings;
use crate::path::vertex::Vertex;
use crate::sampler::{Sampler, Stream};
use crate::scene::Scene;

/// Where one eye path ended.
#[derive(Clone, Debug)]
pub struct HitPoint<'a> {
    /// The surface vertex, with its BSDF, shading frame and the direction back to the eye.
    pub vertex: Vertex<'a>,
    /// The eye path's throughput up to the vertex (its BSDF not included).
    pub beta: Rgb,
    /// Segments of the eye path (1: the camera ray itself).
    pub segments: u32,
    /// The eye path's length in scene units (`radius=auto` scales the pixel's angle by it).
    pub distance: f32,
}

/// One eye sample: its hit point, if it found one, and the emission it met.
#[derive(Clone, Debug, Default)]
pub struct EyeSample<'a> {
    pub hit: Option<HitPoint<'a>>,
    pub emitted: Rgb,
    pub rays: u64,
}

/// The raster position of a sample of pixel (x, y) of a `width` × `height` film, drawn
/// from `u` with density ∝ `filter` around the pixel centre, cut at the film's edges.
pub fn raster_from_filter(
    filter: &ReconstructionFilter,
    (x, y): (u32, u32),
    (width, height): (u32, u32),
    u: Vec2,
) -> Vec2 {
    let axis = |i: u32, size: u32, u: f32| {
        let centre = i as f64 + 0.5;
        let t = filter.sample_offset(u as f64, -centre, size as f64 - centre);
        // Inside [0, size): the camera maps every such position.
        ((centre + t) as f32).clamp(0.0, (size as f32).next_down())
    };
    Vec2::new(axis(x, width, u.x), axis(y, height, u.y))
}

/// Traces pixel (x, y)'s eye path from `sampler`'s current sample: the camera stream gives
/// the raster position (and the lens point), the walk's vertices draw as every walk does.
pub fn trace_eye<'a>(
    scene: &'a Scene,
    camera: &Camera,
    filter: &ReconstructionFilter,
    pixel: (u32, u32),
    settings: &PathSettings,
    sampler: &mut impl Sampler,
) -> EyeSample<'a> {
    sampler.start_stream(Stream::Camera);
    let raster = raster_from_filter(
        filter,
        pixel,
        (camera.width(), camera.height()),
        sampler.next_2d(),
    );
    let ray = if camera.has_lens() {
        camera.sample_ray(raster, sampler.next_2d())
    } else {
        camera.generate_ray(raster)
    };
    let max_segments = settings.max_segments();
    if max_segments == 0 {
        return EyeSample::default();
    }
    let mut hook = StopAtHitPoint {
        scene,
        settings,
        max_segments,
        only_null_so_far: true,
        distance: 0.0,
        found: false,
        sample: EyeSample::default(),
    };
    let rays = random_walk(
        scene,
        Walk::new(ray, Rgb::WHITE),
        TransportMode::Radiance,
        settings.rr_depth,
        sampler,
        &mut hook,
    );
    hook.sample.rays = rays;
    hook.sample
}

/// The eye walk's hook: adds emission, stops at the first non-delta vertex and keeps it.
struct StopAtHitPoint<'a, 's> {
    scene: &'a Scene,
    settings: &'s PathSettings,
    max_segments: u32,
    /// The walk has crossed nothing but `null` surfaces (for `hide_emitters`).
    only_null_so_far: bool,
    distance: f32,
    found: bool,
    sample: EyeSample<'a>,
}

impl<'a> WalkHook<'a> for StopAtHitPoint<'a, '_> {
    fn arrive(&mut self, v: &Vertex<'a>, walk: &Walk, _: &mut impl Sampler) -> Step {
        let segments = walk.depth + 1;
        if segments > self.max_segments {
            return Step::Stop;
        }
        self.distance += (v.p - walk.ray.o).length();
        // The emitter a camera ray hits first is what `hide_emitters` hides.
        if !(self.settings.hide_emitters && walk.depth == 0) {
            self.sample.emitted += walk.beta * v.emitted(self.scene);
        }
        if !v.is_null_surface() {
            self.only_null_so_far = false;
        }
        if v.is_connectible() {
            self.found = true;
            return Step::Stop;
        }
        Step::Continue
    }

    fn leave(&mut self, v: Vertex<'a>, _: Option<&Scattered>, walk: &Walk) {
        if std::mem::take(&mut self.found) {
            self.sample.hit = Some(HitPoint {
                vertex: v,
                beta: walk.beta,
                segments: walk.depth + 1,
                distance: self.distance,
            });
        }
    }

    fn escape(&mut self, walk: &Walk) {
        if walk.depth + 1 > self.max_segments
            || (self.settings.hide_emitters && self.only_null_so_far)
        {
            return;
        }
        let v = Vertex::at_infinity(None, false, walk.ray.d.normalize(), walk.beta);
        self.sample.emitted += walk.beta * v.emitted(self.scene);
    }
}
