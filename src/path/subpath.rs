//! The two subpaths a bidirectional estimator joins, as lists of vertices with their
//! densities (`path::vertex`): a camera subpath from a camera ray, a light subpath from a
//! light chosen by power; and the start of a light path, which light tracing shares.

use glam::Vec3;

use crate::geometry::Ray;
use crate::light::EmissionSample;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::random_walk::{
    Scattered, Step, Walk, WalkHook, emitted_ray, random_walk, sample_densities,
};
use crate::path::vertex::Vertex;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A light chosen by power and a ray leaving it.
#[derive(Clone, Copy, Debug)]
pub struct LightStart {
    /// The light (index in the scene's `LightSet`) and the probability it was chosen with.
    pub light: usize,
    pub pmf: f32,
    pub emission: EmissionSample,
}

impl LightStart {
    /// The walk that leaves the light along the emitted ray.
    pub fn walk(&self) -> Walk {
        let (ray, beta) = emitted_ray(&self.emission, self.pmf);
        Walk::new(ray, beta)
    }
}

/// Draws the start of a light path's five numbers (the light's choice, the emission's
/// position, its direction) whatever happens, chooses a light by power and samples a ray
/// leaving it; None when the scene has no light or the light gives no sample.
#[inline]
pub fn start_light(scene: &Scene, sampler: &mut impl Sampler) -> Option<LightStart> {
    let u_light = sampler.next_1d();
    let (u_pos, u_dir) = (sampler.next_2d(), sampler.next_2d());
    let (light, pmf, _) = scene.lights.sample(u_light)?;
    let emission = scene.lights.get(light).sample_le(u_pos, u_dir)?;
    Some(LightStart {
        light,
        pmf,
        emission,
    })
}

/// Fills `path` (cleared first) with the camera subpath of camera ray `ray`: the camera
/// point, then at most `max_vertices` vertices of the walk (the environment where it escaped
/// a scene that has one counting as one). Returns the rays cast.
pub fn camera_subpath<'a>(
    scene: &'a Scene,
    ray: Ray,
    max_vertices: usize,
    rr_depth: u32,
    sampler: &mut impl Sampler,
    path: &mut Vec<Vertex<'a>>,
) -> u64 {
    path.clear();
    let camera = &scene.camera;
    let start = camera.ray_start(&ray);
    path.push(Vertex::camera(start, Vec3::ZERO));
    if max_vertices == 0 {
        return 0;
    }
    let mut hook = SubpathHook {
        pdf_next: camera.pdf_direction_from(start, ray.d.normalize()),
        environment: !scene.lights.environment().is_empty(),
        max_vertices,
        added: 0,
        path,
    };
    let walk = Walk::new(ray, Rgb::WHITE);
    random_walk(
        scene,
        walk,
        TransportMode::Radiance,
        rr_depth,
        sampler,
        &mut hook,
    )
}

/// Fills `path` (cleared first) with a light subpath (`start_light`, then at most
/// `max_vertices` vertices of the walk). A light at infinity starts with a vertex at
/// infinity (its direction), from which the ray leaves a point of the scene's bounding
/// disk. Returns the start (None when no light could emit) and the rays cast.
pub fn light_subpath<'a>(
    scene: &'a Scene,
    max_vertices: usize,
    rr_depth: u32,
    sampler: &mut impl Sampler,
    path: &mut Vec<Vertex<'a>>,
) -> (Option<LightStart>, u64) {
    path.clear();
    let Some(start) = start_light(scene, sampler) else {
        return (None, 0);
    };
    let light = scene.lights.get(start.light);
    let e = &start.emission;
    // The density the walk converts at the first surface: the direction's (solid angle),
    // or from infinity the disk point's (per unit area).
    let pdf_next = if light.is_infinite() {
        let mut vertex = Vertex::at_infinity(
            Some(start.light),
            light.is_delta(),
            -e.direction,
            e.radiance,
        );
        vertex.pdf_fwd = vertex.pdf_light_origin(scene, e.direction);
        path.push(vertex);
        e.pdf_pos
    } else {
        path.push(Vertex::light(
            start.light,
            e.delta_pos,
            e.origin,
            e.n,
            e.radiance,
            start.pmf * e.pdf_pos,
        ));
        e.pdf_dir
    };
    if max_vertices == 0 {
        return (Some(start), 0);
    }
    let mut hook = SubpathHook {
        pdf_next,
        environment: false,
        max_vertices,
        added: 0,
        path,
    };
    let rays = random_walk(
        scene,
        start.walk(),
        TransportMode::Importance,
        rr_depth,
        sampler,
        &mut hook,
    );
    (Some(start), rays)
}

/// Keeps a subpath's vertices with their densities: each new vertex gets its forward
/// density (`Vertex::to_area`) and gives the one before it its reverse density.
struct SubpathHook<'p, 'a> {
    path: &'p mut Vec<Vertex<'a>>,
    /// The density (solid angle, or per unit disk area from infinity) of the ray the walk
    /// follows, from the last vertex kept.
    pdf_next: f32,
    /// A walk that escapes ends at the environment (camera subpaths of scenes with one).
    environment: bool,
    max_vertices: usize,
    /// Vertices the walk added.
    added: usize,
}

impl<'a> WalkHook<'a> for SubpathHook<'_, 'a> {
    fn arrive(&mut self, _v: &Vertex<'a>, _walk: &Walk, _sampler: &mut impl Sampler) -> Step {
        if self.added + 1 >= self.max_vertices {
            Step::Stop
        } else {
            Step::Continue
        }
    }

    fn leave(&mut self, mut v: Vertex<'a>, scattered: Option<&Scattered>, _walk: &Walk) {
        let prev = self.path.last_mut().expect("a start vertex");
        v.pdf_fwd = prev.to_area(self.pdf_next, &v);
        if let Some(s) = scattered {
            let (fwd, rev) = sample_densities(&v, s);
            v.delta = s.sample.delta;
            prev.pdf_rev = v.to_area(rev, prev);
            self.pdf_next = fwd;
        }
        self.path.push(v);
        self.added += 1;
    }

    fn escape(&mut self, walk: &Walk) {
        if self.environment && self.added < self.max_vertices {
            let mut v = Vertex::at_infinity(None, false, walk.ray.d.normalize(), walk.beta);
            v.pdf_fwd = self.pdf_next;
            self.path.push(v);
        }
    }
}
