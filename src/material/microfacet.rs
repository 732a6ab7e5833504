//! Microfacet normal distributions (Beckmann and GGX / Trowbridge–Reitz), Smith's
//! shadowing–masking, and sampling of microfacet normals: either of the whole distribution
//! D(m)·cos θm (Walter et al. 2007, "Microfacet Models for Refraction through Rough
//! Surfaces") or of the normals visible from a direction (Heitz & d'Eon 2014, "Importance
//! Sampling Microfacet-Based BSDFs using the Distribution of Visible Normals").
//!
//! All vectors are in the local frame (macro-normal +z). α is the microfacet roughness
//! itself (Mitsuba's `alpha`; for Beckmann the RMS slope times √2).
//!
//! Smith's Λ for Beckmann is evaluated exactly (Walter et al. 2007, eq. 27's closed form
//! with erf), not with the rational fit Mitsuba 3 uses (which differs by < 0.35 %): the
//! visible-normal sampler draws from the exact distribution, and its pdf must match it.

use crate::math::erf::{erf, erf_inv};
use glam::{Vec2, Vec3};

use crate::math::PI;
use crate::scene::{MicrofacetKind, Roughness};

/// The smallest α used (Mitsuba clamps to the same value): below it the distributions are
/// too peaked for single precision.
pub const MIN_ALPHA: f32 = 1e-4;

/// An (anisotropic) microfacet distribution with its sampling strategy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub kind: MicrofacetKind,
    pub alpha_u: f32,
    pub alpha_v: f32,
    /// Sample visible normals (Heitz & d'Eon 2014) instead of D(m)·cos θm.
    pub sample_visible: bool,
}

impl Microfacet {
    pub fn new(kind: MicrofacetKind, alpha_u: f32, alpha_v: f32, sample_visible: bool) -> Self {
        let clamp = |a: f32| if a.is_finite() { a.max(MIN_ALPHA) } else { 1.0 };
        Microfacet {
            kind,
            alpha_u: clamp(alpha_u),
            alpha_v: clamp(alpha_v),
            sample_visible,
        }
    }

    pub fn from_roughness(r: &Roughness) -> Self {
        Microfacet::new(r.kind, r.alpha_u, r.alpha_v, r.sample_visible)
    }

    pub fn is_isotropic(&self) -> bool {
        self.alpha_u == self.alpha_v
    }

    /// The same distribution with both α scaled by `s`.
    pub fn scaled(&self, s: f32) -> Self {
        Microfacet::new(
            self.kind,
            self.alpha_u * s,
            self.alpha_v * s,
            self.sample_visible,
        )
    }

    /// The normal distribution D(m) (per unit solid angle of m, normalised so that
    /// ∫ D(m) cos θm dm = 1). Zero for m below the surface.
    pub fn d(&self, m: Vec3) -> f32 {
        let cz = m.z;
        if cz <= 0.0 {
            return 0.0;
        }
        let cz2 = cz * cz;
        let sx = m.x / self.alpha_u;
        let sy = m.y / self.alpha_v;
        let result = match self.kind {
            // Walter et al. 2007, eq. 25 (anisotropic form).
            MicrofacetKind::Beckmann => {
                (-(sx * sx + sy * sy) / cz2).exp() / (PI * self.alpha_u * self.alpha_v * cz2 * cz2)
            }
            // Walter et al. 2007, eq. 33 (anisotropic form).
            MicrofacetKind::Ggx => {
                let t = sx * sx + sy * sy + cz2;
                1.0 / (PI * self.alpha_u * self.alpha_v * t * t)
            }
        };
        // Values this small only cause trouble downstream (as in Mitsuba).
        if result.is_finite() && result * cz > 1e-20 {
            result
        } else {
            0.0
        }
    }

    /// Smith's auxiliary function Λ(v) for the projected roughness along v.
    fn lambda(&self, v: Vec3) -> f32 {
        let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy == 0.0 {
            return 0.0;
        }
        let z2 = v.z * v.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        // α² tan²θ along v.
        let tan2 = xy / z2;
        match self.kind {
            MicrofacetKind::Beckmann => {
                // a = 1/(α tan θ); Λ = (erf(a) − 1)/2 + e^(−a²)/(2a√π)
                //   = e^(−a²) (1/(a√π) − P(t)) / 2 with erfc(a) = P(t) e^(−a²)
                // (Abramowitz & Stegun 7.1.26, |error of erfc| < 1.5e-7).
                let a = 1.0 / tan2.sqrt();
                if a > 8.0 {
                    return 0.0;
                }
                let t = 1.0 / (1.0 + 0.327_591_1 * a);
                let poly = t
                    * (0.254_829_6
                        + t * (-0.284_496_74
                            + t * (1.421_413_8 + t * (-1.453_152_1 + t * 1.061_405_4))));
                let e = (-a * a).exp();
                (0.5 * e * (1.0 / (a * std::f32::consts::PI.sqrt()) - poly)).max(0.0)
            }
            // Walter et al. 2007, eq. 34 written with Λ.
            MicrofacetKind::Ggx => 0.5 * ((1.0 + tan2).sqrt() - 1.0),
        }
    }

    /// Smith's masking function G1(v, m) (Walter et al. 2007, eqs. 27 and 34): the fraction
    /// of microfacets with normal m visible from v. Zero when v sees the back of m or m is
    /// seen from the wrong side of the macro-surface.
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let l = self.lambda(v);
        if l.is_finite() { 1.0 / (1.0 + l) } else { 0.0 }
    }

    /// Separable Smith shadowing–masking G(wo, wi, m) = G1(wo, m) G1(wi, m).
    pub fn g(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Density of `sample_normal(wo, ·)` over microfacet normals (solid angle of m).
    /// `wo` must be in the upper hemisphere.
    pub fn pdf(&self, wo: Vec3, m: Vec3) -> f32 {
        if self.sample_visible {
            if wo.z <= 0.0 {
                return 0.0;
            }
            // D_wo(m) = G1(wo, m) max(0, wo·m) D(m) / cos θo (Heitz & d'Eon 2014, eq. 2).
            let p = self.d(m) * self.g1(wo, m) * wo.dot(m).max(0.0) / wo.z;
            if p.is_finite() { p } else { 0.0 }
        } else {
            self.d(m) * m.z.max(0.0)
        }
    }

    /// Solid-angle density of the reflected direction wi = reflect(wo, m) when m is drawn by
    /// `sample_normal(wo, ·)`: pdf(wo, m) / (4 wi·m) (Walter et al. 2007, eq. 14). With
    /// visible normals wo·m = wi·m cancels, leaving D(m) G1(wo, m) / (4 cos θo): evaluated
    /// in that form, it stays accurate when wo·m is tiny (grazing `wo`).
    pub fn reflection_pdf(&self, wo: Vec3, m: Vec3, wi_m: f32) -> f32 {
        if wi_m <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let p = if self.sample_visible {
            self.d(m) * self.g1(wo, m) / (4.0 * wo.z)
        } else {
            self.d(m) * m.z.max(0.0) / (4.0 * wi_m)
        };
        if p.is_finite() { p } else { 0.0 }
    }

    /// Samples a microfacet normal (upper hemisphere) for a direction `wo` above the surface,
    /// returning it with its density `pdf(wo, m)`. The density is 0 for a degenerate sample.
    pub fn sample_normal(&self, wo: Vec3, u: Vec2) -> (Vec3, f32) {
        let m = if self.sample_visible {
            self.sample_visible_normal(wo, u)
        } else {
            self.sample_all_normals(u)
        };
        if !m.is_finite() || m.z <= 0.0 {
            return (Vec3::Z, 0.0);
        }
        (m, self.pdf(wo, m))
    }

    /// m ∝ D(m) cos θm (Walter et al. 2007, eqs. 28–29 and 35–36; anisotropic azimuth as in
    /// Ward 1992: tan φ = (α_v/α_u) tan 2πu).
    fn sample_all_normals(&self, u: Vec2) -> Vec3 {
        let psi = 2.0 * PI * u.y;
        let (sin_phi, cos_phi, alpha2) = if self.is_isotropic() {
            (psi.sin(), psi.cos(), self.alpha_u * self.alpha_u)
        } else {
            let phi = (self.alpha_v * psi.sin()).atan2(self.alpha_u * psi.cos());
            let (s, c) = phi.sin_cos();
            let inv = (c / self.alpha_u).powi(2) + (s / self.alpha_v).powi(2);
            (s, c, 1.0 / inv)
        };
        let tan2 = match self.kind {
            MicrofacetKind::Beckmann => -alpha2 * (1.0 - u.x).ln(),
            MicrofacetKind::Ggx => alpha2 * u.x / (1.0 - u.x),
        };
        let cos_theta = 1.0 / (1.0 + tan2).sqrt();
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta)
    }

    /// Visible-normal sampling: stretch `wo` to the α = 1 configuration, sample there, and
    /// unstretch (Heitz & d'Eon 2014, §4).
    fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let stretched =
            Vec3::new(self.alpha_u * wo.x, self.alpha_v * wo.y, wo.z.max(0.0)).normalize_or_zero();
        if stretched == Vec3::ZERO {
            return Vec3::NAN;
        }
        match self.kind {
            MicrofacetKind::Ggx => {
                // Heitz 2018, "Sampling the GGX Distribution of Visible Normals": a point on
                // the projected hemisphere, warped for the half hidden by the incidence.
                let vh = stretched;
                let len2 = vh.x * vh.x + vh.y * vh.y;
                let t1 = if len2 > 0.0 {
                    Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
                } else {
                    Vec3::X
                };
                let t2 = vh.cross(t1);
                let r = u.x.sqrt();
                let phi = 2.0 * PI * u.y;
                let p1 = r * phi.cos();
                let mut p2 = r * phi.sin();
                let s = 0.5 * (1.0 + vh.z);
                p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
                let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
                Vec3::new(self.alpha_u * nh.x, self.alpha_v * nh.y, nh.z.max(0.0))
                    .normalize_or_zero()
            }
            MicrofacetKind::Beckmann => {
                let cos_theta = stretched.z;
                let sin_theta2 = stretched.x * stretched.x + stretched.y * stretched.y;
                let (cos_phi, sin_phi) = if sin_theta2 > 0.0 {
                    let inv = 1.0 / sin_theta2.sqrt();
                    (stretched.x * inv, stretched.y * inv)
                } else {
                    (1.0, 0.0)
                };
                let (sx, sy) = beckmann_visible_slopes(cos_theta as f64, u.x as f64, u.y as f64);
                let (sx, sy) = (sx as f32, sy as f32);
                // Rotate back to wo's azimuth and unstretch.
                let x = (cos_phi * sx - sin_phi * sy) * self.alpha_u;
                let y = (sin_phi * sx + cos_phi * sy) * self.alpha_v;
                Vec3::new(-x, -y, 1.0).normalize_or_zero()
            }
        }
    }
}

/// Slopes (x̃, ỹ) of a visible normal of the α = 1 Beckmann surface seen from a direction in
/// the xz-plane with cos θ = `cos_theta` (+x side), from a uniform (u1, u2).
///
/// The x-slope's density is ∝ (cot θ − x̃) e^(−x̃²) for x̃ < cot θ; in the variable
/// χ = erf(x̃) its CDF is proportional to 1 + χ + tan θ e^(−x̃²)/√π (Jakob 2014, "An
/// Improved Visible Normal Sampling Routine for the Beckmann Distribution"), which is
/// inverted with safeguarded Halley iterations (the function is increasing and concave; a
/// bisection bracket protects against overshoot and round-off). The
/// y-slope is an independent Gaussian. Public for the rough plastic's precomputation.
pub fn beckmann_visible_slopes(cos_theta: f64, u1: f64, u2: f64) -> (f64, f64) {
    const EPS: f64 = 1e-12;
    let u1 = u1.clamp(EPS, 1.0 - EPS);
    let u2 = u2.clamp(EPS, 1.0 - EPS);
    let slope_y = erf_inv(2.0 * u2 - 1.0);
    let cos_theta = cos_theta.clamp(0.0, 1.0);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    if sin_theta < 1e-7 {
        // Normal incidence: every normal is equally visible, slopes are plain Gaussians.
        return (erf_inv(2.0 * u1 - 1.0), slope_y);
    }
    let inv_sqrt_pi = 1.0 / std::f64::consts::PI.sqrt();
    let tan_theta = sin_theta / cos_theta.max(1e-300);
    let cot_theta = cos_theta / sin_theta;
    let max_val = erf(cot_theta);
    let norm = 1.0 + max_val + inv_sqrt_pi * tan_theta * (-cot_theta * cot_theta).exp();
    let target = u1 * norm;
    // Initial guess: Jakob's fit of the inverse, χ = max − (max + 1)(1 − u1)^k with
    // k = 1 + θ(−0.876 + θ(0.4265 − 0.0594 θ)) (Jakob 2014, §4), within a few percent
    // of the root at every angle, so Halley's method needs one or two steps.
    // (A guess: single precision is enough.)
    let theta = crate::math::fast_trig::acos(cos_theta as f32);
    let k = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut lo = -1.0f64;
    let mut hi = max_val;
    let power = ((1.0 - u1) as f32).powf(k) as f64;
    let mut x = (max_val - (max_val + 1.0) * power).clamp(lo, hi);
    let mut slope = erf_inv(x);
    for _ in 0..MAX_ROOT_STEPS {
        let gauss = (-slope * slope).exp();
        let value = 1.0 + x + inv_sqrt_pi * tan_theta * gauss - target;
        // Solved once the CDF is off by less than f32 can resolve in u1, by far.
        if value.abs() <= CDF_TOLERANCE * norm {
            break;
        }
        if value > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        // Halley's step (cubic convergence: from Jakob's guess one or two steps reach the
        // tolerance where Newton's needed two or three). With ds/dχ = (√π/2)·e^(s²):
        // F′ = 1 − s·tan θ and F″ = −tan θ·(√π/2)·e^(s²); Newton's where e^(−s²)
        // underflows.
        let derivative = 1.0 - slope * tan_theta;
        let second = -tan_theta * (0.5 / inv_sqrt_pi) / gauss;
        let mut next = if second.is_finite() {
            x - 2.0 * value * derivative / (2.0 * derivative * derivative - value * second)
        } else {
            x - value / derivative
        };
        if !(next > lo && next < hi && next.is_finite()) {
            next = 0.5 * (lo + hi);
        }
        if next == x || hi - lo <= 1e-15 {
            break;
        }
        x = next;
        slope = erf_inv(x);
    }
    if !slope.is_finite() {
        slope = erf_inv(x.clamp(-1.0 + 1e-16, 1.0 - 1e-16));
    }
    // erf and its inverse agree to single precision only: near χ = erf(cot θ) the slope
    // can land a little beyond cot θ, where no microfacet faces the viewer.
    (slope.min(cot_theta), slope_y)
}

/// Most Halley (or bisection) steps `beckmann_visible_slopes` takes; from Jakob's initial
/// guess one or two reach `CDF_TOLERANCE`.
const MAX_ROOT_STEPS: usize = 40;

/// The CDF residual, relative to the CDF's total, at which `beckmann_visible_slopes`
/// stops: 10⁻⁶, above the residual's own error (the single-precision erf⁻¹ puts up to
/// 3·10⁻⁷ into it, `math::erf`), about 16 steps of f32's resolution of u1.
const CDF_TOLERANCE: f64 = 1e-6;

#[cfg(test)]
mod tests {
    use super::*;

    /// The x-slope solves its CDF equation: 1 + erf(x̃) + tan θ e^(−x̃²)/√π = u1 · (its
    /// value at x̃ = cot θ), checked with erf itself, to the stopping tolerance (and a
    /// rounding margin) at angles from normal to grazing incidence, including u1 near 0
    /// and 1; the y-slope is the Gaussian's inverse CDF.
    #[test]
    fn visible_slopes_solve_the_cdf_equation() {
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let inv_sqrt_pi = 1.0 / std::f64::consts::PI.sqrt();
        for cos_theta in [0.9999, 0.99, 0.9, 0.7, 0.5, 0.3, 0.1, 0.01, 0.001] {
            let sin_theta = (1.0f64 - cos_theta * cos_theta).sqrt();
            let (tan_theta, cot_theta) = (sin_theta / cos_theta, cos_theta / sin_theta);
            // In double precision: the sampler's own erf is good to 1.5e-7 only.
            let erf = statrs::function::erf::erf;
            let cdf = |x: f64| 1.0 + erf(x) + inv_sqrt_pi * tan_theta * (-x * x).exp();
            let norm = cdf(cot_theta);
            for k in 0..2000 {
                let u1 = match k {
                    0 => 1e-9,
                    1 => 1.0 - 1e-9,
                    _ => next(),
                };
                let u2 = next();
                let (x, y) = beckmann_visible_slopes(cos_theta, u1, u2);
                assert!(x < cot_theta + 1e-12, "cos θ {cos_theta}, u1 {u1}: x̃ {x}");
                let residual = (cdf(x) - u1 * norm).abs() / norm;
                assert!(
                    residual <= 2.0 * CDF_TOLERANCE,
                    "cos θ {cos_theta}, u1 {u1}: residual {residual:e}"
                );
                // erf⁻¹ to single precision (`math::erf`): within 4·10⁻⁷·|ỹ| of the
                // exact inverse, so the CDF within e^(−ỹ²)·|ỹ|·4·10⁻⁷/√π < 1e-7.
                let e = ((1.0 + statrs::function::erf::erf(y)) / 2.0 - u2).abs();
                assert!(e < 1.2e-7, "u2 {u2}: ỹ {y}, off by {e:e}");
            }
        }
    }
}
