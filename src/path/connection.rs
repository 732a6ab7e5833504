//! One bidirectional strategy (s, t): joining the first s vertices of a light subpath
//! y0 y1 … and the first t of a camera subpath z0 z1 … into a path of s + t vertices
//! (Veach 1997, §10.2), its unweighted contribution, and its multiple-importance weight
//! over every strategy that could have made the same path (§10.3).
//!
//! * s = 0: the camera subpath found an emitter (an area light, or the environment at
//!   infinity);
//! * s = 1: a point sampled on a light from z(t−1) (next-event estimation);
//! * t = 1: y(s−1) joined to a camera point and splatted where it lands (light tracing);
//! * otherwise y(s−1) and z(t−1) joined by a shadow ray.
//!
//! Point, spot and directional lights stay invisible to the camera, lights at infinity are
//! never joined to it directly (only camera rays see them), and `hide_emitters` leaves out
//! the emitter seen directly and the environment seen through `null` surfaces only, as in
//! `pt`.

use glam::{Vec2, Vec3};

use crate::geometry::Ray;
use crate::material::TransportMode;
use crate::math::Rgb;
use crate::path::camera_connection::{self, adjoint_shading_factor};
use crate::path::mis::{Heuristic, PathDensity, StrategyRules};
use crate::path::mis_sums::{Joint, SubpathSums, joint_weight};
use crate::path::next_event::{self, LightChoice};
use crate::path::subpath::LightStart;
use crate::path::vertex::{Vertex, VertexKind};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A strategy's endpoint sampled by the strategy itself (s = 1: a light point; t = 1: a
/// camera point), standing in for the subpath's own first vertex.
pub struct Sampled<'a> {
    pub vertex: Vertex<'a>,
    /// Light subpath side (s = 1) or camera side (t = 1).
    pub light_side: bool,
}

/// One strategy's unweighted contribution, before its visibility test.
pub struct Connection<'a> {
    pub value: Rgb,
    /// The segment that must be unoccluded for the contribution to count.
    pub shadow: Option<Ray>,
    /// The film position, for t = 1 (splatted); None for the camera sample's pixel.
    pub raster: Option<Vec2>,
    pub sampled: Option<Sampled<'a>>,
    /// The BSDF densities (solid angle) its evaluation gave at the endpoints, for the weight.
    pub densities: EndpointDensities,
}

impl<'a> Connection<'a> {
    /// What the weight of this connection's strategy reads from it (`weight`).
    pub fn ends(&self) -> ConnectionEnds<'_, 'a> {
        ConnectionEnds {
            sampled: self.sampled.as_ref(),
            densities: self.densities,
        }
    }
}

/// The parts of a connection its strategy's weight depends on: the endpoint it sampled
/// and the densities its evaluation gave. A caller that keeps connections waiting can
/// keep the sampled endpoints apart (most strategies have none, and a vertex is most of
/// a connection's size) and hand them back here.
#[derive(Clone, Copy)]
pub struct ConnectionEnds<'c, 'a> {
    pub sampled: Option<&'c Sampled<'a>>,
    pub densities: EndpointDensities,
}

/// The solid-angle densities of the BSDFs at a connection's endpoints, from the same
/// evaluation as their f (`Bsdf::eval_with_pdfs`): at z(t−1), of leaving towards y(s−1)
/// having come from z(t−2), and the reverse; at y(s−1), towards z(t−1) from y(s−2), and the
/// reverse. For t = 1 the camera's is the density of its ray towards y(s−1) (no reverse).
/// None where the connection did not evaluate the endpoint.
#[derive(Clone, Copy, Debug, Default)]
pub struct EndpointDensities {
    pub camera: Option<(f32, f32)>,
    pub light: Option<(f32, f32)>,
}

/// The unweighted contribution of strategy (s, t); None when it gives nothing. Draws a
/// light choice and a light point for s = 1, a lens point for t = 1 with a thin lens.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn connect<'a>(
    scene: &'a Scene,
    light_path: &[Vertex<'a>],
    camera_path: &[Vertex<'a>],
    start: Option<&LightStart>,
    s: usize,
    t: usize,
    hide_emitters: bool,
    sampler: &mut impl Sampler,
) -> Option<Connection<'a>> {
    if s == 0 {
        return emitter_found(scene, camera_path, t, hide_emitters);
    }
    if t == 1 {
        return light_vertex_to_camera(scene, light_path, start, s, hide_emitters, sampler);
    }
    let pt = &camera_path[t - 1];
    let (si_pt, bsdf_pt, frame_pt) = pt.connectible_surface()?;
    if s == 1 {
        // Next-event estimation from z(t−1).
        let LightChoice {
            light: index,
            pmf,
            sample: ls,
        } = next_event::sample_light(scene, si_pt.p, sampler)?;
        let (f, pdf_fwd, pdf_rev) = bsdf_pt.eval_with_pdfs(
            frame_pt.to_local(pt.wo),
            frame_pt.to_local(ls.wi),
            TransportMode::Radiance,
        );
        let cos = ls.wi.dot(si_pt.ns).abs();
        let value = pt.beta * f * ls.radiance * (cos / (pmf * ls.pdf_solid_angle));
        let mut vertex = if ls.dist.is_finite() {
            Vertex::light(index, ls.delta, ls.p, ls.n, ls.radiance, 0.0)
        } else {
            Vertex::at_infinity(Some(index), ls.delta, ls.wi, ls.radiance)
        };
        vertex.pdf_fwd = vertex.pdf_light_origin(scene, -ls.wi);
        return Some(Connection {
            value,
            shadow: Some(next_event::shadow_ray(si_pt, &ls)),
            raster: None,
            sampled: Some(Sampled {
                vertex,
                light_side: true,
            }),
            densities: EndpointDensities {
                camera: Some((pdf_fwd, pdf_rev)),
                light: None,
            },
        });
    }
    let qs = &light_path[s - 1];
    let (si_qs, bsdf_qs, frame_qs) = qs.connectible_surface()?;
    let d = pt.p - qs.p;
    let dist2 = d.length_squared();
    if dist2.is_nan() || dist2 <= 0.0 {
        return None;
    }
    let w = d / dist2.sqrt();
    // f at the light vertex (importance, with the adjoint's shading-normal factor)
    // and at the camera vertex, and G with shading-normal cosines (Veach 1997, §10.2).
    let (f_qs, light_fwd, light_rev) = bsdf_qs.eval_with_pdfs(
        frame_qs.to_local(qs.wo),
        frame_qs.to_local(w),
        TransportMode::Importance,
    );
    let f_qs = f_qs * adjoint_shading_factor(qs.wo, w, si_qs.ns, si_qs.ng);
    let (f_pt, camera_fwd, camera_rev) = bsdf_pt.eval_with_pdfs(
        frame_pt.to_local(pt.wo),
        frame_pt.to_local(-w),
        TransportMode::Radiance,
    );
    let g = w.dot(si_qs.ns).abs() * w.dot(si_pt.ns).abs() / dist2;
    Some(Connection {
        value: qs.beta * f_qs * f_pt * pt.beta * g,
        shadow: Some(si_qs.spawn_ray_to_interaction(si_pt)),
        raster: None,
        sampled: None,
        densities: EndpointDensities {
            camera: Some((camera_fwd, camera_rev)),
            light: Some((light_fwd, light_rev)),
        },
    })
}

/// s = 0: z(t−1) lies on an area light or is the environment at infinity.
fn emitter_found<'a>(
    scene: &Scene,
    camera_path: &[Vertex<'a>],
    t: usize,
    hide_emitters: bool,
) -> Option<Connection<'a>> {
    if hide_emitters {
        // The emitter the camera ray hits first, and the environment behind `null`
        // surfaces only (pt's rule, Mitsuba 3's).
        let through_nulls_only = camera_path[1..t - 1].iter().all(Vertex::is_null_surface);
        if t == 2 || (camera_path[t - 1].is_infinite() && through_nulls_only) {
            return None;
        }
    }
    let pt = &camera_path[t - 1];
    let le = pt.emitted(scene);
    if le.is_black() {
        return None;
    }
    Some(Connection {
        value: pt.beta * le,
        shadow: None,
        raster: None,
        sampled: None,
        densities: EndpointDensities::default(),
    })
}

/// t = 1: y(s−1) joined to a camera point (light tracing).
fn light_vertex_to_camera<'a>(
    scene: &'a Scene,
    light_path: &[Vertex<'a>],
    start: Option<&LightStart>,
    s: usize,
    hide_emitters: bool,
    sampler: &mut impl Sampler,
) -> Option<Connection<'a>> {
    let qs = &light_path[s - 1];
    if !qs.is_connectible() {
        return None;
    }
    let u_lens = if scene.camera.has_lens() {
        sampler.next_2d()
    } else {
        Vec2::ZERO
    };
    let splat = match &qs.kind {
        VertexKind::Light { light, .. } => {
            if hide_emitters {
                return None;
            }
            let start = start?;
            camera_connection::connect_emitter(
                scene,
                scene.lights.get(*light),
                start.pmf,
                &start.emission,
                u_lens,
            )?
        }
        VertexKind::Surface { si, bsdf, frame } => camera_connection::connect_surface(
            scene, si, frame, bsdf, qs.wo, qs.beta, u_lens, true,
        )?,
        VertexKind::Infinite { .. } | VertexKind::Camera => return None,
    };
    Some(Connection {
        value: splat.value,
        shadow: Some(splat.shadow),
        raster: Some(splat.raster),
        sampled: Some(Sampled {
            vertex: Vertex::camera(splat.camera_position, Vec3::ZERO),
            light_side: false,
        }),
        // At the camera only the direction's density (no z(t−2) for t = 1).
        densities: EndpointDensities {
            camera: Some((splat.pdf_camera, 0.0)),
            light: splat.bsdf_densities,
        },
    })
}

/// The partial weight sums of a camera sample's two subpaths (`mis_sums`), filled once
/// after they are traced; every strategy's weight then costs O(1) (`weight`).
#[derive(Clone, Debug, Default)]
pub struct SubpathWeights {
    light: SubpathSums,
    camera: SubpathSums,
}

impl SubpathWeights {
    /// Fills the sums of `light_path` and `camera_path` as `mis` sees their vertices: a
    /// vertex connectible when a connection may end there (the light's own vertex always).
    pub fn fill(&mut self, light_path: &[Vertex], camera_path: &[Vertex], heuristic: Heuristic) {
        let light_hittable = light_path.first().is_some_and(|v| !v.is_delta_light());
        self.light.fill_light(
            light_path.iter().enumerate().map(|(i, v)| PathDensity {
                from_light: v.pdf_fwd,
                from_camera: v.pdf_rev,
                connectible: i == 0 || connectible(v),
            }),
            light_hittable,
            heuristic,
        );
        self.camera.fill_camera(
            camera_path.iter().map(|v| PathDensity {
                from_light: v.pdf_rev,
                from_camera: v.pdf_fwd,
                connectible: connectible(v),
            }),
            heuristic,
        );
    }
}

/// A connection may end at `v` (the walk did not leave it through a delta component).
fn connectible(v: &Vertex) -> bool {
    !v.delta && v.is_connectible()
}

/// The densities strategy (s, t) gives the two vertices on each side of its joint
/// (`mis_sums::Joint`), the endpoints replaced by what the strategy sampled (`sampled`) and
/// the densities the connection creates computed here; with the strategy rules that the
/// path's light imposes (with `heuristic` and `hide_emitters`).
#[allow(clippy::too_many_arguments)]
fn joint(
    scene: &Scene,
    light_path: &[Vertex],
    camera_path: &[Vertex],
    ends: ConnectionEnds,
    s: usize,
    t: usize,
    heuristic: Heuristic,
    hide_emitters: bool,
) -> (Joint, StrategyRules) {
    let sampled = ends.sampled;
    // The strategy's endpoints as vertices (the sampled one where there is one).
    let light_end = |i: usize| match sampled {
        Some(Sampled {
            vertex,
            light_side: true,
        }) if i == 0 => vertex,
        _ => &light_path[i],
    };
    let camera_end = |i: usize| match sampled {
        Some(Sampled {
            vertex,
            light_side: false,
        }) if i == 0 => vertex,
        _ => &camera_path[i],
    };
    let pt = camera_end(t - 1);
    let pt_minus = (t >= 2).then(|| camera_end(t - 2));
    let qs = (s >= 1).then(|| light_end(s - 1));
    let qs_minus = (s >= 2).then(|| light_end(s - 2));
    // Whatever their walks sampled next, the path leaves the connection's endpoints along
    // the connection, through non-delta components: both are connectible. The densities
    // the connection creates: of pt from the light side, of pt_minus from pt; of qs from
    // the camera side, of qs_minus from qs (from the BSDF densities the connection
    // evaluated where it did, converted to the measure of the vertex reached).
    let EndpointDensities {
        camera: at_pt,
        light: at_qs,
    } = ends.densities;
    let camera = [
        Some(PathDensity {
            from_light: match (qs, at_qs) {
                (Some(qs), Some((fwd, _))) => qs.to_area(fwd, pt),
                (Some(qs), None) => qs.pdf(scene, qs_minus, pt),
                (None, _) => {
                    pt.pdf_light_origin(scene, pt.direction_to(pt_minus.expect("s = 0 has t ≥ 2")))
                }
            },
            from_camera: pt.pdf_fwd,
            connectible: true,
        }),
        pt_minus.map(|pt_minus| PathDensity {
            from_light: match (qs, at_pt) {
                (Some(_), Some((_, rev))) => pt.to_area(rev, pt_minus),
                (Some(qs), None) => pt.pdf(scene, Some(qs), pt_minus),
                (None, _) => pt.pdf_light_direction(scene, pt_minus),
            },
            from_camera: pt_minus.pdf_fwd,
            connectible: connectible(pt_minus),
        }),
    ];
    let light = [
        qs.map(|qs| PathDensity {
            from_light: qs.pdf_fwd,
            from_camera: match at_pt {
                Some((fwd, _)) => pt.to_area(fwd, qs),
                None => pt.pdf(scene, pt_minus, qs),
            },
            connectible: true,
        }),
        qs_minus.map(|qs_minus| PathDensity {
            from_light: qs_minus.pdf_fwd,
            from_camera: match at_qs {
                Some((_, rev)) => qs.expect("s ≥ 2").to_area(rev, qs_minus),
                None => qs.expect("s ≥ 2").pdf(scene, Some(pt), qs_minus),
            },
            connectible: s == 2 || connectible(qs_minus),
        }),
    ];
    let x0 = if s >= 1 { light_end(0) } else { pt };
    let finite_area_light = matches!(x0.kind, VertexKind::Surface { .. })
        || matches!(x0.kind, VertexKind::Light { delta: false, .. });
    let rules = StrategyRules {
        heuristic,
        hide_emitters,
        light_hittable: !x0.is_delta_light(),
        light_seen_by_camera: finite_area_light,
    };
    (Joint { light, camera }, rules)
}

/// The weight of strategy (s, t) for the path it made: `mis::strategy_weight` over the
/// complete path (Veach 1997, eq. 10.9), computed from the joint's densities and the
/// subpaths' partial sums (`sums`, filled for these subpaths with this heuristic).
#[allow(clippy::too_many_arguments)]
pub fn weight(
    scene: &Scene,
    light_path: &[Vertex],
    camera_path: &[Vertex],
    ends: ConnectionEnds,
    s: usize,
    t: usize,
    heuristic: Heuristic,
    hide_emitters: bool,
    sums: &SubpathWeights,
) -> f32 {
    let (joint, rules) = joint(
        scene,
        light_path,
        camera_path,
        ends,
        s,
        t,
        heuristic,
        hide_emitters,
    );
    joint_weight(&joint, &sums.light, &sums.camera, s, t, &rules)
}
