//! Floating-point error bounds and robust ray origins.
//!
//! A computed hit point is not exactly on the surface. Each intersector returns, with the
//! point, a conservative bound on the absolute error of each coordinate (`p_error`): the
//! true surface point lies in the box `p ± p_error`. A new ray leaving the surface starts
//! from `p` pushed along the geometric normal far enough that the whole box lies behind it,
//! on the side the ray goes to; then it cannot re-hit its own surface at t ≈ 0, whatever
//! the scene's scale. The reasoning follows Pharr, Jakob & Humphreys, "Physically Based
//! Rendering", 4th ed., §6.8 (running error bounds with γ(n), offset along the normal by
//! the error box's extent, round away); the code is mltbench's own.

use glam::Vec3;

use crate::math::lanes::{Real, V3};

/// Unit roundoff of f32 round-to-nearest: |fl(x) − x| ≤ u·|x|.
pub const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// γ(n) = n·u / (1 − n·u): the relative error of a value that went through n rounded
/// operations is at most γ(n) (Higham, "Accuracy and Stability of Numerical Algorithms",
/// 2nd ed., Lemma 3.1). Valid for n·u < 1.
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// The smallest f32 greater than `v` (`v` itself for +∞ and NaN).
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest f32 smaller than `v` (`v` itself for −∞ and NaN).
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// The origin of a ray leaving the surface point `p` (error box `p ± p_error`, unit
/// geometric normal `ng`) towards `w`.
///
/// The error box's extent along the normal is `δ = Σ |ng_i|·p_error_i` (the box's support
/// function), so every point of the box is within δ of the tangent plane through the true
/// point. Moving `p` by δ along ±ng, to the side of `w`, puts the origin on that side of
/// the plane; the addition itself rounds, so each coordinate is then moved one more float
/// away from `p`, in the direction of the offset, which cannot bring it back.
#[inline]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    offset_origin(V3::from(p), V3::from(p_error), V3::from(ng), V3::from(w)).into()
}

/// `offset_ray_origin` over `Real` (one origin, or sixteen in lanes).
#[inline(always)]
pub fn offset_origin<T: Real>(p: V3<T>, p_error: V3<T>, ng: V3<T>, w: V3<T>) -> V3<T> {
    let delta = ng.abs().dot(p_error);
    let side = T::select(w.dot(ng).lt(T::splat(0.0)), -delta, delta);
    let offset = ng * side;
    let po = p + offset;
    // Each coordinate moves one float towards the sign of its offset, none where the
    // offset is zero.
    V3::new(
        po.x.step_towards(offset.x),
        po.y.step_towards(offset.y),
        po.z.step_towards(offset.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        for v in [1.0f32, -1.0, 0.0, -0.0, 1e-40, -1e-40, 3.5e5, f32::MAX] {
            let up = next_float_up(v);
            let down = next_float_down(v);
            assert!(up > v && down < v, "{v}");
            // nothing lies strictly between
            assert_eq!(next_float_down(up), if v == 0.0 { 0.0 } else { v });
        }
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(next_float_down(f32::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(next_float_up(f32::MAX), f32::INFINITY);
    }

    #[test]
    fn gamma_bounds_repeated_rounding() {
        // (1 + u)^n − 1 ≤ γ(n): the product of n worst-case roundings.
        let u = UNIT_ROUNDOFF as f64;
        for n in 1..10u32 {
            assert!((1.0 + u).powi(n as i32) - 1.0 <= gamma(n) as f64);
        }
    }

    #[test]
    fn offset_moves_to_the_side_of_w() {
        let p = Vec3::new(1e5, -3.0, 0.25);
        let e = Vec3::splat(0.01);
        let n = Vec3::new(0.0, 0.6, 0.8);
        let up = offset_ray_origin(p, e, n, Vec3::new(0.1, 1.0, 0.0));
        let down = offset_ray_origin(p, e, n, Vec3::new(0.1, -1.0, 0.0));
        let delta = n.abs().dot(e);
        assert!((up - p).dot(n) >= delta * 0.999);
        assert!((down - p).dot(n) <= -delta * 0.999);
    }

    #[test]
    fn step_towards_matches_next_float() {
        for v in [
            1.0f32,
            -1.0,
            0.0,
            -0.0,
            1e-40,
            -1e-40,
            3.5e5,
            -2.5e-3,
            f32::MAX,
        ] {
            assert_eq!(
                v.step_towards(1.0).to_bits(),
                next_float_up(v).to_bits(),
                "{v}"
            );
            assert_eq!(
                v.step_towards(-0.5).to_bits(),
                next_float_down(v).to_bits(),
                "{v}"
            );
            assert_eq!(v.step_towards(0.0).to_bits(), v.to_bits(), "{v}");
        }
    }
}
