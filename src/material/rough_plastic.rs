//! Rough plastic (Mitsuba `roughplastic`): a diffuse base under a rough dielectric coating.
//!
//! * Specular lobe: microfacet reflection off the coating (Walter et al. 2007, eq. 20) with
//!   the dielectric Fresnel term, times `specular_reflectance`.
//! * Diffuse lobe: R_d / (1 − F_int) · t(θo) t(θi) / (π η²), where t(θ) is the fraction of
//!   light the rough interface transmits into the coating from direction θ (its
//!   single-scattering transmission albedo, 1 minus what it reflects or loses to masking)
//!   and F_int the internal diffuse reflectance of the interface seen from inside.
//!   `nonlinear` uses R_d / (1 − R_d F_int) instead.
//!
//! Both t and F_int are integrals over the visible microfacet normals, precomputed when the
//! BSDF is built exactly as Mitsuba 3 lays them out: t tabulated at 64 cosines
//! μ_k = max(10⁻⁶, k/63) and linearly interpolated; F_int = 2·mean_k(R_int(μ_k) μ_k), with
//! R_int the interface's reflectance albedo from inside. The per-direction albedos are
//! Gauss–Legendre rules over the unit square mapped through visible-normal sampling (32² nodes
//! when entering the denser side, 64² when leaving it, where total internal reflection makes
//! the integrand kinked; both within 1e-4 of the converged integrals). Isotropic only:
//! `alpha_u` is used.
//!
//! Sampling picks the specular lobe with probability ∝ (1 − t(θo))·s̄ against t(θo)·d̄.

use glam::{Vec2, Vec3};

use crate::material::fresnel::{fresnel_dielectric, refract_about};
use crate::material::glossy_mix::sample_mixture;
use crate::material::microfacet::beckmann_visible_slopes;
use crate::material::plastic::{internal_scattering, lobe_weight};
use crate::material::quadrature::gauss_legendre;
use crate::material::{
    BsdfFlags, BsdfModel, BsdfSample, Microfacet, TransportMode, reflect_about, valid_weight,
};
use crate::math::warp::cosine_hemisphere_pdf;
use crate::math::{INV_PI, Rgb};
use crate::scene::MicrofacetKind;

/// Number of tabulated cosines (Mitsuba's MI_ROUGH_TRANSMITTANCE_RES).
pub const TABLE_SIZE: usize = 64;

/// Largest Gauss–Legendre order used for the tables.
const MAX_NODES: usize = 64;

#[derive(Clone, Debug, PartialEq)]
pub struct RoughPlastic {
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub distribution: Microfacet,
    pub nonlinear: bool,
    inv_eta2: f32,
    specular_weight: f32,
    /// t(μ_k): transmission albedo of the rough interface from outside.
    external_transmittance: [f32; TABLE_SIZE],
    /// F_int: diffuse reflectance of the rough interface from inside.
    internal_reflectance: f32,
    diffuse_scaled: Rgb,
}

impl RoughPlastic {
    pub fn new(
        eta: f32,
        diffuse: Rgb,
        specular: Rgb,
        distribution: Microfacet,
        nonlinear: bool,
    ) -> Self {
        let eta = if eta.is_finite() && eta > 0.0 {
            eta
        } else {
            1.0
        };
        let distribution = Microfacet::new(
            distribution.kind,
            distribution.alpha_u,
            distribution.alpha_u,
            distribution.sample_visible,
        );
        let (external_transmittance, internal_reflectance) =
            interface_tables(distribution.kind, distribution.alpha_u, eta);
        RoughPlastic {
            eta,
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            distribution,
            nonlinear,
            inv_eta2: 1.0 / (eta * eta),
            specular_weight: lobe_weight(specular, diffuse),
            external_transmittance,
            internal_reflectance,
            diffuse_scaled: internal_scattering(diffuse, internal_reflectance, nonlinear),
        }
    }

    /// The same plastic with diffuse reflectance `diffuse` (a texture's value at a point).
    /// The tables depend on η and α only; the lobe-selection weight stays, as Mitsuba 3
    /// sets it once from the texture's mean.
    pub fn with_diffuse_reflectance(&self, diffuse: Rgb) -> Self {
        RoughPlastic {
            diffuse_reflectance: diffuse,
            diffuse_scaled: internal_scattering(diffuse, self.internal_reflectance, self.nonlinear),
            ..self.clone()
        }
    }

    /// The tabulated transmission albedo t(μ) (linear interpolation).
    pub fn external_transmittance(&self, cos_theta: f32) -> f32 {
        let x = cos_theta.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let w = x - i as f32;
        let t = &self.external_transmittance;
        (1.0 - w) * t[i] + w * t[i + 1]
    }

    /// F_int, the internal diffuse reflectance of the rough interface.
    pub fn internal_reflectance(&self) -> f32 {
        self.internal_reflectance
    }

    fn lobe_probabilities(&self, t_o: f32) -> (f32, f32) {
        let ps = (1.0 - t_o) * self.specular_weight;
        let pd = t_o * (1.0 - self.specular_weight);
        let total = ps + pd;
        if total > 0.0 {
            (ps / total, pd / total)
        } else {
            (0.0, 0.0)
        }
    }
}

impl BsdfModel for RoughPlastic {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let mut value = Rgb::BLACK;
        let h = (wo + wi).normalize_or_zero();
        if h != Vec3::ZERO {
            let dist = &self.distribution;
            let d = dist.d(h);
            if d > 0.0 {
                let f = fresnel_dielectric(wo.dot(h), self.eta).f;
                let g = dist.g(wo, wi, h);
                let s = f * d * g / (4.0 * wo.z * wi.z);
                if s.is_finite() {
                    value = self.specular_reflectance * s;
                }
            }
        }
        let t_o = self.external_transmittance(wo.z);
        let t_i = self.external_transmittance(wi.z);
        value += self.diffuse_scaled * (INV_PI * self.inv_eta2 * t_o * t_i);
        if valid_weight(value) {
            value
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let (ps, pd) = self.lobe_probabilities(self.external_transmittance(wo.z));
        let mut p = pd * cosine_hemisphere_pdf(wi);
        let h = (wo + wi).normalize_or_zero();
        let wi_h = wi.dot(h);
        if h != Vec3::ZERO && wi_h > 0.0 && ps > 0.0 {
            p += ps * self.distribution.reflection_pdf(wo, h, wi_h);
        }
        p
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 || !wo.is_finite() {
            return None;
        }
        let (ps, _) = self.lobe_probabilities(self.external_transmittance(wo.z));
        sample_mixture(self, wo, u_lobe, u, mode, ps, |u| {
            let (m, pdf_m) = self.distribution.sample_normal(wo, u);
            (pdf_m > 0.0).then(|| reflect_about(wo, m).normalize_or_zero())
        })
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}

/// The cosine of table entry k (Mitsuba's layout).
fn table_cosine(k: usize) -> f32 {
    (k as f32 / (TABLE_SIZE - 1) as f32).max(1e-6)
}

/// (t(μ_k) for every k, F_int) for an isotropic interface of roughness `alpha` and relative
/// IOR `eta` (inside over outside).
fn interface_tables(kind: MicrofacetKind, alpha: f32, eta: f32) -> ([f32; TABLE_SIZE], f32) {
    let dist = Microfacet::new(kind, alpha, alpha, true);
    // Gauss–Legendre orders: Mitsuba uses 32² entering the coating and 128² leaving it;
    // 64² for the latter is within 1e-4 of the converged integral (as is 128²) at half
    // the construction time.
    let res = |e: f32| if e > 1.0 { 32 } else { 64 };
    let ext_rule = gauss_legendre(res(eta));
    let int_rule = gauss_legendre(res(1.0 / eta));
    let mut transmittance = [0.0f32; TABLE_SIZE];
    let mut internal_sum = 0.0f64;
    for (k, t) in transmittance.iter_mut().enumerate() {
        let mu = table_cosine(k);
        let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        *t = interface_albedo(&dist, wi, eta, &ext_rule, Albedo::Transmission) as f32;
        let r = interface_albedo(&dist, wi, 1.0 / eta, &int_rule, Albedo::Reflection);
        internal_sum += r * mu as f64;
    }
    let internal = (2.0 * internal_sum / TABLE_SIZE as f64) as f32;
    (transmittance, internal)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Albedo {
    Reflection,
    Transmission,
}

/// Single-scattering albedo of a rough dielectric interface (relative IOR `eta`, far side
/// over `wi`'s side) for light from `wi` (in the xz-plane, above): the expectation over
/// visible normals m of F(wi·m)·G1(wr, m) for reflection, (1 − F)·G1(wt, m) for
/// transmission, with a tensor Gauss–Legendre rule over the square the sampler maps from.
fn interface_albedo(
    dist: &Microfacet,
    wi: Vec3,
    eta: f32,
    rule: &(Vec<f64>, Vec<f64>),
    which: Albedo,
) -> f64 {
    let (nodes, weights) = rule;
    let n = nodes.len();
    let alpha = dist.alpha_u;
    // wi in the stretched (α = 1) configuration; its azimuth is 0.
    let stretched = Vec3::new(alpha * wi.x, 0.0, wi.z).normalize();
    // The sampler's work that depends on one coordinate only is done once per node: for
    // Beckmann the x-slope depends on u1 and the y-slope on u2; for GGX (Heitz 2018's
    // construction, wi's azimuth 0) the radius √u1 and the angle 2πu2.
    let mut along_u1 = [0.0f32; MAX_NODES];
    let mut along_u2 = [(0.0f32, 0.0f32); MAX_NODES];
    for i in 0..n {
        let u = 0.5 * (nodes[i] + 1.0);
        match dist.kind {
            MicrofacetKind::Beckmann => {
                let (sx, sy) = beckmann_visible_slopes(stretched.z as f64, u, u);
                along_u1[i] = sx as f32;
                along_u2[i] = (sy as f32, 0.0);
            }
            MicrofacetKind::Ggx => {
                along_u1[i] = (u as f32).sqrt();
                along_u2[i] = (2.0 * std::f32::consts::PI * u as f32).sin_cos();
            }
        }
    }
    // GGX: the frame of the projected hemisphere around the stretched wi.
    let t1 = if stretched.x > 0.0 { Vec3::Y } else { Vec3::X };
    let t2 = stretched.cross(t1);
    let s = 0.5 * (1.0 + stretched.z);
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let m = match dist.kind {
                MicrofacetKind::Beckmann => {
                    Vec3::new(-alpha * along_u1[i], -alpha * along_u2[j].0, 1.0).normalize()
                }
                MicrofacetKind::Ggx => {
                    let r = along_u1[i];
                    let (sin_phi, cos_phi) = along_u2[j];
                    let p1 = r * cos_phi;
                    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin_phi;
                    let nh =
                        p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * stretched;
                    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize_or_zero()
                }
            };
            if m.z <= 0.0 {
                continue;
            }
            let fr = fresnel_dielectric(wi.dot(m), eta);
            let value = match which {
                Albedo::Reflection => {
                    let wr = reflect_about(wi, m);
                    if wr.z > 0.0 {
                        fr.f * dist.g1(wr, m)
                    } else {
                        0.0
                    }
                }
                Albedo::Transmission => {
                    let wt = refract_about(wi, m, fr.cos_theta_t, fr.eta_ti);
                    if wt.z < 0.0 {
                        (1.0 - fr.f) * dist.g1(wt, m)
                    } else {
                        0.0
                    }
                }
            };
            sum += weights[i] * weights[j] * value as f64;
        }
    }
    0.25 * sum
}
