//! Path vertices and the densities bidirectional estimators weigh them by.
//!
//! A subpath is a list of vertices: the camera or a light first, then the surfaces its
//! random walk met (and, for a camera subpath that escapes the scene, the environment in
//! the direction it escaped). Each vertex keeps the throughput β of the subpath up to it,
//! and two densities:
//!
//! * `pdf_fwd`: of the vertex being produced by its own subpath's sampling from the
//!   previous vertex;
//! * `pdf_rev`: of it being produced by the other direction's sampling, from the vertex
//!   after it (filled in when the next vertex is sampled, and for the connection's
//!   endpoints by the strategy that connects them).
//!
//! The measure is **area** at points of the scene (per unit area; at the pinhole or a point
//! light, which have no area, the direction's density stands in), and **solid angle** at
//! infinity (a vertex at infinity is a direction). A ray from infinity (a light at infinity
//! emitting through the scene's bounding disk) gives the point it reaches the density of its
//! disk point times the cosine there: the disk is perpendicular to the ray.
//!
//! A vertex whose subpath left it through a delta (specular) component has `delta` set: no
//! strategy connects there, but its densities are real numbers, not zeros (see
//! `random_walk` and the README's Design section: the density of a delta vertex in
//! projected solid angle), so that the ratios between strategies keep every factor that
//! does not cancel (Veach 1997, §10.3.5).

use std::borrow::Cow;

use glam::Vec3;

use crate::geometry::SurfaceInteraction;
use crate::light::LightPoint;
use crate::material::Bsdf;
use crate::math::{Frame, Rgb};
use crate::scene::Scene;

/// What a vertex is.
#[derive(Clone, Debug)]
pub enum VertexKind<'a> {
    /// The pinhole or a point of the lens.
    Camera,
    /// A point of light `light` (index in the scene's `LightSet`) at a finite position;
    /// `delta` for point and spot lights (no ray can hit them).
    Light { light: usize, delta: bool },
    /// A direction at infinity (`Vertex::p` is the unit direction from the scene towards
    /// it): the start of a light subpath from light `light` (`directional`, `constant`,
    /// `envmap`; `delta` for directional lights, which no ray can hit), or, with `light`
    /// None, where a camera subpath escaped the scene: the environment, all of the scene's
    /// `constant` and `envmap` emitters together.
    Infinite { light: Option<usize>, delta: bool },
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
    /// The position; for a vertex at infinity the unit direction towards it.
    pub p: Vec3,
    /// Geometric normal; zero for points without a surface (pinhole, point lights); for a
    /// vertex at infinity −`p` (facing the scene).
    pub ng: Vec3,
    /// Throughput of the subpath up to and including this vertex's sampling density.
    pub beta: Rgb,
    pub pdf_fwd: f32,
    pub pdf_rev: f32,
    /// The BSDF sample that left this vertex was a delta component.
    pub delta: bool,
    /// A connection can end here: a surface whose BSDF has a non-delta component, any
    /// light, the camera (`is_connectible`, kept so that weights need not ask the BSDF).
    connectible: bool,
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
            connectible: true,
            wo: Vec3::ZERO,
        }
    }

    /// A point of light `light` at a finite position, with origin density `pdf`.
    pub fn light(light: usize, delta: bool, p: Vec3, ng: Vec3, beta: Rgb, pdf: f32) -> Self {
        Vertex {
            kind: VertexKind::Light { light, delta },
            p,
            ng,
            beta,
            pdf_fwd: pdf,
            pdf_rev: 0.0,
            delta: false,
            connectible: true,
            wo: Vec3::ZERO,
        }
    }

    /// The direction `towards` at infinity: of light `light`, or (None) the environment a
    /// camera subpath escaped to, with throughput `beta`.
    pub fn at_infinity(light: Option<usize>, delta: bool, towards: Vec3, beta: Rgb) -> Self {
        Vertex {
            kind: VertexKind::Infinite { light, delta },
            p: towards,
            ng: -towards,
            beta,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            connectible: true,
            wo: Vec3::ZERO,
        }
    }

    /// A surface vertex reached along `wo`'s opposite with throughput `beta`.
    pub fn surface(scene: &'a Scene, si: SurfaceInteraction, wo: Vec3, beta: Rgb) -> Self {
        let bsdf = scene.bsdf_at(&si);
        let connectible = bsdf.has_non_delta();
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
            connectible,
            wo,
        }
    }

    /// True when a connection can end here: a surface with a non-delta component, any
    /// light, the camera.
    #[inline]
    pub fn is_connectible(&self) -> bool {
        self.connectible
    }

    /// A light that no ray can hit: a point, spot or directional light.
    pub fn is_delta_light(&self) -> bool {
        matches!(
            self.kind,
            VertexKind::Light { delta: true, .. } | VertexKind::Infinite { delta: true, .. }
        )
    }

    pub fn is_infinite(&self) -> bool {
        matches!(self.kind, VertexKind::Infinite { .. })
    }

    /// A surface whose BSDF is the index-matched `null` boundary.
    pub fn is_null_surface(&self) -> bool {
        matches!(&self.kind, VertexKind::Surface { bsdf, .. } if bsdf.is_null())
    }

    /// A surface vertex a connection can end at: its interaction, BSDF and shading frame.
    #[inline]
    pub fn connectible_surface(&self) -> Option<(&SurfaceInteraction, &Bsdf, &Frame)> {
        match &self.kind {
            VertexKind::Surface { si, bsdf, frame } if self.connectible => Some((si, bsdf, frame)),
            _ => None,
        }
    }

    /// The surface interaction of a surface vertex.
    pub fn si(&self) -> Option<&SurfaceInteraction> {
        match &self.kind {
            VertexKind::Surface { si, .. } => Some(si),
            _ => None,
        }
    }

    /// The unit direction from this vertex to `next` (either may be at infinity).
    #[inline]
    pub fn direction_to(&self, next: &Vertex) -> Vec3 {
        if next.is_infinite() {
            next.p
        } else if self.is_infinite() {
            -self.p
        } else {
            (next.p - self.p).normalize_or_zero()
        }
    }

    /// Converts a density of the ray leaving this vertex towards `next` to `next`'s measure
    /// (Veach 1997, eq. 8.10): a solid-angle density × |cos θ_next| / d² (the cosine only
    /// where `next` lies on a surface); unchanged when `next` is at infinity (a direction);
    /// from a vertex at infinity, whose rays are parallel, a density per unit area of the
    /// emission disk × |cos θ_next|.
    #[inline]
    pub fn to_area(&self, pdf: f32, next: &Vertex) -> f32 {
        if next.is_infinite() {
            return pdf;
        }
        if self.is_infinite() {
            let pdf = pdf * next.ng.dot(self.p).abs();
            return if pdf.is_finite() { pdf } else { 0.0 };
        }
        let d = next.p - self.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return 0.0;
        }
        let mut pdf = pdf / dist2;
        if next.ng != Vec3::ZERO {
            pdf *= next.ng.dot(d / dist2.sqrt()).abs();
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    /// The density in `next`'s measure with which this vertex's sampling produces it,
    /// given that the subpath reached this vertex from `prev` (None for the camera or a
    /// light, which need none): the BSDF's density for a surface, the camera's direction
    /// density, a light's emission direction density, the emission disk's for a vertex at
    /// infinity. Connections never end at a delta vertex, so this is only asked of
    /// non-delta sampling.
    #[inline]
    pub fn pdf(&self, scene: &Scene, prev: Option<&Vertex>, next: &Vertex) -> f32 {
        if self.is_infinite() || next.is_infinite() {
            let pdf = self.pdf_solid_angle(scene, prev, self.direction_to(next));
            return self.to_area(pdf, next);
        }
        // `to_area` with the distance computed once.
        let d = next.p - self.p;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return 0.0;
        }
        let w = d / dist2.sqrt();
        let mut pdf = self.pdf_solid_angle(scene, prev, w) / dist2;
        if next.ng != Vec3::ZERO {
            pdf *= next.ng.dot(w).abs();
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    /// The density per unit solid angle (per unit area of the emission disk at infinity) of
    /// this vertex's sampling leaving in unit direction `w`.
    #[inline]
    fn pdf_solid_angle(&self, scene: &Scene, prev: Option<&Vertex>, w: Vec3) -> f32 {
        match &self.kind {
            VertexKind::Surface { bsdf, frame, .. } => {
                let Some(prev) = prev else { return 0.0 };
                let wp = self.direction_to(prev);
                bsdf.pdf(frame.to_local(wp), frame.to_local(w))
            }
            VertexKind::Camera => scene.camera.pdf_direction_from(self.p, w),
            VertexKind::Light { light, .. } => {
                scene.lights.get(*light).pdf_le(self.p, self.ng, w).1
            }
            VertexKind::Infinite { .. } => scene.lights.sphere().disk_pdf(),
        }
    }

    /// For a vertex on an emitter (a light vertex, a camera-subpath surface vertex on an
    /// area light, a direction at infinity): the density with which a light subpath starts
    /// here, choice of the light included (area measure; solid angle at infinity). 0 when
    /// it is on no light.
    ///
    /// At infinity the direction is what is sampled, and every `constant` and `envmap`
    /// emitter could have sampled it: its density is Σ_j p_choose(j) p_dir,j(ω), the
    /// environment taken as one emitter (a directional light's own direction is a delta:
    /// its choice probability stands for it).
    /// `w` is the unit direction the light subpath leaves in (unused at infinity).
    pub fn pdf_light_origin(&self, scene: &Scene, w: Vec3) -> f32 {
        let lights = &scene.lights;
        if let VertexKind::Infinite { light, delta } = self.kind {
            if delta {
                return light.map_or(0.0, |l| lights.pmf(l));
            }
            let travel = -self.p;
            return lights
                .environment()
                .iter()
                .map(|&j| lights.pmf(j) * lights.get(j).pdf_le(Vec3::ZERO, travel, travel).1)
                .sum();
        }
        let Some(light) = self.light_index(scene) else {
            return 0.0;
        };
        lights.pmf(light) * lights.get(light).pdf_le(self.p, self.ng, w).0
    }

    /// For a vertex on an emitter: the density at `towards` (in its measure) of the light's
    /// emission sampling.
    pub fn pdf_light_direction(&self, scene: &Scene, towards: &Vertex) -> f32 {
        if self.is_infinite() {
            return self.to_area(scene.lights.sphere().disk_pdf(), towards);
        }
        let Some(light) = self.light_index(scene) else {
            return 0.0;
        };
        let w = self.direction_to(towards);
        self.to_area(
            scene.lights.get(light).pdf_le(self.p, self.ng, w).1,
            towards,
        )
    }

    /// The light this vertex lies on, if any (None at infinity: see `pdf_light_origin`).
    pub fn light_index(&self, scene: &Scene) -> Option<usize> {
        match &self.kind {
            VertexKind::Light { light, .. } => Some(*light),
            VertexKind::Surface { si, .. } => scene.lights.light_of_shape(si.shape as usize),
            VertexKind::Camera | VertexKind::Infinite { .. } => None,
        }
    }

    /// The radiance a camera subpath that ends here receives from an emitter: an area
    /// light's towards `wo`, or the environment's along the escaped direction. Black
    /// elsewhere.
    pub fn emitted(&self, scene: &Scene) -> Rgb {
        let lights = &scene.lights;
        match &self.kind {
            VertexKind::Surface { si, .. } => match lights.light_of_shape(si.shape as usize) {
                Some(light) => lights.get(light).le(&LightPoint::from(si), self.wo),
                None => Rgb::BLACK,
            },
            VertexKind::Infinite { light: None, .. } => {
                let point = LightPoint::direction(self.p);
                lights
                    .environment()
                    .iter()
                    .fold(Rgb::BLACK, |sum, &j| sum + lights.get(j).le(&point, self.p))
            }
            _ => Rgb::BLACK,
        }
    }
}
