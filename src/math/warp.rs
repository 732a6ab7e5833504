//! Warps from the unit square to other domains, each with its pdf (with respect to area on
//! the target domain, or solid angle for directions).
//!
//! Every warp maps [0, 1)² onto its domain bijectively (up to measure zero) and preserves
//! stratification, so that samplers which distribute points well on the square keep doing so.

use glam::{Vec2, Vec3};

use crate::math::lanes::{Real, V3};
use crate::math::{INV_PI, PI};

/// Uniform point on a triangle as barycentrics (b1, b2) (Shirley & Chiu 1997 square-root map).
pub fn square_to_triangle(u: Vec2) -> Vec2 {
    let (b1, b2) = triangle_barycentrics(u.x, u.y);
    Vec2::new(b1, b2)
}

/// `square_to_triangle` over `Real` (one point, or sixteen in lanes).
#[inline(always)]
pub fn triangle_barycentrics<T: Real>(ux: T, uy: T) -> (T, T) {
    let su = ux.sqrt();
    (T::splat(1.0) - su, uy * su)
}

/// Uniform direction on the unit sphere; pdf 1/(4π).
pub fn square_to_sphere(u: Vec2) -> Vec3 {
    sphere_direction(u.x, u.y).into()
}

/// `square_to_sphere` over `Real` (one direction, or sixteen in lanes), with
/// `sin_cos_turns` for the azimuth.
#[inline(always)]
pub fn sphere_direction<T: Real>(ux: T, uy: T) -> V3<T> {
    let one = T::splat(1.0);
    let z = one - T::splat(2.0) * ux;
    let r = (one - z * z).max_gt(T::splat(0.0)).sqrt();
    let (sin, cos) = sin_cos_turns(T::splat(2.0 * PI) * uy);
    V3::new(r * cos, r * sin, z)
}

/// Solid-angle density of `square_to_sphere`: 1/(4π).
pub fn sphere_pdf() -> f32 {
    0.25 * INV_PI
}

/// Uniform point on the unit disk by Shirley & Chiu's (1997) concentric map, which keeps
/// neighbourhoods compact (low distortion); density 1/π.
#[inline]
pub fn square_to_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = disk_concentric(u.x, u.y);
    Vec2::new(x, y)
}

/// `square_to_disk_concentric` over `Real` (one point, or sixteen in lanes).
#[inline(always)]
pub fn disk_concentric<T: Real>(ux: T, uy: T) -> (T, T) {
    let (one, two, zero) = (T::splat(1.0), T::splat(2.0), T::splat(0.0));
    let a = two * ux - one;
    let b = two * uy - one;
    // φ = θ in the wedges around the x axis and φ = π/2 − θ in those around the y axis, with
    // θ = (π/4)·(ratio of the two coordinates) in [−π/4, π/4] either way.
    let around_x = (a * a).gt(b * b);
    let (num, den) = (T::select(around_x, b, a), T::select(around_x, a, b));
    let (sin, cos) = sin_cos_quarter(T::splat(PI / 4.0) * (num / den));
    let r = T::select(around_x, a, b);
    let x = r * T::select(around_x, cos, sin);
    let y = r * T::select(around_x, sin, cos);
    let centre = a.eq(zero) & b.eq(zero);
    (T::select(centre, zero, x), T::select(centre, zero, y))
}

/// (sin φ, cos φ) for φ in [−π/4, 4π), over `Real` (one angle, or sixteen in lanes with
/// each lane the bits of the scalar call, which libm's `sin_cos` cannot give): the nearest
/// multiple k of π/2 is taken off in two parts (Cody and Waite's reduction, the first part
/// short enough that k times it is exact), the rest, within ±π/4, goes to
/// `sin_cos_quarter`, and the result turns by k quarter turns. Within about 2·10⁻⁷ of the
/// exact values.
#[inline(always)]
pub fn sin_cos_turns<T: Real>(phi: T) -> (T, T) {
    // π/2 = HALF_PI_HI + HALF_PI_LO, HALF_PI_HI with 8 significant bits (201/128).
    const HALF_PI_HI: f32 = 1.570_312_5;
    const HALF_PI_LO: f32 = 4.838_268e-4;
    let (zero, one) = (T::splat(0.0), T::splat(1.0));
    let t = phi * T::splat(2.0 / PI);
    // k = round(t) for t in [−½, 8), counted without a float-to-integer conversion.
    let mut k = zero;
    for j in 0..8 {
        k = k + T::select(t.ge(T::splat(j as f32 + 0.5)), one, zero);
    }
    let r = (phi - k * T::splat(HALF_PI_HI)) - k * T::splat(HALF_PI_LO);
    let (s, c) = sin_cos_quarter(r);
    // Quarter turns k mod 4: (sin, cos) → (cos, −sin) → (−sin, −cos) → (−cos, sin).
    let q1 = k.eq(one) | k.eq(T::splat(5.0));
    let q2 = k.eq(T::splat(2.0)) | k.eq(T::splat(6.0));
    let q3 = k.eq(T::splat(3.0)) | k.eq(T::splat(7.0));
    let sin = T::select(q1, c, T::select(q2, -s, T::select(q3, -c, s)));
    let cos = T::select(q1, -s, T::select(q2, -c, T::select(q3, s, c)));
    (sin, cos)
}

/// (sin θ, cos θ) for θ in [−π/4, π/4], by polynomials fitted (least squares, in mltbench)
/// to sin θ / θ and cos θ on that interval: both within 1e-7 of the exact values in f32,
/// inline and without the range reduction of the general functions.
#[inline(always)]
fn sin_cos_quarter<T: Real>(theta: T) -> (T, T) {
    let c = T::splat;
    let t2 = theta * theta;
    let sin = theta
        * (c(1.0) + t2 * (c(-0.166_666_57) + t2 * (c(0.008_332_327) + t2 * c(-0.000_195_374_87))));
    let cos = c(1.0)
        + t2 * (c(-0.5)
            + t2 * (c(0.041_666_63) + t2 * (c(-0.001_388_697_9) + t2 * c(0.000_024_410_747))));
    (sin, cos)
}

/// Density of a uniform point on the unit disk: 1/π inside, 0 outside.
pub fn disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        INV_PI
    } else {
        0.0
    }
}

/// Cosine-weighted direction on the upper hemisphere (z ≥ 0) by Malley's method: a uniform
/// point on the disk lifted onto the hemisphere; pdf cos θ / π.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    cosine_hemisphere(u.x, u.y).into()
}

/// `square_to_cosine_hemisphere` over `Real` (one direction, or sixteen in lanes).
#[inline(always)]
pub fn cosine_hemisphere<T: Real>(ux: T, uy: T) -> V3<T> {
    let (x, y) = disk_concentric(ux, uy);
    // max(1 − r², 0), NaN to 0, as `f32::max` gives it.
    let z = (T::splat(1.0) - (x * x + y * y))
        .max_gt(T::splat(0.0))
        .sqrt();
    V3::new(x, y, z)
}

/// Solid-angle density of `square_to_cosine_hemisphere`: cos θ / π above the surface, 0 below.
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z > 0.0 { w.z * INV_PI } else { 0.0 }
}

/// Uniform direction on the upper hemisphere; pdf 1/(2π).
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = 1.0 - u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of `square_to_uniform_hemisphere`.
pub fn uniform_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z >= 0.0 { 0.5 * INV_PI } else { 0.0 }
}

/// Uniform direction in the cone of directions within angle acos(`cos_max`) of +z;
/// pdf 1 / (2π (1 − cos_max)).
pub fn square_to_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let z = 1.0 - u.x * (1.0 - cos_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of `square_to_uniform_cone`.
pub fn uniform_cone_pdf(w: Vec3, cos_max: f32) -> f32 {
    if w.z >= cos_max && cos_max < 1.0 {
        0.5 * INV_PI / (1.0 - cos_max)
    } else {
        0.0
    }
}

/// Direction on the upper hemisphere with density proportional to cosⁿθ about +z (the lobe of
/// the modified Phong model, Lafortune & Willems 1994): pdf (n + 1)/(2π) cosⁿθ.
/// Inverts the CDF 1 − cos^(n+1)θ.
pub fn square_to_cosine_power(u: Vec2, exponent: f32) -> Vec3 {
    // 1 − u.x is in (0, 1]: cos θ = (1 − u.x)^(1/(n+1)) never reaches 0 from the top end.
    let z = (1.0 - u.x).powf(1.0 / (exponent + 1.0));
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of `square_to_cosine_power`.
pub fn cosine_power_pdf(w: Vec3, exponent: f32) -> f32 {
    if w.z > 0.0 {
        (exponent + 1.0) * 0.5 * INV_PI * w.z.powf(exponent)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed, well-spread set of points of the unit square (a 64×64 jittered grid with a
    /// deterministic hash for the jitter).
    fn points() -> impl Iterator<Item = Vec2> {
        (0..64u32).flat_map(|i| {
            (0..64u32).map(move |j| {
                let h = (i.wrapping_mul(0x9E37_79B9) ^ j.wrapping_mul(0x85EB_CA6B))
                    .wrapping_mul(0xC2B2_AE35);
                let jx = (h & 0xFFFF) as f32 / 65536.0;
                let jy = (h >> 16) as f32 / 65536.0;
                Vec2::new((i as f32 + jx) / 64.0, (j as f32 + jy) / 64.0)
            })
        })
    }

    #[test]
    fn directions_are_unit_and_on_their_domain() {
        for u in points() {
            let d = square_to_disk_concentric(u);
            assert!(d.length() <= 1.0 + 1e-6);
            for (w, upper) in [
                (square_to_cosine_hemisphere(u), true),
                (square_to_uniform_hemisphere(u), true),
                (square_to_uniform_cone(u, 0.8), true),
                (square_to_cosine_power(u, 20.0), true),
                (square_to_sphere(u), false),
            ] {
                assert!((w.length() - 1.0).abs() < 1e-5, "{w:?}");
                assert!(!upper || w.z >= 0.0);
            }
            assert!(square_to_uniform_cone(u, 0.8).z >= 0.8 - 1e-6);
        }
    }

    /// The concentric map's polynomial sine and cosine stay within 2e-7 (under two f32
    /// ulps at 1) of the double-precision functions over their whole interval.
    #[test]
    fn quarter_sin_cos_match_the_exact_functions() {
        let n = 100_000;
        for i in 0..=n {
            let theta = (PI / 4.0) * (2.0 * i as f32 / n as f32 - 1.0);
            let (sin, cos) = sin_cos_quarter(theta);
            let t = theta as f64;
            assert!((sin as f64 - t.sin()).abs() < 2e-7, "sin {theta}");
            assert!((cos as f64 - t.cos()).abs() < 2e-7, "cos {theta}");
        }
    }

    /// The full-range sine and cosine stay within 4e-7 of the double-precision functions
    /// over [−π/4, 4π) (the reduction adds a rounding of φ − kπ/2), and sixteen lanes give
    /// each lane the scalar call's bits.
    #[test]
    fn turned_sin_cos_match_the_exact_functions_and_their_lanes() {
        use crate::math::lanes::F32x16;
        let n = 160_000;
        let angles: Vec<f32> = (0..n)
            .map(|i| -PI / 4.0 + (4.25 * PI) * i as f32 / n as f32)
            .chain([
                0.0,
                -0.0,
                PI / 4.0,
                PI / 2.0,
                PI,
                1.5 * PI,
                2.0 * PI,
                3.75 * PI,
            ])
            .collect();
        for chunk in angles.chunks(16) {
            let a: [f32; 16] = std::array::from_fn(|i| chunk.get(i).copied().unwrap_or(1.0));
            let (ls, lc) = sin_cos_turns(F32x16::from_array(a));
            let (ls, lc) = (ls.to_array(), lc.to_array());
            for i in 0..16 {
                let (sin, cos) = sin_cos_turns(a[i]);
                let t = a[i] as f64;
                // Against the exact functions of the rounded f32 angle.
                assert!((sin as f64 - t.sin()).abs() < 4e-7, "sin {}", a[i]);
                assert!((cos as f64 - t.cos()).abs() < 4e-7, "cos {}", a[i]);
                assert_eq!(
                    (ls[i].to_bits(), lc[i].to_bits()),
                    (sin.to_bits(), cos.to_bits())
                );
            }
        }
    }

    /// The mean of a test function under each warp equals its integral against the pdf,
    /// computed independently in closed form: E[z] for each density.
    #[test]
    fn first_moments_match_closed_forms() {
        let n = points().count() as f64;
        let mean = |f: &dyn Fn(Vec2) -> f32| points().map(|u| f(u) as f64).sum::<f64>() / n;
        // cosine hemisphere: E[cos θ] = ∫ cos² θ / π dω = 2/3
        assert!((mean(&|u| square_to_cosine_hemisphere(u).z) - 2.0 / 3.0).abs() < 1e-3);
        // uniform hemisphere: E[cos θ] = 1/2
        assert!((mean(&|u| square_to_uniform_hemisphere(u).z) - 0.5).abs() < 1e-3);
        // cone: z uniform on [cos_max, 1]
        assert!((mean(&|u| square_to_uniform_cone(u, 0.6).z) - 0.8).abs() < 1e-3);
        // cosine power n: E[cos θ] = (n + 1)/(n + 2)
        assert!((mean(&|u| square_to_cosine_power(u, 9.0).z) - 10.0 / 11.0).abs() < 1e-3);
        // disk: E[r²] = 1/2
        assert!((mean(&|u| square_to_disk_concentric(u).length_squared()) - 0.5).abs() < 1e-3);
    }

    #[test]
    fn pdfs_integrate_to_one() {
        // Midpoint rule on a (cos θ, φ) grid: dω = d(cos θ) dφ.
        let (nz, nphi) = (400, 64);
        let integrate = |pdf: &dyn Fn(Vec3) -> f32| {
            let mut sum = 0.0f64;
            for i in 0..nz {
                let z = -1.0 + 2.0 * (i as f32 + 0.5) / nz as f32;
                let r = (1.0 - z * z).sqrt();
                for j in 0..nphi {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / nphi as f32;
                    sum += pdf(Vec3::new(r * phi.cos(), r * phi.sin(), z)) as f64;
                }
            }
            sum * (2.0 / nz as f64) * (2.0 * std::f64::consts::PI / nphi as f64)
        };
        assert!((integrate(&cosine_hemisphere_pdf) - 1.0).abs() < 1e-3);
        assert!((integrate(&uniform_hemisphere_pdf) - 1.0).abs() < 1e-2);
        assert!((integrate(&|w| uniform_cone_pdf(w, 0.5)) - 1.0).abs() < 1e-2);
        assert!((integrate(&|w| cosine_power_pdf(w, 5.0)) - 1.0).abs() < 1e-3);
        assert!((integrate(&|_| sphere_pdf()) - 1.0).abs() < 1e-5);
    }
}
