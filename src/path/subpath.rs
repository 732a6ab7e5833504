//! The starts of the two subpaths a bidirectional estimator joins: a camera subpath from a
//! camera ray, a light subpath from a light chosen by power.

use glam::Vec3;

use crate::geometry::Ray;
use crate::light::EmissionSample;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::random_walk::{WalkLimits, emitted_ray, random_walk};
use crate::path::vertex::Vertex;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// The light subpath's first vertex as sampled, kept for the s = 1, t = 1 strategy (the
/// light point joined to the camera).
pub struct LightStart {
    /// The probability with which the light was chosen.
    pub pmf: f32,
    pub emission: EmissionSample,
}

/// Fills `path` (cleared first) with the camera subpath of camera ray `ray`: the camera
/// point, then at most `limits.max_vertices` vertices of the walk. Returns the rays cast.
pub fn camera_subpath<'a>(
    scene: &'a Scene,
    ray: Ray,
    sampler: &mut impl Sampler,
    limits: WalkLimits,
    path: &mut Vec<Vertex<'a>>,
) -> u64 {
    path.clear();
    let camera = &scene.camera;
    let start = camera.ray_start(&ray);
    path.push(Vertex::camera(start, Vec3::ZERO));
    let pdf_dir = camera.pdf_direction_from(start, ray.d.normalize());
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

/// Fills `path` (cleared first) with a light subpath: a light chosen by power, a ray by its
/// emission sampling, then at most `limits.max_vertices` vertices of the walk. A light at
/// infinity starts with a vertex at infinity (its direction), from which the ray leaves a
/// point of the scene's bounding disk. Returns the start (None when no light could emit)
/// and the rays cast.
pub fn light_subpath<'a>(
    scene: &'a Scene,
    sampler: &mut impl Sampler,
    limits: WalkLimits,
    path: &mut Vec<Vertex<'a>>,
) -> (Option<LightStart>, u64) {
    path.clear();
    let u_light = sampler.next_1d();
    let (u_pos, u_dir) = (sampler.next_2d(), sampler.next_2d());
    let Some((index, pmf, _)) = scene.lights.sample(u_light) else {
        return (None, 0);
    };
    let light = scene.lights.get(index);
    let Some(e) = light.sample_le(u_pos, u_dir) else {
        return (None, 0);
    };
    // The density the walk converts at the first surface: the direction's (solid angle),
    // or from infinity the disk point's (per unit area).
    let pdf_walk = if light.is_infinite() {
        let mut vertex =
            Vertex::at_infinity(Some(index), light.is_delta(), -e.direction, e.radiance);
        vertex.pdf_fwd = vertex.pdf_light_origin(scene, e.direction);
        path.push(vertex);
        e.pdf_pos
    } else {
        path.push(Vertex::light(
            index,
            e.delta_pos,
            e.origin,
            e.n,
            e.radiance,
            pmf * e.pdf_pos,
        ));
        e.pdf_dir
    };
    let (ray, beta) = emitted_ray(&e, pmf);
    let rays = random_walk(
        scene,
        ray,
        beta,
        pdf_walk,
        sampler,
        limits,
        TransportMode::Importance,
        path,
    );
    (Some(LightStart { pmf, emission: e }), rays)
}
