//! Materials: the BSDFs of mltbench's Mitsuba 3 subset, plus the classic Phong, Blinn-Phong
//! and Ward models as mltbench extensions.
//!
//! # Contract (every model in this module keeps it)
//!
//! * **Local shading frame.** Directions are in the local frame whose normal is +z
//!   (`crate::math::Frame::to_local`). `wo` and `wi` both point *away* from the surface and
//!   are unit length. In a camera path (radiance transport) `wo` points back towards the
//!   camera and `wi` towards the light; in a light path (importance transport) the roles of
//!   the physical quantities swap but the arguments keep their meaning: `wo` is the direction
//!   the walk arrived from, `wi` the one it continues in.
//! * **`eval(wo, wi, mode)`** is the BSDF value f(wo, wi) *without* the cosine factor. Delta
//!   (specular) components contribute 0. One-sided models (`diffuse`, `conductor`,
//!   `roughconductor`, `plastic`, `roughplastic`, `phong`, `blinn`, `ward`) are zero when
//!   either direction is on or below the surface (cos θ ≤ 0); `twosided` mirrors both
//!   directions to the front when `wo` is below (and uses its `back` BSDF there).
//! * **`pdf(wo, wi)`** is the solid-angle density with which `sample(wo, …)` produces `wi`,
//!   counting only the non-delta components (lobe-selection probabilities included). It may
//!   integrate to less than one: the rest is the probability of a delta sample or of no
//!   sample at all (e.g. a microfacet reflection that would leave below the surface).
//! * **`sample(wo, u_lobe, u, mode)`** draws `wi`. `u_lobe` picks a component, `u` the
//!   direction. For a non-delta sample, `weight = f(wo, wi)·|cos θi| / pdf` and `pdf` equals
//!   `pdf(wo, wi)`. For a delta sample, `pdf` is the discrete probability of choosing that
//!   component and `weight` is its contribution divided by that probability. `eta` is the
//!   relative index of refraction crossed (IOR on `wi`'s side over IOR on `wo`'s side) for a
//!   refraction, 1 otherwise: Russian roulette multiplies it out of the throughput (Mitsuba 3
//!   continues with probability min(max(throughput)·η², 0.95)). `None` means no sample
//!   (degenerate or grazing input, or a direction the model cannot produce).
//! * **Transport mode.** Refraction compresses solid angle: radiance crossing from IOR η_wi
//!   to IOR η_wo is scaled by (η_wo/η_wi)² (Veach 1997, §5.2). This factor is part of `f`
//!   and of the sample weights in `TransportMode::Radiance` only; in
//!   `TransportMode::Importance` it is absent. As a consequence the radiance-mode
//!   transmission obeys the generalised reciprocity f(wo, wi)/η_wo² = f(wi, wo)/η_wi²
//!   (Veach 1997, eq. 5.14), and f_importance(wo, wi) = f_radiance(wi, wo).
//! * **Robustness.** No allocation per call; no NaN or infinity ever leaves these functions:
//!   grazing or degenerate configurations give black, a zero pdf, or `None`.
//!
//! Semantics follow Mitsuba 3 (see MITSUBA-NOTES.md): parameter meanings, lobe-selection
//! probabilities, the rough plastic's precomputed tables and which models are one-sided.

pub mod blinn;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
mod glossy_mix;
pub mod microfacet;
pub mod null;
pub mod phong;
pub mod plastic;
pub mod quadrature;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod rough_plastic;
pub mod thin_dielectric;
pub mod twosided;
pub mod ward;

use glam::{Vec2, Vec3};

use crate::math::Rgb;
use crate::scene::BsdfDesc;

pub use blinn::Blinn;
pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use microfacet::Microfacet;
pub use null::Null;
pub use phong::Phong;
pub use plastic::Plastic;
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::RoughPlastic;
pub use thin_dielectric::ThinDielectric;
pub use twosided::TwoSided;
pub use ward::Ward;

/// Which quantity a path carries: radiance (paths from the camera) or importance (paths from
/// the lights). Only refraction's solid-angle compression depends on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// One sampled direction (see the module contract).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction, unit length, pointing away from the surface.
    pub wi: Vec3,
    /// f·|cos θi|/pdf for a non-delta sample; the delta component's value over its discrete
    /// probability otherwise.
    pub weight: Rgb,
    /// Solid-angle pdf (non-delta) or discrete lobe probability (delta).
    pub pdf: f32,
    /// True when `wi` came from a delta (specular) component.
    pub delta: bool,
    /// IOR on `wi`'s side over IOR on `wo`'s side for a refraction, 1 for anything else.
    pub eta: f32,
}

impl BsdfSample {
    /// A sample of a component with a density that does not refract (η = 1).
    pub fn non_delta(wi: Vec3, weight: Rgb, pdf: f32) -> BsdfSample {
        BsdfSample {
            wi,
            weight,
            pdf,
            delta: false,
            eta: 1.0,
        }
    }
}

/// What kinds of components a BSDF has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BsdfFlags {
    /// Has a specular (Dirac delta) component: mirror reflection, smooth refraction, or a
    /// straight pass-through.
    pub delta: bool,
    /// Has a component with a density (diffuse or glossy): `eval`/`pdf` can be non-zero.
    pub non_delta: bool,
    /// Can send light to the other side of the surface.
    pub transmission: bool,
    /// Is the index-matched `null` boundary: rays continue unchanged.
    pub null: bool,
}

impl BsdfFlags {
    /// A model whose only components have a density and reflect (diffuse, glossy).
    pub const NON_DELTA_REFLECTION: BsdfFlags = BsdfFlags {
        delta: false,
        non_delta: true,
        transmission: false,
        null: false,
    };

    pub fn union(self, o: BsdfFlags) -> BsdfFlags {
        BsdfFlags {
            delta: self.delta || o.delta,
            non_delta: self.non_delta || o.non_delta,
            transmission: self.transmission || o.transmission,
            null: self.null && o.null,
        }
    }
}

/// What every model implements; `Bsdf` dispatches to it.
pub trait BsdfModel {
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb;
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// f(wo, wi) with the densities of sampling wi from wo and wo from wi (a path's two
    /// directions through a connection's endpoint) in one call; models whose evaluation
    /// and densities share work override it.
    fn eval_with_pdfs(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> (Rgb, f32, f32) {
        (self.eval(wo, wi, mode), self.pdf(wo, wi), self.pdf(wi, wo))
    }
    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample>;
    fn flags(&self) -> BsdfFlags;
}

/// A BSDF ready to evaluate and sample, built from a scene's `BsdfDesc`.
#[derive(Clone, Debug, PartialEq)]
pub enum Bsdf {
    Diffuse(Diffuse),
    Conductor(Conductor),
    RoughConductor(RoughConductor),
    Dielectric(Dielectric),
    ThinDielectric(ThinDielectric),
    RoughDielectric(RoughDielectric),
    Plastic(Plastic),
    RoughPlastic(Box<RoughPlastic>),
    TwoSided(Box<TwoSided>),
    Null(Null),
    Phong(Phong),
    Blinn(Blinn),
    Ward(Ward),
}

macro_rules! dispatch {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            Bsdf::Diffuse($m) => $e,
            Bsdf::Conductor($m) => $e,
            Bsdf::RoughConductor($m) => $e,
            Bsdf::Dielectric($m) => $e,
            Bsdf::ThinDielectric($m) => $e,
            Bsdf::RoughDielectric($m) => $e,
            Bsdf::Plastic($m) => $e,
            Bsdf::RoughPlastic($m) => $e,
            Bsdf::TwoSided($m) => $e,
            Bsdf::Null($m) => $e,
            Bsdf::Phong($m) => $e,
            Bsdf::Blinn($m) => $e,
            Bsdf::Ward($m) => $e,
        }
    };
}

impl Bsdf {
    /// Builds the BSDF a scene describes. `desc` holds Mitsuba 3 parameters with their
    /// defaults already applied; the loader has validated them (positive IORs, …). Values it
    /// could not have rejected are made safe here (e.g. α is clamped to at least 10⁻⁴, as
    /// Mitsuba does).
    pub fn from_desc(desc: &BsdfDesc) -> Bsdf {
        match desc {
            BsdfDesc::Diffuse { reflectance } => Bsdf::Diffuse(Diffuse::new(*reflectance)),
            // Away from any surface point: the texture's mean (`at_point` looks it up).
            BsdfDesc::Textured { base, .. } => Bsdf::from_desc(base),
            BsdfDesc::Conductor {
                eta_k,
                specular_reflectance,
            } => Bsdf::Conductor(Conductor::new(*eta_k, *specular_reflectance)),
            BsdfDesc::RoughConductor {
                eta_k,
                specular_reflectance,
                roughness,
            } => Bsdf::RoughConductor(RoughConductor::new(
                *eta_k,
                *specular_reflectance,
                Microfacet::from_roughness(roughness),
            )),
            BsdfDesc::Dielectric {
                ior,
                specular_reflectance,
                specular_transmittance,
            } => Bsdf::Dielectric(Dielectric::new(
                ior.int_ior / ior.ext_ior,
                *specular_reflectance,
                *specular_transmittance,
            )),
            BsdfDesc::ThinDielectric {
                ior,
                specular_reflectance,
                specular_transmittance,
            } => Bsdf::ThinDielectric(ThinDielectric::new(
                ior.int_ior / ior.ext_ior,
                *specular_reflectance,
                *specular_transmittance,
            )),
            BsdfDesc::RoughDielectric {
                ior,
                roughness,
                specular_reflectance,
                specular_transmittance,
            } => Bsdf::RoughDielectric(RoughDielectric::new(
                ior.int_ior / ior.ext_ior,
                Microfacet::from_roughness(roughness),
                *specular_reflectance,
                *specular_transmittance,
            )),
            BsdfDesc::Plastic {
                ior,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
            } => Bsdf::Plastic(Plastic::new(
                ior.int_ior / ior.ext_ior,
                *diffuse_reflectance,
                *specular_reflectance,
                *nonlinear,
            )),
            BsdfDesc::RoughPlastic {
                ior,
                diffuse_reflectance,
                specular_reflectance,
                roughness,
                nonlinear,
            } => Bsdf::RoughPlastic(Box::new(RoughPlastic::new(
                ior.int_ior / ior.ext_ior,
                *diffuse_reflectance,
                *specular_reflectance,
                Microfacet::from_roughness(roughness),
                *nonlinear,
            ))),
            BsdfDesc::TwoSided { front, back } => Bsdf::TwoSided(Box::new(TwoSided::new(
                Bsdf::from_desc(front),
                Bsdf::from_desc(back),
            ))),
            BsdfDesc::Null => Bsdf::Null(Null),
            BsdfDesc::Phong {
                exponent,
                diffuse_reflectance,
                specular_reflectance,
            } => Bsdf::Phong(Phong::new(
                *exponent,
                *diffuse_reflectance,
                *specular_reflectance,
            )),
            BsdfDesc::Blinn {
                exponent,
                diffuse_reflectance,
                specular_reflectance,
            } => Bsdf::Blinn(Blinn::new(
                *exponent,
                *diffuse_reflectance,
                *specular_reflectance,
            )),
            BsdfDesc::Ward {
                alpha_u,
                alpha_v,
                diffuse_reflectance,
                specular_reflectance,
            } => Bsdf::Ward(Ward::new(
                *alpha_u,
                *alpha_v,
                *diffuse_reflectance,
                *specular_reflectance,
            )),
        }
    }

    /// This BSDF (built from `desc`) at surface coordinates `uv`: every texture of `desc`
    /// looked up there.
    pub fn at_point(&self, desc: &BsdfDesc, uv: Vec2) -> Bsdf {
        match (desc, self) {
            (BsdfDesc::Textured { diffuse, .. }, _) => {
                self.with_diffuse_reflectance(diffuse.eval(uv))
            }
            (BsdfDesc::TwoSided { front, back }, Bsdf::TwoSided(t)) => Bsdf::TwoSided(Box::new(
                TwoSided::new(t.front.at_point(front, uv), t.back.at_point(back, uv)),
            )),
            _ => self.clone(),
        }
    }

    /// The same BSDF with diffuse reflectance `rho` (`diffuse`, `plastic`, `roughplastic`;
    /// other models, which have none, are returned unchanged).
    pub fn with_diffuse_reflectance(&self, rho: Rgb) -> Bsdf {
        match self {
            Bsdf::Diffuse(_) => Bsdf::Diffuse(Diffuse::new(rho)),
            Bsdf::Plastic(p) => Bsdf::Plastic(p.with_diffuse_reflectance(rho)),
            Bsdf::RoughPlastic(p) => Bsdf::RoughPlastic(Box::new(p.with_diffuse_reflectance(rho))),
            other => other.clone(),
        }
    }

    /// f(wo, wi) without the cosine factor; 0 for delta components.
    pub fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        dispatch!(self, m => m.eval(wo, wi, mode))
    }

    /// Solid-angle density of `sample` producing `wi` (non-delta components only).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        dispatch!(self, m => m.pdf(wo, wi))
    }

    /// (`eval(wo, wi)`, `pdf(wo, wi)`, `pdf(wi, wo)`) in one call.
    #[inline]
    pub fn eval_with_pdfs(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> (Rgb, f32, f32) {
        dispatch!(self, m => m.eval_with_pdfs(wo, wi, mode))
    }

    /// Samples a direction `wi` given `wo` (see the module contract).
    pub fn sample(
        &self,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        dispatch!(self, m => m.sample(wo, u_lobe, u, mode))
    }

    pub fn flags(&self) -> BsdfFlags {
        dispatch!(self, m => m.flags())
    }

    /// Has a diffuse or glossy component (worth connecting to / evaluating).
    pub fn has_non_delta(&self) -> bool {
        self.flags().non_delta
    }

    /// Has a specular component.
    pub fn has_delta(&self) -> bool {
        self.flags().delta
    }

    /// Only specular components: `eval` and `pdf` are always zero.
    pub fn is_delta_only(&self) -> bool {
        let f = self.flags();
        f.delta && !f.non_delta
    }

    /// Can send light through the surface.
    pub fn has_transmission(&self) -> bool {
        self.flags().transmission
    }

    /// The index-matched boundary: the ray continues unchanged (`sample` returns −wo with
    /// weight 1). Integrators usually skip such surfaces without counting a bounce.
    pub fn is_null(&self) -> bool {
        self.flags().null
    }
}

/// Mirror reflection about the shading normal (+z).
#[inline]
pub fn reflect_z(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// Mirror reflection of `w` about the unit vector `m`: 2(w·m)m − w.
#[inline]
pub fn reflect_about(w: Vec3, m: Vec3) -> Vec3 {
    2.0 * w.dot(m) * m - w
}

/// Completes a sampled reflection direction `wi` of a non-delta, reflection-only model:
/// its pdf, and the weight f·cos θi/pdf; None below the surface or for a degenerate pdf.
pub(crate) fn reflection_sample(
    model: &impl BsdfModel,
    wo: Vec3,
    wi: Vec3,
    mode: TransportMode,
) -> Option<BsdfSample> {
    if wi.z <= 0.0 {
        return None;
    }
    let pdf = model.pdf(wo, wi);
    if !(pdf > 0.0 && pdf.is_finite()) {
        return None;
    }
    let weight = model.eval(wo, wi, mode) * (wi.z / pdf);
    valid_weight(weight).then_some(BsdfSample::non_delta(wi, weight, pdf))
}

/// A weight that must be finite and non-negative, or the sample is dropped.
#[inline]
pub(crate) fn valid_weight(w: Rgb) -> bool {
    w.is_valid_radiance()
}

/// Mean of a colour's channels, clamped to be non-negative (lobe-selection weights).
#[inline]
pub(crate) fn mean_nonneg(c: Rgb) -> f32 {
    c.mean().max(0.0)
}
