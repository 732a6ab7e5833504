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
    #[cfg(target_arch = "x86_64")]
    {
        offset_ray_origin_sse2(p, p_error, ng, w)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        offset_ray_origin_portable(p, p_error, ng, w)
    }
}

/// `offset_ray_origin` through the generic `offset_origin` (the reference the SSE2 version
/// is tested against).
#[inline]
pub fn offset_ray_origin_portable(p: Vec3, p_error: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    offset_origin(V3::from(p), V3::from(p_error), V3::from(ng), V3::from(w)).into()
}

/// `offset_ray_origin` with the three coordinates' offset and one-float step in SSE2 lanes:
/// the same operations as `offset_origin` (the two dot products in scalar, in its order),
/// so the same bits. The step is `Real::step_towards` for `f32`, written for four lanes:
/// a scalar origin went through six data-dependent branches, 7% of `bdpt` on the Cornell
/// box, two origins per connection.
#[cfg(target_arch = "x86_64")]
#[inline]
fn offset_ray_origin_sse2(p: Vec3, p_error: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    use std::arch::x86_64::*;
    let delta = ng.abs().dot(p_error);
    let side = if w.dot(ng) < 0.0 { -delta } else { delta };
    // SAFETY: SSE2 is part of every x86_64 target; the intrinsics only touch registers and
    // the local array they are stored to.
    unsafe {
        let offset = _mm_mul_ps(_mm_set_ps(0.0, ng.z, ng.y, ng.x), _mm_set1_ps(side));
        let po = _mm_add_ps(_mm_set_ps(0.0, p.z, p.y, p.x), offset);
        let zero = _mm_setzero_ps();
        // u = po with the offset's sign folded in (−0 counts as +0); one float up in |u|'s
        // direction is bits + 1 for u ≥ 0, bits − 1 below; the sign folded back.
        let flip = _mm_and_si128(
            _mm_castps_si128(_mm_cmplt_ps(offset, zero)),
            _mm_set1_epi32(i32::MIN),
        );
        let u = _mm_xor_si128(_mm_castps_si128(po), flip);
        let u = _mm_andnot_si128(_mm_castps_si128(_mm_cmpeq_ps(_mm_castsi128_ps(u), zero)), u);
        let up = _mm_castps_si128(_mm_cmpge_ps(_mm_castsi128_ps(u), zero));
        // +1 where `up`, −1 elsewhere.
        let step = _mm_xor_si128(_mm_set1_epi32(-1), _mm_and_si128(up, _mm_set1_epi32(-2)));
        let stepped = _mm_castsi128_ps(_mm_xor_si128(_mm_add_epi32(u, step), flip));
        // Unmoved where the offset is 0 (or the coordinate not finite).
        let magnitude = _mm_and_ps(po, _mm_castsi128_ps(_mm_set1_epi32(i32::MAX)));
        let finite = _mm_cmplt_ps(magnitude, _mm_set1_ps(f32::INFINITY));
        let moves = _mm_andnot_ps(_mm_cmpeq_ps(offset, zero), finite);
        let out = _mm_or_ps(_mm_and_ps(moves, stepped), _mm_andnot_ps(moves, po));
        let mut xyz = [0.0f32; 4];
        _mm_storeu_ps(xyz.as_mut_ptr(), out);
        Vec3::new(xyz[0], xyz[1], xyz[2])
    }
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

    /// The SSE2 origin is the generic one bit for bit, on random inputs and on the cases
    /// each branch of the step exists for: zero and negative-zero offsets and coordinates,
    /// subnormals, the largest floats, infinities and NaN.
    #[test]
    fn sse2_origin_matches_the_generic_one() {
        let specials = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            1e-40,
            -1e-40,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            3.5e5,
            -2.5e-3,
        ];
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let pick = |k: u64| -> f32 {
            if k.is_multiple_of(4) {
                specials[(k / 4 % specials.len() as u64) as usize]
            } else {
                // Any float of moderate exponent and either sign.
                let bits = (k >> 16) as u32 & 0x807f_ffff | (100 + (k as u32 % 56)) << 23;
                f32::from_bits(bits)
            }
        };
        let vec =
            |next: &mut dyn FnMut() -> u64| Vec3::new(pick(next()), pick(next()), pick(next()));
        for _ in 0..200_000 {
            let (p, e, n, w) = (
                vec(&mut next),
                vec(&mut next).abs(),
                vec(&mut next),
                vec(&mut next),
            );
            let fast = offset_ray_origin(p, e, n, w);
            let reference = offset_ray_origin_portable(p, e, n, w);
            // NaN's sign and payload are not specified by either version's arithmetic.
            let bits = |v: Vec3| {
                v.to_array()
                    .map(|x| if x.is_nan() { 0 } else { x.to_bits() })
            };
            assert_eq!(
                bits(fast),
                bits(reference),
                "p {p:?} error {e:?} n {n:?} w {w:?}"
            );
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
