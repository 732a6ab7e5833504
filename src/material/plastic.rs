//! Smooth plastic (Mitsuba `plastic`): a diffuse base under a smooth dielectric coating.
//! Specular reflection off the coating with the Fresnel reflectance F; light refracted into
//! the coating scatters diffusely off the base and bounces between base and coating before
//! it leaves. Summing those bounces in closed form gives the diffuse lobe
//!
//!   f_d = R_d / (1 − F_dr,int) · (1 − F(θo)) (1 − F(θi)) / (π η²)          (`nonlinear` false)
//!   f_d = R_d / (1 − R_d F_dr,int) · …                                    (`nonlinear` true)
//!
//! where F_dr,int is the coating's diffuse reflectance seen from inside and η = int/ext
//! (the 1/η² accounts for radiance leaving the denser coating). One-sided. Sampling picks the specular
//! lobe with probability ∝ F(θo)·s̄ against (1 − F(θo))·d̄, s̄ and d̄ the mean specular and
//! diffuse reflectances (Mitsuba's weights).

use glam::{Vec2, Vec3};

use crate::material::fresnel::{diffuse_fresnel_reflectance, fresnel_dielectric};
use crate::material::{
    BsdfFlags, BsdfModel, BsdfSample, TransportMode, mean_nonneg, reflect_z, valid_weight,
};
use crate::math::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use crate::math::{INV_PI, Rgb};

#[derive(Clone, Debug, PartialEq)]
pub struct Plastic {
    pub eta: f32,
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub nonlinear: bool,
    /// R_d / (1 − F_dr,int) or R_d / (1 − R_d F_dr,int), precomputed.
    diffuse_scaled: Rgb,
    /// F_dr,int: the interface's diffuse reflectance from inside (a quadrature, kept so that
    /// a textured plastic need not integrate it again at every hit).
    fdr_int: f32,
    inv_eta2: f32,
    /// s̄ / (s̄ + d̄).
    specular_weight: f32,
}

impl Plastic {
    pub fn new(eta: f32, diffuse: Rgb, specular: Rgb, nonlinear: bool) -> Self {
        let eta = if eta.is_finite() && eta > 0.0 {
            eta
        } else {
            1.0
        };
        let fdr_int = diffuse_fresnel_reflectance(1.0 / eta);
        Plastic {
            eta,
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            nonlinear,
            diffuse_scaled: internal_scattering(diffuse, fdr_int, nonlinear),
            fdr_int,
            inv_eta2: 1.0 / (eta * eta),
            specular_weight: lobe_weight(specular, diffuse),
        }
    }

    /// The same plastic with diffuse reflectance `diffuse` (a texture's value at a point).
    /// The lobe-selection weight stays: Mitsuba 3 sets it once, from the texture's mean.
    pub fn with_diffuse_reflectance(&self, diffuse: Rgb) -> Self {
        Plastic {
            diffuse_reflectance: diffuse,
            diffuse_scaled: internal_scattering(diffuse, self.fdr_int, self.nonlinear),
            ..self.clone()
        }
    }

    /// (probability of the specular lobe, of the diffuse lobe) for a given F(θo).
    fn lobe_probabilities(&self, f_o: f32) -> (f32, f32) {
        let ps = f_o * self.specular_weight;
        let pd = (1.0 - f_o) * (1.0 - self.specular_weight);
        let total = ps + pd;
        if total > 0.0 {
            (ps / total, pd / total)
        } else {
            (0.0, 0.0)
        }
    }

    fn diffuse_value(&self, f_o: f32, f_i: f32) -> Rgb {
        self.diffuse_scaled * (INV_PI * self.inv_eta2 * (1.0 - f_o) * (1.0 - f_i))
    }
}

/// R_d/(1 − F) or, with `nonlinear`, R_d/(1 − R_d F): the geometric series of internal
/// bounces (each returns a fraction F_dr,int, times R_d when the base's colour is taken into
/// account for every bounce).
pub(crate) fn internal_scattering(diffuse: Rgb, f_int: f32, nonlinear: bool) -> Rgb {
    diffuse.map(|d| {
        let denom = if nonlinear {
            1.0 - d * f_int
        } else {
            1.0 - f_int
        };
        if denom > 0.0 { d / denom } else { 0.0 }
    })
}

/// s̄/(s̄ + d̄), the weight Mitsuba steers lobe selection with.
pub(crate) fn lobe_weight(specular: Rgb, diffuse: Rgb) -> f32 {
    let s = mean_nonneg(specular);
    let d = mean_nonneg(diffuse);
    if s + d > 0.0 { s / (s + d) } else { 0.5 }
}

impl BsdfModel for Plastic {
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta).f;
        let f_i = fresnel_dielectric(wi.z, self.eta).f;
        self.diffuse_value(f_o, f_i)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let (_, pd) = self.lobe_probabilities(fresnel_dielectric(wo.z, self.eta).f);
        pd * cosine_hemisphere_pdf(wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 || !wo.is_finite() {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta).f;
        let (ps, pd) = self.lobe_probabilities(f_o);
        if u_lobe < ps {
            let weight = self.specular_reflectance * (f_o / ps);
            return valid_weight(weight).then_some(BsdfSample {
                wi: reflect_z(wo),
                weight,
                pdf: ps,
                delta: true,
                eta: 1.0,
            });
        }
        if pd <= 0.0 {
            return None;
        }
        let wi = square_to_cosine_hemisphere(u);
        let pdf = pd * cosine_hemisphere_pdf(wi);
        if pdf <= 0.0 {
            return None;
        }
        let f_i = fresnel_dielectric(wi.z, self.eta).f;
        let weight = self.diffuse_value(f_o, f_i) * (wi.z / pdf);
        valid_weight(weight).then_some(BsdfSample::non_delta(wi, weight, pdf))
    }

    fn flags(&self) -> BsdfFlags {
        BsdfFlags {
            delta: true,
            non_delta: true,
            ..Default::default()
        }
    }
}
