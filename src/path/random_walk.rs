//! The random walk every estimator's paths are made of: from a ray, surface after surface,
//! BSDF sampling and Russian roulette at each, in radiance transport (from the camera) or
//! importance transport (from a light). What an estimator does at a vertex (gather emission,
//! next-event estimation, join the camera, keep the vertex, stop at the first non-specular
//! one) is a hook (`WalkHook`); `pt` drives the same steps itself (`Walk::scatter`), one
//! vertex at a time, because its wavefront needs them so.

use glam::Vec3;

use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::light::EmissionSample;
use crate::material::{BsdfSample, TransportMode};
use crate::math::Rgb;
use crate::path::camera_connection::adjoint_shading_factor;
use crate::path::vertex::{Vertex, VertexKind};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// The start of a light walk: the ray leaving emission sample `e` of a light chosen with
/// probability `pmf` (its origin offset off an area light's surface), and its throughput
/// Le |cos θ| / (p_light p_pos p_dir). Point and spot lights have no cosine; for lights at
/// infinity n = ω, so |n·ω| = 1.
pub fn emitted_ray(e: &EmissionSample, pmf: f32) -> (Ray, Rgb) {
    let cos = if e.delta_pos {
        1.0
    } else {
        e.n.dot(e.direction).abs()
    };
    let beta = e.radiance * (cos / (pmf * e.pdf_pos * e.pdf_dir));
    let origin = offset_ray_origin(e.origin, e.p_error, e.n, e.direction);
    (Ray::new(origin, e.direction), beta)
}

/// A walk between two of its vertices.
#[derive(Clone, Copy, Debug)]
pub struct Walk {
    /// The ray to the next vertex.
    pub ray: Ray,
    /// Throughput of the walk up to the vertex `ray` reaches.
    pub beta: Rgb,
    /// Product of the relative indices of refraction crossed: Russian roulette divides the
    /// η² that refraction puts into radiance throughput back out (Mitsuba 3's rule).
    pub eta: f32,
    /// Vertices the walk has scattered at so far: the vertex `ray` reaches ends segment
    /// `depth + 1` of the walk.
    pub depth: u32,
}

/// How the walk left a vertex.
#[derive(Clone, Copy, Debug)]
pub struct Scattered {
    pub sample: BsdfSample,
    /// The direction the walk arrived from, in the vertex's shading frame.
    pub wo_local: Vec3,
}

impl Walk {
    pub fn new(ray: Ray, beta: Rgb) -> Walk {
        Walk {
            ray,
            beta,
            eta: 1.0,
            depth: 0,
        }
    }

    /// Scatters the walk at surface vertex `v`, the vertex its ray reached: draws the
    /// vertex's four numbers (the BSDF's component, its direction, Russian roulette's) in
    /// that order whatever happens, samples the BSDF in `mode` (importance transport with
    /// the adjoint's shading-normal factor, Veach 1997, eq. 5.19), moves the ray on, and
    /// plays Russian roulette once the walk has scattered `rr_depth` times: it continues
    /// with probability min(max(β)·η², 0.95) (Mitsuba 3). None when the walk ends here (no
    /// sample, a throughput of 0 or not finite, or the roulette).
    #[inline]
    pub fn scatter(
        &mut self,
        v: &Vertex,
        mode: TransportMode,
        rr_depth: u32,
        sampler: &mut impl Sampler,
    ) -> Option<Scattered> {
        let u_lobe = sampler.next_1d();
        let u = sampler.next_2d();
        let u_roulette = sampler.next_1d();
        let VertexKind::Surface { si, bsdf, frame } = &v.kind else {
            return None;
        };
        let wo_local = frame.to_local(v.wo);
        let sample = bsdf.sample(wo_local, u_lobe, u, mode)?;
        let wi = frame.to_world(sample.wi);
        let mut weight = sample.weight;
        if mode == TransportMode::Importance {
            weight *= adjoint_shading_factor(v.wo, wi, si.ns, si.ng);
        }
        self.beta *= weight;
        self.eta *= sample.eta;
        self.ray = si.spawn_ray(wi);
        self.depth += 1;
        let max_beta = self.beta.max_component();
        if !(max_beta > 0.0 && max_beta.is_finite()) {
            return None;
        }
        if self.depth >= rr_depth {
            let q = (max_beta * self.eta * self.eta).min(0.95);
            if u_roulette >= q {
                return None;
            }
            self.beta /= q;
        }
        Some(Scattered { sample, wo_local })
    }
}

/// Whether a walk goes on from a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    Continue,
    Stop,
}

/// What an estimator does along a walk (`random_walk`).
pub trait WalkHook<'a> {
    /// The walk reached surface vertex `v` (`walk.ray` is the ray that found it, `walk.beta`
    /// the throughput up to it). `Stop` ends the walk there, before it scatters.
    fn arrive(&mut self, v: &Vertex<'a>, walk: &Walk, sampler: &mut impl Sampler) -> Step;

    /// The walk leaves `v`: by `scattered`, or not at all (None: it stopped or ended there).
    fn leave(&mut self, _v: Vertex<'a>, _scattered: Option<&Scattered>, _walk: &Walk) {}

    /// The walk's ray escaped the scene.
    fn escape(&mut self, _walk: &Walk) {}
}

/// Walks from `walk.ray` through the scene in transport `mode`, calling `hook` at every
/// vertex (`arrive`, then `leave`) and where the walk escapes; Russian roulette from
/// `rr_depth` scatterings on. Returns the rays cast.
pub fn random_walk<'a>(
    scene: &'a Scene,
    mut walk: Walk,
    mode: TransportMode,
    rr_depth: u32,
    sampler: &mut impl Sampler,
    hook: &mut impl WalkHook<'a>,
) -> u64 {
    let mut rays = 0u64;
    loop {
        rays += 1;
        let Some(si) = scene.geometry.intersect(&walk.ray) else {
            hook.escape(&walk);
            return rays;
        };
        let v = Vertex::surface(scene, si, -walk.ray.d.normalize(), walk.beta);
        let scattered = match hook.arrive(&v, &walk, sampler) {
            Step::Stop => None,
            Step::Continue => walk.scatter(&v, mode, rr_depth, sampler),
        };
        let going_on = scattered.is_some();
        hook.leave(v, scattered.as_ref(), &walk);
        if !going_on {
            return rays;
        }
    }
}

/// The densities of a bidirectional subpath's vertex (`path::vertex`) for the BSDF sample
/// that left it: (forward, reverse), the forward one of the direction sampled, the reverse
/// one of the direction the walk arrived from, in solid angle.
///
/// A delta (specular) sample gets densities that make the ratios between strategies right
/// (Veach 1997, §10.3.5; derived in the README's Design section). In projected solid angle
/// the Dirac deltas of the two directions through a specular vertex differ only by the
/// squared indices of refraction on either side (conservation of étendue,
/// η_i² cos θ_i dω_i = η_t² cos θ_t dω_t), so with the delta itself factored out, the
/// forward density is P·η_t/η_i and the reverse P·η_i/η_t, P being the probability of
/// choosing the component (the same both ways for every delta component mltbench has: a
/// mirror keeps |cos θ|, and Fresnel reflectance is the same from either side). As
/// solid-angle densities, the form `Vertex::to_area` converts: P·(η_t/η_i)·|cos θ_t|
/// forward and P·(η_i/η_t)·|cos θ_i| back, the cosines taken in the shading frame the
/// component reflects or refracts in.
pub fn sample_densities(v: &Vertex, s: &Scattered) -> (f32, f32) {
    let bs = &s.sample;
    if bs.delta {
        return (
            bs.pdf * bs.eta * bs.wi.z.abs(),
            bs.pdf / bs.eta * s.wo_local.z.abs(),
        );
    }
    let VertexKind::Surface { bsdf, .. } = &v.kind else {
        return (0.0, 0.0);
    };
    (bs.pdf, bsdf.pdf(bs.wi, s.wo_local))
}
