//! Analytic spheres, intersected in f64.
//!
//! Few spheres appear in a scene, so they are tested one by one beside the BVH, in double
//! precision: the roots are then accurate to ~1e-16 relative, far below the f32 offsets of
//! spawned ray origins, so the sign of t (self-intersection) is never in doubt.

use glam::{DVec3, Vec2, Vec3};

use super::AnalyticHit;
use super::offset::gamma;
use crate::math::fast_trig;
use crate::math::lanes::{F64x8, Mask8};
use std::f32::consts::PI;

/// A sphere of `flip_normals` orientation, belonging to shape `shape`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub flip_normals: bool,
    pub shape: u32,
    /// Whether hits compute (u, v) (two inverse trigonometric calls): only a textured
    /// BSDF reads them (`Geometry::keep_uv_only_for`); zero otherwise.
    pub uv: bool,
}

impl Sphere {
    /// True when the sphere can be hit at all (finite centre, finite positive radius).
    pub fn is_valid(&self) -> bool {
        self.center.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }

    /// Smallest t in (0, t_max) with o + t·d on the sphere (t in units of d).
    ///
    /// The discriminant is formed from the distance between the centre and the ray's line
    /// rather than from b² − 4ac, which cancels catastrophically for small spheres far from
    /// the origin (Haines, Günther & Akenine-Möller, "Precision Improvements for Ray/Sphere
    /// Intersection", Ray Tracing Gems, 2019, ch. 7): that distance is |f × d|/|d| (f from
    /// the centre to o), so a·disc = r²·a − |f × d|² needs no division, and a ray that
    /// misses (most tests) costs no division or square root. The roots use the stable
    /// quadratic formula (no subtraction of nearly equal numbers).
    #[inline(always)]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f64) -> Option<f64> {
        let d = d.as_dvec3();
        let f = o.as_dvec3() - self.center.as_dvec3();
        let r = self.radius as f64;
        let a = d.length_squared();
        let a_disc = r * r * a - f.cross(d).length_squared();
        if a_disc.is_nan() || a_disc < 0.0 {
            return None;
        }
        let b = f.dot(d); // half of the usual b
        let c = f.length_squared() - r * r;
        let q = -(b + a_disc.sqrt().copysign(b));
        let (t0, t1) = if q == 0.0 {
            let t = -b / a;
            (t, t)
        } else {
            let (x, y) = (c / q, q / a);
            if x <= y { (x, y) } else { (y, x) }
        };
        if t0 > 0.0 && t0 < t_max {
            Some(t0)
        } else if t1 > 0.0 && t1 < t_max {
            Some(t1)
        } else {
            None
        }
    }

    /// `intersect` for eight rays in f64 lanes (origins `o` and directions `d` widened from
    /// f32, segment ends `t_max`), lane by lane the same operations and so the same bits:
    /// the lanes of `m` that hit, and their t.
    #[inline(always)]
    pub fn intersect_lanes(
        &self,
        o: &[F64x8; 3],
        d: &[F64x8; 3],
        t_max: F64x8,
        m: Mask8,
    ) -> (Mask8, F64x8) {
        let splat = F64x8::splat;
        let zero = splat(0.0);
        // `DVec3::dot` and `DVec3::cross`, operation for operation.
        let dot = |a: &[F64x8; 3], b: &[F64x8; 3]| (a[0] * b[0]) + (a[1] * b[1]) + (a[2] * b[2]);
        let c = self.center.as_dvec3();
        let f = [o[0] - splat(c.x), o[1] - splat(c.y), o[2] - splat(c.z)];
        let r = self.radius as f64;
        let a = dot(d, d);
        let f_cross_d = [
            f[1] * d[2] - d[1] * f[2],
            f[2] * d[0] - d[2] * f[0],
            f[0] * d[1] - d[0] * f[1],
        ];
        let a_disc = splat(r * r) * a - dot(&f_cross_d, &f_cross_d);
        // Not NaN and not negative.
        let real = m & zero.le(a_disc);
        if real.none() {
            return (Mask8::NONE, zero);
        }
        let b = dot(&f, d);
        let c = dot(&f, &f) - splat(r * r);
        let q = -(b + a_disc.sqrt().copysign(b));
        let (x, y) = (c / q, q / a);
        let ordered = x.le(y);
        let double = q.eq(zero);
        let t = -b / a;
        let t0 = F64x8::select(double, t, F64x8::select(ordered, x, y));
        let t1 = F64x8::select(double, t, F64x8::select(ordered, y, x));
        let hit0 = t0.gt(zero) & t0.lt(t_max);
        let hit1 = t1.gt(zero) & t1.lt(t_max);
        (real & (hit0 | hit1), F64x8::select(hit0, t0, t1))
    }

    /// The surface data where `o + t·d` meets the sphere.
    ///
    /// The hit is reprojected onto the sphere in f64 (`c + r·(h − c)/|h − c|`), so the only
    /// errors are the f64 ones (a few 2⁻⁵³ of |c| + r) and the final rounding to f32 (u·|p|
    /// per coordinate). The bound is γ(2)·|p| + 2⁻⁴⁶·(|c| + r): generous on both counts.
    /// uv as Mitsuba's sphere: u = φ/2π with φ = atan2(y, x) in [0, 2π), v = θ/π from +z.
    pub fn hit(&self, o: Vec3, d: Vec3, t: f64) -> AnalyticHit {
        let c = self.center.as_dvec3();
        let h = o.as_dvec3() + d.as_dvec3() * t;
        let mut n = h - c;
        let len = n.length();
        n = if len > 0.0 { n / len } else { DVec3::Z };
        let p64 = c + n * self.radius as f64;
        let p = p64.as_vec3();
        let p_error = p.abs() * gamma(2)
            + (self.center.abs() + Vec3::splat(self.radius)) * (2.0f32).powi(-46);
        let uv = if self.uv {
            // The angles in f32 by `fast_trig` (within 4·10⁻⁷ rad: under 10⁻⁷ of the unit
            // square, far below any texel), not libm's f64 atan2, which was 4% of `pt` on
            // the textures scene.
            let m = n.as_vec3();
            let mut phi = fast_trig::atan2(m.y, m.x);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            let theta = fast_trig::atan2(m.x.hypot(m.y), m.z);
            Vec2::new(phi / (2.0 * PI), theta / PI)
        } else {
            Vec2::ZERO
        };
        let n = n.as_vec3().normalize();
        AnalyticHit {
            p,
            p_error,
            n: if self.flip_normals { -n } else { n },
            uv,
        }
    }

    /// Bounding box (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (
            self.center - Vec3::splat(self.radius),
            self.center + Vec3::splat(self.radius),
        )
    }
}

/// The f64 part of `Sphere::hit` for eight rays, each on its own sphere (centres `c` and
/// radii `r` widened from f32): the hit `o + t·d` reprojected onto its sphere, and the unit
/// normal there, lane by lane the same operations as `hit` and so the same bits.
#[inline(always)]
pub fn reproject_lanes(
    c: &[F64x8; 3],
    r: F64x8,
    o: &[F64x8; 3],
    d: &[F64x8; 3],
    t: F64x8,
) -> ([F64x8; 3], [F64x8; 3]) {
    let n: [F64x8; 3] = std::array::from_fn(|k| (o[k] + d[k] * t) - c[k]);
    let len = ((n[0] * n[0]) + (n[1] * n[1]) + (n[2] * n[2])).sqrt();
    let positive = len.gt(F64x8::splat(0.0));
    // `DVec3::Z` where the length is not positive (or NaN).
    let n: [F64x8; 3] = std::array::from_fn(|k| {
        F64x8::select(positive, n[k] / len, F64x8::splat((k == 2) as u8 as f64))
    });
    (std::array::from_fn(|k| c[k] + n[k] * r), n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiny_far_sphere_is_hit_accurately() {
        // b² − 4ac would lose every digit here in f32, and most in f64.
        let s = Sphere {
            uv: true,
            center: Vec3::new(1e5, 2e5, -3e4),
            radius: 1e-2,
            flip_normals: false,
            shape: 0,
        };
        let o = Vec3::ZERO;
        let to_c = s.center.as_dvec3();
        let d = (to_c / to_c.length()).as_vec3();
        let t = s.intersect(o, d, f64::INFINITY).unwrap();
        let dist = to_c.length() - 1e-2;
        assert!(
            (t - dist).abs() < 1e-4 * 1e-2 + dist * 1e-7,
            "{t} vs {dist}"
        );
    }

    #[test]
    fn inside_hits_far_side() {
        let s = Sphere {
            uv: true,
            center: Vec3::ZERO,
            radius: 2.0,
            flip_normals: true,
            shape: 0,
        };
        let t = s.intersect(Vec3::ZERO, Vec3::X, f64::INFINITY).unwrap();
        assert!((t - 2.0).abs() < 1e-12);
        let h = s.hit(Vec3::ZERO, Vec3::X, t);
        assert!(
            (h.n - -Vec3::X).length() < 1e-6,
            "flipped normal points inward"
        );
        assert!((h.uv - Vec2::new(0.0, 0.5)).length() < 1e-6);
        assert!(s.intersect(Vec3::ZERO, Vec3::X, 1.9).is_none());
    }
}
