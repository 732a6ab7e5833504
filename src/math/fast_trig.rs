//! Inverse trigonometric functions in f32 without a library call, for the hot lookups
//! that turn a direction into image coordinates (environment maps): within 4·10⁻⁷ radians
//! of the exact value (under 2 ulp of f32 near π, where rounding alone costs half an ulp),
//! where the maps need a small fraction of a texel.

use std::f32::consts::{FRAC_PI_2, PI};

use crate::math::lanes::Real;

/// Coefficients of atan x ≈ x·(1 + a₂x² + a₄x⁴ + … + a₁₆x¹⁶) on 0 ≤ x ≤ 1, with absolute
/// error at most 2·10⁻⁸ (Abramowitz and Stegun 1964, eq. 4.4.49).
const ATAN: [f32; 8] = [
    -0.333_331_45,
    0.199_935_51,
    -0.142_089,
    0.106_562_64,
    -0.075_289_64,
    0.042_909_614,
    -0.016_165_737,
    0.002_866_225_7,
];

/// atan(a) for a in [0, 1].
#[inline(always)]
fn atan_unit<T: Real>(a: T) -> T {
    let a2 = a * a;
    // Horner's rule from the highest power.
    let p = ATAN
        .iter()
        .rev()
        .fold(T::splat(0.0), |acc, &c| acc * a2 + T::splat(c));
    a + a * a2 * p
}

/// True where the sign bit of `x` is set (−0 and NaNs with the sign bit included), as
/// `f32::is_sign_negative`.
#[inline(always)]
fn sign_negative<T: Real>(x: T) -> T::Mask {
    T::splat(1.0).copysign(x).lt(T::splat(0.0))
}

/// atan2(y, x) in [−π, π], as `f32::atan2` for every sign of y and x (zeros included):
/// the angle of (x, y) from the +x axis. atan2(0, 0) is 0 (or ±π for x = −0). Written
/// against `Real`, so sixteen lanes give each lane the bits of the scalar call.
#[inline(always)]
pub fn atan2<T: Real>(y: T, x: T) -> T {
    let (ax, ay) = (x.abs(), y.abs());
    let y_larger = ax.lt(ay);
    let (lo, hi) = (T::select(y_larger, ax, ay), T::select(y_larger, ay, ax));
    // The octant's angle from the nearer axis (0 at the origin, where lo / hi is 0 / 0).
    let zero = T::splat(0.0);
    let mut r = T::select(hi.gt(zero), atan_unit(lo / hi), zero);
    r = T::select(ay.gt(ax), T::splat(FRAC_PI_2) - r, r);
    r = T::select(sign_negative(x), T::splat(PI) - r, r);
    T::select(sign_negative(y), -r, r)
}

/// acos(x) in [0, π] for x in [−1, 1] (clamped): the angle whose cosine is
/// x, through atan2(√((1 − x)(1 + x)), x), which keeps its precision near ±1.
#[inline(always)]
pub fn acos<T: Real>(x: T) -> T {
    let one = T::splat(1.0);
    // `f32::clamp(−1, 1)`.
    let x = T::select(x.lt(-one), -one, x);
    let x = T::select(x.gt(one), one, x);
    atan2(((one - x) * (one + x)).sqrt(), x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within 4·10⁻⁷ of f64's atan2 on a grid of directions around the circle (every
    /// octant, the axes and points close to them), and the signs of zero as f32::atan2.
    #[test]
    fn atan2_matches_f64_around_the_circle() {
        let mut worst = 0.0f64;
        for k in 0..=100_000 {
            let angle = -std::f64::consts::PI + std::f64::consts::TAU * k as f64 / 100_000.0;
            for radius in [1e-3f64, 1.0, 7e4] {
                let (y, x) = ((radius * angle.sin()) as f32, (radius * angle.cos()) as f32);
                let exact = (y as f64).atan2(x as f64);
                let error = (atan2(y, x) as f64 - exact).abs();
                // ±π are the same angle.
                let error = error.min((error - std::f64::consts::TAU).abs());
                worst = worst.max(error);
            }
        }
        assert!(worst < 4e-7, "largest error {worst:e} rad");
        for (y, x) in [(0.0f32, 0.0f32), (0.0, -0.0), (-0.0, 0.0), (-0.0, -0.0)] {
            assert_eq!(atan2(y, x), y.atan2(x), "atan2({y}, {x})");
        }
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(-1.0, 0.0), -FRAC_PI_2);
    }

    /// Within 4·10⁻⁷ of f64's acos, the ends exact, and values beyond ±1 clamped.
    #[test]
    fn acos_matches_f64_on_the_interval() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let x = (-1.0 + 2.0 * k as f64 / 200_000.0) as f32;
            worst = worst.max((acos(x) as f64 - (x as f64).acos()).abs());
        }
        assert!(worst < 4e-7, "largest error {worst:e} rad");
        assert_eq!(acos(1.0), 0.0);
        assert_eq!(acos(-1.0), PI);
        assert_eq!(acos(1.5), 0.0);
        assert_eq!(acos(0.0), FRAC_PI_2);
    }

    /// Sixteen lanes give each lane the scalar call's bits, on values around the circle,
    /// signed zeros, infinities and NaNs.
    #[test]
    fn lanes_give_the_scalar_bits() {
        use crate::math::lanes::F32x16;
        let special = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let mut values: Vec<f32> = special.to_vec();
        values.extend((0..1000).map(|k| ((k as f32) * 0.7311).sin() * 1.3));
        let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for (k, chunk) in values.chunks(16).enumerate() {
            let ys: [f32; 16] = std::array::from_fn(|i| chunk.get(i).copied().unwrap_or(0.5));
            let xs: [f32; 16] =
                std::array::from_fn(|i| values[(k * 16 + i * 7 + 3) % values.len()]);
            let got = atan2(F32x16::from_array(ys), F32x16::from_array(xs)).to_array();
            let got_acos = acos(F32x16::from_array(ys)).to_array();
            for i in 0..16 {
                assert!(
                    same(got[i], atan2(ys[i], xs[i])),
                    "atan2({}, {})",
                    ys[i],
                    xs[i]
                );
                assert!(same(got_acos[i], acos(ys[i])), "acos({})", ys[i]);
            }
        }
    }
}
