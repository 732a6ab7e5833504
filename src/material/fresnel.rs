//! Fresnel reflectance of smooth interfaces: dielectric–dielectric (real relative IOR) and
//! dielectric–conductor (complex IOR), unpolarised light (the mean of the s and p terms).
//! Formulas: Born & Wolf, "Principles of Optics", §1.5 (dielectrics) and §14.2 (conductors).

use glam::Vec3;

use crate::material::quadrature::gauss_legendre;
use crate::math::Rgb;

/// Result of `fresnel_dielectric`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricFresnel {
    /// Reflectance F in [0, 1] (1 under total internal reflection).
    pub f: f32,
    /// Cosine of the refracted direction, with the sign of the side it leaves into (opposite
    /// to `cos_theta_i`); 0 under total internal reflection.
    pub cos_theta_t: f32,
    /// Relative IOR in the direction of travel: η_t/η_i.
    pub eta_it: f32,
    /// Its reciprocal η_i/η_t: the factor that scales the tangential components on refraction.
    pub eta_ti: f32,
}

/// Fresnel reflectance of a smooth dielectric interface whose normal points to the side of
/// lower IOR when `eta` > 1: `eta` = η_inside/η_outside, and `cos_theta_i` > 0 means the
/// incident direction is outside. Unpolarised: F = (r_s² + r_p²)/2 (Born & Wolf §1.5.2).
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> DielectricFresnel {
    let outside = cos_theta_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let ci = cos_theta_i.abs().min(1.0);
    // Snell: sin²θt = sin²θi (η_i/η_t)².
    let cos_t2 = 1.0 - (1.0 - ci * ci) * eta_ti * eta_ti;
    if eta == 1.0 {
        return DielectricFresnel {
            f: 0.0,
            cos_theta_t: -cos_theta_i,
            eta_it,
            eta_ti,
        };
    }
    if cos_t2 <= 0.0 || ci == 0.0 {
        // Total internal reflection (or exactly grazing incidence: F → 1).
        return DielectricFresnel {
            f: 1.0,
            cos_theta_t: 0.0,
            eta_it,
            eta_ti,
        };
    }
    let ct = cos_t2.sqrt();
    let r_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    let r_p = (eta_it * ci - ct) / (eta_it * ci + ct);
    let f = (0.5 * (r_s * r_s + r_p * r_p)).clamp(0.0, 1.0);
    DielectricFresnel {
        f,
        cos_theta_t: if outside { -ct } else { ct },
        eta_it,
        eta_ti,
    }
}

/// Refraction through the interface with normal +z given the results of
/// `fresnel_dielectric(w.z, η)`: (−η_ti·w.x, −η_ti·w.y, cos θt).
#[inline]
pub fn refract_z(w: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    Vec3::new(-eta_ti * w.x, -eta_ti * w.y, cos_theta_t)
}

/// Refraction of `w` through a microfacet with unit normal `m`, given
/// `fresnel_dielectric(w·m, η)`: the transmitted direction (Walter et al. 2007, eq. 40).
#[inline]
pub fn refract_about(w: Vec3, m: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    m * (w.dot(m) * eta_ti + cos_theta_t) - w * eta_ti
}

/// Unpolarised reflectance of a conductor with complex relative IOR η + iκ at incidence
/// cosine `cos_theta_i` ∈ [0, 1] (Born & Wolf §14.2, written with a² + b² = |n² − sin²θ|
/// as in Moeller, "Optics", 1988).
pub fn fresnel_conductor_scalar(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    let c = cos_theta_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    // n² − sin²θ = (η² − κ² − sin²θ) + i·2ηκ; a² + b² is its modulus, a its root's real part.
    let re = eta * eta - k * k - s2;
    let a2b2 = (re * re + 4.0 * eta * eta * k * k).max(0.0).sqrt();
    let a = (0.5 * (a2b2 + re)).max(0.0).sqrt();
    let t1 = a2b2 + c2;
    let t2 = 2.0 * c * a;
    let denom_s = t1 + t2;
    if denom_s <= 0.0 {
        return 1.0;
    }
    let r_s = (t1 - t2) / denom_s;
    let t3 = a2b2 * c2 + s4;
    let t4 = t2 * s2;
    let denom_p = t3 + t4;
    let r_p = if denom_p > 0.0 {
        r_s * (t3 - t4) / denom_p
    } else {
        r_s
    };
    (0.5 * (r_s + r_p)).clamp(0.0, 1.0)
}

/// Per-channel conductor reflectance (see `fresnel_conductor_scalar`).
pub fn fresnel_conductor(cos_theta_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    Rgb::new(
        fresnel_conductor_scalar(cos_theta_i, eta[0], k[0]),
        fresnel_conductor_scalar(cos_theta_i, eta[1], k[1]),
        fresnel_conductor_scalar(cos_theta_i, eta[2], k[2]),
    )
}

/// Diffuse Fresnel reflectance F_dr(η) = 2 ∫₀¹ F(μ, η) μ dμ: the fraction of uniformly
/// diffuse (Lambertian) radiance incident on the interface from the side with cosines
/// measured against the normal that is reflected back. `eta` is the relative IOR seen from
/// that side (η < 1: light inside a denser medium, with total internal reflection for
/// μ < μ_c = √(1 − η²)). Integrated numerically (Gauss–Legendre, with the square-root kink
/// at the critical angle removed by substitution), accurate to about 1e-6.
pub fn diffuse_fresnel_reflectance(eta: f32) -> f32 {
    let eta = eta as f64;
    if eta == 1.0 {
        return 0.0;
    }
    let fres = |mu: f64| fresnel_dielectric(mu as f32, eta as f32).f as f64;
    let (nodes, weights) = gauss_legendre(48);
    let mut sum = 0.0;
    if eta > 1.0 {
        // Smooth on [0, 1]; the kink is at μ = 0 (cos θt ≈ const): substitute μ = t².
        for (x, w) in nodes.iter().zip(weights.iter()) {
            let t = 0.5 * (x + 1.0);
            let mu = t * t;
            sum += w * 0.5 * fres(mu) * mu * 2.0 * t;
        }
        2.0 * sum as f32
    } else {
        let mu_c = (1.0 - eta * eta).max(0.0).sqrt();
        // [0, μ_c]: F = 1, contributes μ_c². [μ_c, 1]: μ = μ_c + (1 − μ_c) t².
        for (x, w) in nodes.iter().zip(weights.iter()) {
            let t = 0.5 * (x + 1.0);
            let mu = mu_c + (1.0 - mu_c) * t * t;
            sum += w * 0.5 * fres(mu) * mu * 2.0 * (1.0 - mu_c) * t;
        }
        (mu_c * mu_c + 2.0 * sum) as f32
    }
}
