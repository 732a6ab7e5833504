//! Rough conductor (Mitsuba `roughconductor`): the microfacet reflection model of Walter et
//! al. 2007 (eq. 20), f = F(wo·h) D(h) G(wo, wi, h) / (4 cos θo cos θi), with the conductor
//! Fresnel term (or none), times `specular_reflectance`. One-sided. Sampling picks a
//! microfacet normal (visible normals by default) and reflects `wo` about it.

use glam::{Vec2, Vec3};

use crate::material::fresnel::fresnel_conductor;
use crate::material::{
    BsdfFlags, BsdfModel, BsdfSample, Microfacet, TransportMode, reflect_about, valid_weight,
};
use crate::math::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct RoughConductor {
    pub eta_k: Option<(Rgb, Rgb)>,
    pub specular_reflectance: Rgb,
    pub distribution: Microfacet,
}

impl RoughConductor {
    pub fn new(
        eta_k: Option<(Rgb, Rgb)>,
        specular_reflectance: Rgb,
        distribution: Microfacet,
    ) -> Self {
        RoughConductor {
            eta_k,
            specular_reflectance,
            distribution,
        }
    }

    fn fresnel(&self, cos_theta: f32) -> Rgb {
        match self.eta_k {
            Some((eta, k)) => self.specular_reflectance * fresnel_conductor(cos_theta, eta, k),
            None => self.specular_reflectance,
        }
    }
}

impl BsdfModel for RoughConductor {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let h = (wo + wi).normalize_or_zero();
        if h == Vec3::ZERO {
            return Rgb::BLACK;
        }
        let d = self.distribution.d(h);
        if d == 0.0 {
            return Rgb::BLACK;
        }
        let g = self.distribution.g(wo, wi, h);
        let value = d * g / (4.0 * wo.z * wi.z);
        if !value.is_finite() {
            return Rgb::BLACK;
        }
        self.fresnel(wo.dot(h)) * value
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize_or_zero();
        let wi_h = wi.dot(h);
        if h == Vec3::ZERO || wo.dot(h) <= 0.0 || wi_h <= 0.0 {
            return 0.0;
        }
        self.distribution.reflection_pdf(wo, h, wi_h)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 || !wo.is_finite() {
            return None;
        }
        let (m, pdf_m) = self.distribution.sample_normal(wo, u);
        if pdf_m <= 0.0 {
            return None;
        }
        let wi = reflect_about(wo, m).normalize_or_zero();
        let wi_m = wi.dot(m);
        if wi.z <= 0.0 || wi_m <= 0.0 {
            return None;
        }
        let pdf = self.distribution.reflection_pdf(wo, m, wi_m);
        // f cos θi / pdf, simplified: visible normals give F·G1(wi, m) (Heitz & d'Eon 2014,
        // eq. 8); sampling D cos θm gives F·G·(wo·m)/(cos θo cos θm) (Walter et al. eq. 41).
        let dist = &self.distribution;
        let g_ratio = if dist.sample_visible {
            dist.g1(wi, m)
        } else {
            dist.g(wo, wi, m) * wo.dot(m) / (wo.z * m.z)
        };
        let weight = self.fresnel(wo.dot(m)) * g_ratio;
        if !(pdf.is_finite() && pdf > 0.0 && valid_weight(weight)) {
            return None;
        }
        Some(BsdfSample::non_delta(wi, weight, pdf))
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags::NON_DELTA_REFLECTION
    }
}
