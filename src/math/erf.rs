//! The error function and its inverse to single precision, for the Beckmann distribution's
//! visible-normal sampling (`material::microfacet`), which calls them several times per
//! sample: the general double-precision routines cost a fifth of `pt`'s time on a scene of
//! Beckmann conductors. The sampled slopes are f32, so f32 accuracy is what they need.

/// erf(x) within 1.5·10⁻⁷ (absolute): Abramowitz & Stegun, "Handbook of Mathematical
/// Functions" (1964), formula 7.1.26, with erf(−x) = −erf(x).
pub fn erf(x: f64) -> f64 {
    const P: f64 = 0.327_591_1;
    const A: [f64; 5] = [
        0.254_829_592,
        -0.284_496_736,
        1.421_413_741,
        -1.453_152_027,
        1.061_405_429,
    ];
    let z = x.abs();
    let t = 1.0 / (1.0 + P * z);
    let poly = t * (A[0] + t * (A[1] + t * (A[2] + t * (A[3] + t * A[4]))));
    (1.0 - poly * (-z * z).exp()).copysign(x)
}

/// erf⁻¹(x) for x in (−1, 1), within 4·10⁻⁷ (relative) of the exact inverse: Giles,
/// "Approximating the erfinv function" (GPU Computing Gems, 2011), single-precision
/// polynomials in w = −ln(1 − x²), evaluated in f64. Beyond that approximation's range
/// (1 − |x| below about 10⁻⁷, where w > 16) the double-precision routine takes over.
pub fn erf_inv(x: f64) -> f64 {
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_36e-8;
        for c in [
            3.432_739_39e-7,
            -3.523_387_7e-6,
            -4.391_506_54e-6,
            0.000_218_580_87,
            -0.001_253_725_03,
            -0.004_177_681_64,
            0.246_640_727,
            1.501_409_41,
        ] {
            p = c + p * w;
        }
        p
    } else if w <= 16.0 {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000_200_214_257;
        for c in [
            0.000_100_950_558,
            0.001_349_343_22,
            -0.003_673_428_44,
            0.005_739_507_73,
            -0.007_622_461_3,
            0.009_438_870_47,
            1.001_674_06,
            2.832_976_82,
        ] {
            p = c + p * w;
        }
        p
    } else {
        return statrs::function::erf::erf_inv(x);
    };
    p * x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against statrs' double-precision routines on a fine grid, tails included.
    #[test]
    fn match_the_double_precision_functions() {
        let mut worst_erf = 0.0f64;
        for i in -60_000..=60_000 {
            let x = i as f64 * 1e-4;
            worst_erf = worst_erf.max((erf(x) - statrs::function::erf::erf(x)).abs());
        }
        assert!(worst_erf < 1.5e-7, "erf off by {worst_erf:e}");
        let mut worst_inv = 0.0f64;
        let mut check = |x: f64| {
            let exact = statrs::function::erf::erf_inv(x);
            let e = ((erf_inv(x) - exact) / exact).abs();
            assert!(e.is_finite(), "erf_inv({x})");
            worst_inv = worst_inv.max(e);
        };
        for i in 1..200_000 {
            check(i as f64 / 200_000.0);
            check(-(i as f64) / 200_000.0);
        }
        // Towards ±1: 1 − 10^−k, through both polynomials and the fallback.
        for k in 1..=15 {
            for m in [1.0, 2.0, 5.0] {
                check(1.0 - m * 10f64.powi(-k));
                check(-1.0 + m * 10f64.powi(-k));
            }
        }
        assert!(worst_inv < 4e-7, "erf_inv off by {worst_inv:e} (relative)");
        assert_eq!(erf_inv(0.0), 0.0);
    }
}
