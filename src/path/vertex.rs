//! Path vertices and the densities bidirectional estimators weigh them by (DESIGN.md §2).
//!
//! A subpath is a list of vertices: the camera or a light first, then the surfaces its
//! random walk met. Each vertex keeps the throughput β of the subpath up to it, and two
//! densities in **area measure** (per unit area at the vertex; per unit solid angle where
//! the vertex is a point, the pinhole or a point light, has no area):
//!
//! * `pdf_fwd`: of the vertex being produced by its own subpath's sampling from the
//!   previous vertex;
//! * `pdf_rev`: of it being produced by the other direction's sampling, from the vertex
//!   after it (filled in when the next vertex is sampled, and for the connection's
//!   endpoints by the strategy that connects them).
//!
//! Multiple importance sampling over all ways (s, t) of cutting a path into a light and a
//! camera subpath needs only these ratios (Veach 1997, §10.2–10.3). Delta (specular)
//! vertices carry density 0 both ways: no strategy can connect at them.

use std::borrow::Cow;

use glam::Vec3;

use crate::geometry::SurfaceInteraction;
use crate::material::Bsdf;
use crate::math::{Frame, Rgb};
use crate::scene::Scene;

/// What a vertex is.
#[derive(Clone, Debug)]
pub enum VertexKind<'a> {
    /// The pinhole or a point of the lens.
    Camera,
    /// A point of light `light` (index in the scene's `LightSet`); `delta_pos` for point
    /// and spot lights.
    Light { light: usize, delta_pos: bool },
    /// A surface point with its BSDF and shading frame.
    Surface {
        si: SurfaceInteraction,
        bsdf: Cow<'a, Bsdf>,
        frame: Frame,
    },
}

#[derive(Clone, Debug)]
pub struct Vertex<'a> {
    pub kind: VertexKind<'a>,
    pub p: Vec3,
    /// Geometric normal; zero for points without a surface (pinhole, point lights).
    pub ng: Vec3,
    /// Throughput of the subpath up to and including this vertex's sampling density.
    pub beta: Rgb,
    pub pdf_fwd: f32,
    pub pdf_rev: f32,
    /// The BSDF sample that left this vertex was a delta component.
    pub delta: bool,
    /// Unit world direction towards the previous vertex of its subpath (surfaces).
    pub wo: Vec3,
}

impl<'a> Vertex<'a> {
    pub fn camera(p: Vec3, ng: Vec3) -> Vertex<'a> {
        Vertex {
            kind: VertexKind::Camera,
            p,
            ng,
            beta: Rgb::WHITE,
            pdf_fwd: 1.0,
            pdf_rev: 0.0,
            delta: false,
            wo: Vec3::ZERO,
        }
    }

    pub fn light(light: usize, delta_pos: bool, p: Vec3, ng: Vec3, beta: Rgb, pdf: f32) -> Self {
        Vertex {
            kind: VertexKind::Light { light, delta_pos },
            p,
            ng,
            beta,
            pdf_fwd: pdf,
            pdf_rev: 0.0,
            delta: false,
            wo: Vec3::ZERO,
        }
    }

    /// A surface vertex reached along `wo`'s opposite with throughput `beta`.
    pub fn surface(scene: &'a Scene, si: SurfaceInteraction, wo: Vec3, beta: Rgb) -> Self {
        let bsdf = scene.bsdf_at(&si);
        Vertex {
            p: si.p,
            ng: si.ng,
            kind: VertexKind::Surface {
                frame: si.frame(),
                bsdf,
                si,
            },
            beta,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            wo,
        }
    }

    /// True when a connection can end here: a surface with a non-delta component, any
    /// light, the camera.
    pub fn is_connectible(&self) -> bool {
        match &self.kind {
            VertexKind::Surface { bsdf, .. } => bsdf.has_non_delta(),
            _ => true,
        }
    }

    pub fn is_delta_light(&self) -> bool {
        matches!(
            self.kind,
            VertexKind::Light {
                delta_pos: true,
                ..
            }
        )
    }

    /// The surface interaction of a surface vertex.
    pub fn si(&self) -> Option<&SurfaceInteraction> {
        match &self.kind {
            VertexKind::Surface { si, .. } => Some(si),
            _ => None,
        }
    }

    /// Converts a solid-angle density at this vertex, for the direction towards `next`,
    /// to area measure at `next` (Veach 1997, eq. 8.10): × |cos θ_next| / d², the cosine
    /// only where `next` lies on a surface.
    pub fn to_area(&self, pdf_solid_angle: f32, next: &Vertex) -> f32 {
        let d = next.p - self.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return 0.0;
        }
        let mut pdf = pdf_solid_angle / dist2;
        if next.ng != Vec3::ZERO {
            pdf *= next.ng.dot(d / dist2.sqrt()).abs();
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    /// The area density at `next` with which this vertex's sampling produces it, given
    /// that the subpath reached this vertex from `prev` (None for the camera or a light,
    /// which need none): the BSDF's density for a surface, the camera's direction density,
    /// a light's emission direction density.
    pub fn pdf(&self, scene: &Scene, prev: Option<&Vertex>, next: &Vertex) -> f32 {
        let w = (next.p - self.p).normalize_or_zero();
        let pdf = match &self.kind {
            VertexKind::Surface { bsdf, frame, .. } => {
                let Some(prev) = prev else { return 0.0 };
                let wp = (prev.p - self.p).normalize_or_zero();
                bsdf.pdf(frame.to_local(wp), frame.to_local(w))
            }
            VertexKind::Camera => scene.camera.pdf_direction_from(self.p, w),
            VertexKind::Light { light, .. } => {
                scene.lights.get(*light).pdf_le(self.p, self.ng, w).1
            }
        };
        self.to_area(pdf, next)
    }

    /// For a vertex on an emitter (a light vertex, or a camera-subpath surface vertex on an
    /// area light): the area density with which a light subpath starts here, choice of the
    /// light included. 0 when it is on no light.
    pub fn pdf_light_origin(&self, scene: &Scene, towards: &Vertex) -> f32 {
        let Some(light) = self.light_index(scene) else {
            return 0.0;
        };
        let w = (towards.p - self.p).normalize_or_zero();
        scene.lights.pmf(light) * scene.lights.get(light).pdf_le(self.p, self.ng, w).0
    }

    /// For a vertex on an emitter: the area density at `towards` of the light's emission
    /// direction sampling.
    pub fn pdf_light_direction(&self, scene: &Scene, towards: &Vertex) -> f32 {
        let Some(light) = self.light_index(scene) else {
            return 0.0;
        };
        let w = (towards.p - self.p).normalize_or_zero();
        self.to_area(
            scene.lights.get(light).pdf_le(self.p, self.ng, w).1,
            towards,
        )
    }

    /// The light this vertex lies on, if any.
    pub fn light_index(&self, scene: &Scene) -> Option<usize> {
        match &self.kind {
            VertexKind::Light { light, .. } => Some(*light),
            VertexKind::Surface { si, .. } => scene.lights.light_of_shape(si.shape as usize),
            VertexKind::Camera => None,
        }
    }
}
