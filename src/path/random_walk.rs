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

/// Extends `path`, whose last vertex (the camera or a light) sent `ray` with solid-angle
/// density `pdf_dir` and left throughput `beta`, by the surfaces the walk meets: each new
/// vertex gets its forward density (area measure) and gives the one before it its reverse
/// density. `mode` is the quantity carried: radiance from the camera, importance from a
/// light (with the adjoint's shading-normal factor, Veach 1997, eq. 5.19). Returns the
/// rays cast.
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
        // Delta samples have no density either way (Veach 1997, §10.3.5).
        let (fwd, rev) = if bs.delta {
            (0.0, 0.0)
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
