//! The random walk both subpaths of a bidirectional estimator are made of (DESIGN.md §2).

use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::light::EmissionSample;
use crate::material::TransportMode;
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

/// How far a walk may go and when Russian roulette starts.
#[derive(Clone, Copy, Debug)]
pub struct WalkLimits {
    /// Most surface vertices the walk adds.
    pub max_vertices: usize,
    /// Russian roulette once the walk has scattered this many times (as `pt`).
    pub rr_depth: u32,
}

/// Extends `path`, whose last vertex (the camera or a light) sent `ray` with density
/// `pdf_dir` (solid angle; per unit area of the emission disk from a vertex at infinity)
/// and left throughput `beta`, by the surfaces the walk meets: each new vertex gets its
/// forward density (`Vertex::to_area`) and gives the one before it its reverse density.
/// `mode` is the quantity carried: radiance from the camera, importance from a light (with
/// the adjoint's shading-normal factor, Veach 1997, eq. 5.19). A camera walk (radiance)
/// that escapes a scene with an environment (`constant`, `envmap`) ends with a vertex at
/// infinity in the escaped direction. Returns the rays cast.
///
/// A delta (specular) sample gets densities that make the ratios between strategies right
/// (Veach 1997, §10.3.5; derived in the README's Design section). In projected solid angle
/// the Dirac deltas of the two directions through a specular vertex differ only by the
/// squared indices of refraction on either side (conservation of étendue,
/// η_i² cos θ_i dω_i = η_t² cos θ_t dω_t), so with the delta itself factored out, the
/// forward density is P·η_t/η_i and the reverse P·η_i/η_t, P being the probability of
/// choosing the component (the same both ways for every delta component mltbench has: a
/// mirror keeps |cos θ|, and Fresnel reflectance is the same from either side). As
/// solid-angle densities, the form `to_area` converts: P·(η_t/η_i)·|cos θ_t| forward and
/// P·(η_i/η_t)·|cos θ_i| back, the cosines taken in the shading frame the component
/// reflects or refracts in.
#[allow(clippy::too_many_arguments)]
pub fn random_walk<'a>(
    scene: &'a Scene,
    mut ray: Ray,
    mut beta: Rgb,
    pdf_dir: f32,
    sampler: &mut impl Sampler,
    limits: WalkLimits,
    mode: TransportMode,
    path: &mut Vec<Vertex<'a>>,
) -> u64 {
    let mut pdf_fwd = pdf_dir;
    let mut eta = 1.0f32;
    let mut bounces = 0usize;
    let mut rays = 0u64;
    while bounces < limits.max_vertices {
        rays += 1;
        let Some(si) = scene.geometry.intersect(&ray) else {
            if mode == TransportMode::Radiance && !scene.lights.environment().is_empty() {
                let mut vertex = Vertex::at_infinity(None, false, ray.d.normalize(), beta);
                vertex.pdf_fwd = pdf_fwd;
                path.push(vertex);
            }
            break;
        };
        let wo = -ray.d.normalize();
        let mut vertex = Vertex::surface(scene, si, wo, beta);
        vertex.pdf_fwd = path
            .last()
            .expect("a start vertex")
            .to_area(pdf_fwd, &vertex);
        path.push(vertex);
        bounces += 1;
        if bounces >= limits.max_vertices {
            break;
        }
        let n = path.len();
        let VertexKind::Surface { si, bsdf, frame } = &path[n - 1].kind else {
            unreachable!("the walk adds surface vertices");
        };
        let wo_local = frame.to_local(wo);
        let u_lobe = sampler.next_1d();
        let u = sampler.next_2d();
        let Some(bs) = bsdf.sample(wo_local, u_lobe, u, mode) else {
            break;
        };
        let wi = frame.to_world(bs.wi);
        let mut weight = bs.weight;
        if mode == TransportMode::Importance {
            weight *= adjoint_shading_factor(wo, wi, si.ns, si.ng);
        }
        let (fwd, rev) = if bs.delta {
            // Projected-solid-angle densities P·η_t/η_i and P·η_i/η_t, as solid angle.
            (
                bs.pdf * bs.eta * bs.wi.z.abs(),
                bs.pdf / bs.eta * wo_local.z.abs(),
            )
        } else {
            (bs.pdf, bsdf.pdf(bs.wi, wo_local))
        };
        let next_ray = si.spawn_ray(wi);
        path[n - 1].delta = bs.delta;
        let pdf_rev = path[n - 1].to_area(rev, &path[n - 2]);
        path[n - 2].pdf_rev = pdf_rev;
        beta *= weight;
        eta *= bs.eta;
        pdf_fwd = fwd;
        ray = next_ray;

        let max_beta = beta.max_component();
        if max_beta <= 0.0 || !max_beta.is_finite() {
            break;
        }
        if bounces as u32 >= limits.rr_depth {
            let q = (max_beta * eta * eta).min(0.95);
            if sampler.next_1d() >= q {
                break;
            }
            beta /= q;
        }
    }
    rays
}
