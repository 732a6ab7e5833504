//! Joining a vertex of a light subpath to the camera: the t = 1 strategies of light tracing
//! (and of bidirectional path tracing, which adds the others).
//!
//! A light subpath x0 x1 … xs with throughput β (the emitted quantity times every BSDF
//! factor and cosine so far, over the densities that produced it) becomes a complete path
//! by the segment from xs to a point of the camera. Its contribution to the film is
//!
//!   β · f(xs) · G(xs ↔ camera) · We  =  β · f · |cos θs| · `CameraConnection::importance`
//!
//! at the raster position where xs lands (Veach 1997, §10.2, the s = k, t = 1 term). The
//! functions here return that value and the shadow ray that decides whether it counts:
//! casting it is the caller's business (it counts the rays).

use glam::{Vec2, Vec3};

use crate::geometry::offset::offset_ray_origin;
use crate::geometry::{Ray, SHADOW_EPSILON, SurfaceInteraction};
use crate::light::{EmissionSample, Light};
use crate::material::{Bsdf, TransportMode};
use crate::math::{Frame, Rgb};
use crate::scene::Scene;

/// A contribution waiting for its visibility test.
#[derive(Clone, Copy, Debug)]
pub struct CameraSplat {
    /// Where it lands on the film.
    pub raster: Vec2,
    /// What it adds there (unnormalised: the estimator divides by the number of paths).
    pub value: Rgb,
    /// From the light-subpath vertex to the camera point, stopping short of it.
    pub shadow: Ray,
    /// The camera point joined: the pinhole, or the sampled point of the lens.
    pub camera_position: Vec3,
    /// The solid-angle density of a camera ray from `camera_position` towards the vertex.
    pub pdf_camera: f32,
    /// For a surface vertex joined `with_densities`: the BSDF's solid-angle densities of
    /// leaving towards the camera having arrived from `wo`, and of the reverse.
    pub bsdf_densities: Option<(f32, f32)>,
}

/// The adjoint BSDF's shading-normal factor |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|) for a light
/// subpath that arrives from `wo` and continues in `wi` (world directions, pointing away
/// from the surface): with it, importance transport through a surface with interpolated
/// normals is the adjoint of radiance transport (Veach 1997, eq. 5.19). 0 when `wo` or `wi`
/// lies in the geometric surface's plane.
#[inline]
pub fn adjoint_shading_factor(wo: Vec3, wi: Vec3, ns: Vec3, ng: Vec3) -> f32 {
    let num = wo.dot(ns).abs() * wi.dot(ng).abs();
    let den = wo.dot(ng).abs() * wi.dot(ns).abs();
    if den > 0.0 && num.is_finite() {
        num / den
    } else {
        0.0
    }
}

/// The light vertex itself seen by the camera (s = 1: the path light → camera): `e` was
/// emitted by `light`, chosen with probability `pmf`. `u_lens` picks the lens point of a
/// thin lens (ignored by a pinhole). None for lights at infinity and delta directions
/// (they cannot reach a point camera), when the point lies outside the image or the light
/// faces away, and for point and spot lights: camera rays never hit those, so in `pt` and
/// in Mitsuba 3 they are invisible, and light tracing keeps that convention (otherwise the
/// pixel that sees one would hold its whole irradiance at the camera).
pub fn connect_emitter(
    scene: &Scene,
    light: &Light,
    pmf: f32,
    e: &EmissionSample,
    u_lens: Vec2,
) -> Option<CameraSplat> {
    if light.is_infinite() || e.delta_dir || e.delta_pos {
        return None;
    }
    let c = scene.camera.connect_lens(e.origin, u_lens)?;
    let emitted = light.emitted_towards(e, c.direction_to_camera);
    // The geometric cosine at the light turns its area density into the solid angle the
    // camera sees.
    let cos = e.n.dot(c.direction_to_camera).abs();
    let value = emitted * (cos * c.importance / (pmf * e.pdf_pos));
    if value.is_black() {
        return None;
    }
    let o = offset_ray_origin(e.origin, e.p_error, e.n, c.camera_position - e.origin);
    Some(CameraSplat {
        raster: c.raster,
        value,
        shadow: Ray {
            o,
            d: c.camera_position - o,
            t_max: 1.0 - SHADOW_EPSILON,
        },
        camera_position: c.camera_position,
        pdf_camera: c.pdf_direction,
        bsdf_densities: None,
    })
}

/// A surface vertex `si` of a light subpath with throughput `beta`, reached from world
/// direction `wo` (pointing back along the subpath), with BSDF `bsdf` in shading frame
/// `frame`. None when the point lies outside the image or the BSDF sends nothing to the
/// camera (delta components never do). `with_densities` also evaluates the BSDF's densities
/// (for a bidirectional estimator's weight; light tracing needs none).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn connect_surface(
    scene: &Scene,
    si: &SurfaceInteraction,
    frame: &Frame,
    bsdf: &Bsdf,
    wo: Vec3,
    beta: Rgb,
    u_lens: Vec2,
    with_densities: bool,
) -> Option<CameraSplat> {
    let c = scene.camera.connect_lens(si.p, u_lens)?;
    let wi = c.direction_to_camera;
    let (wo_local, wi_local) = (frame.to_local(wo), frame.to_local(wi));
    let (f, bsdf_densities) = if with_densities {
        let (f, fwd, rev) = bsdf.eval_with_pdfs(wo_local, wi_local, TransportMode::Importance);
        (f, Some((fwd, rev)))
    } else {
        (
            bsdf.eval(wo_local, wi_local, TransportMode::Importance),
            None,
        )
    };
    // f · |cos θ| at the surface, with the adjoint's shading-normal factor:
    // f · |wi·ns| · |wo·ns||wi·ng| / (|wo·ng||wi·ns|) = f · |wo·ns| |wi·ng| / |wo·ng|.
    let cos = adjoint_shading_factor(wo, wi, si.ns, si.ng) * wi.dot(si.ns).abs();
    let value = beta * f * (cos * c.importance);
    if value.is_black() {
        return None;
    }
    Some(CameraSplat {
        raster: c.raster,
        value,
        shadow: si.spawn_ray_to(c.camera_position),
        camera_position: c.camera_position,
        pdf_camera: c.pdf_direction,
        bsdf_densities,
    })
}
