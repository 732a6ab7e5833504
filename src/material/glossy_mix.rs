//! The mixture the glossy reflection models share (`phong`, `blinn`, `ward`, and the
//! sampling of `roughplastic`): a Lambertian lobe plus a glossy lobe, both one-sided.
//!
//! Sampling picks the glossy lobe with probability p_s and the cosine-weighted diffuse lobe
//! otherwise. The sample's density is the mixture's, p = p_s·p_glossy + (1 − p_s)·cos θi/π,
//! so its weight f·cos θi/p is the whole model's whichever lobe drew it (the one-sample
//! model of Veach 1997, §9.2.4).

use glam::{Vec2, Vec3};

use crate::material::{
    BsdfModel, BsdfSample, TransportMode, reflect_about, reflection_sample, valid_weight,
};
use crate::math::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use crate::math::{INV_PI, Rgb};

/// f = ρ_d/π + ρ_s·glossy, where `glossy` is the glossy lobe's value per unit specular
/// reflectance; black where the sum is not a valid weight.
pub(crate) fn diffuse_plus_glossy(diffuse: Rgb, specular: Rgb, glossy: f32) -> Rgb {
    let value = diffuse * INV_PI + specular * glossy;
    if valid_weight(value) {
        value
    } else {
        Rgb::BLACK
    }
}

/// The mixture's density in wi: p_s·p_glossy + (1 − p_s)·cos θi/π.
pub(crate) fn mixture_pdf(glossy_probability: f32, glossy_pdf: f32, wi: Vec3) -> f32 {
    glossy_probability * glossy_pdf + (1.0 - glossy_probability) * cosine_hemisphere_pdf(wi)
}

/// The density in wi of a lobe that draws the half vector h = (wo + wi)/|wo + wi| with
/// solid-angle density `pdf_h(h)` and reflects wo about it: pdf_h/(4 wo·h), the Jacobian of
/// the reflection (Walter et al. 2007, eq. 14). 0 where h lies below the surface or faces
/// away from wo, and where the quotient is not finite.
pub(crate) fn half_vector_pdf_to_wi(wo: Vec3, wi: Vec3, pdf_h: impl FnOnce(Vec3) -> f32) -> f32 {
    let h = (wo + wi).normalize_or_zero();
    let wo_h = wo.dot(h);
    if !(h.z > 0.0 && wo_h > 0.0) {
        return 0.0;
    }
    let p = pdf_h(h) / (4.0 * wo_h);
    if p.is_finite() { p } else { 0.0 }
}

/// wo reflected about a sampled half vector h; None when h faces away from wo (the
/// reflection's own half vector would be −h, a direction the lobe does not produce).
pub(crate) fn reflect_about_half_vector(wo: Vec3, h: Vec3) -> Option<Vec3> {
    (wo.dot(h) > 0.0).then(|| reflect_about(wo, h).normalize_or_zero())
}

/// Samples the mixture of `model`: with probability `glossy_probability` the direction
/// `sample_glossy(u)` draws, otherwise a cosine-weighted one; pdf and weight are the model's
/// (`reflection_sample`). None below the surface or where the glossy lobe draws nothing.
pub(crate) fn sample_mixture(
    model: &impl BsdfModel,
    wo: Vec3,
    u_lobe: f32,
    u: Vec2,
    mode: TransportMode,
    glossy_probability: f32,
    sample_glossy: impl FnOnce(Vec2) -> Option<Vec3>,
) -> Option<BsdfSample> {
    if wo.z <= 0.0 || !wo.is_finite() {
        return None;
    }
    let wi = if u_lobe < glossy_probability {
        sample_glossy(u)?
    } else {
        square_to_cosine_hemisphere(u)
    };
    reflection_sample(model, wo, wi, mode)
}
