//! Analytic disks: the unit disk of the local xy plane (normal +z) under an affine
//! `to_world`, intersected in f64 like the spheres (few of them, exact enough that a ray
//! spawned from the disk always sees its origin on the correct side).

use glam::{DMat4, DVec3, Mat4, Vec2, Vec3};

use super::AnalyticHit;
use super::offset::gamma;
use crate::math::Transform;
use crate::math::lanes::{F64x8, Mask8};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    /// The scene's f32 matrix, taken as exact: the disk is M·(x, y, 0, 1), x² + y² ≤ 1.
    pub to_world: Mat4,
    to_world64: DMat4,
    /// Inverse of `to_world`, computed in f64 from the f32 matrix (the f32 inverse is only
    /// accurate to ~1e-7 relative, not enough to place an offset origin on the right side).
    to_local64: DMat4,
    /// Unit normal: the local +z through the inverse transpose, negated by `flip_normals`.
    pub n: Vec3,
    pub shape: u32,
    /// Whether hits compute (u, v) (as `Sphere::uv`).
    pub uv: bool,
}

impl Disk {
    /// None when the transform is singular or not finite.
    pub fn new(to_world: &Transform, flip_normals: bool, shape: u32) -> Option<Disk> {
        let m = to_world.matrix;
        let m64 = m.as_dmat4();
        let det = m64.determinant();
        if !m.is_finite() || !det.is_finite() || det == 0.0 {
            return None;
        }
        let inv = m64.inverse();
        // Normal = (M⁻¹)ᵀ·(0, 0, 1): the third row of M⁻¹.
        let n = DVec3::new(inv.x_axis.z, inv.y_axis.z, inv.z_axis.z);
        let n = (n / n.length()).as_vec3().normalize();
        if !n.is_finite() {
            return None;
        }
        Some(Disk {
            to_world: m,
            to_world64: m64,
            to_local64: inv,
            n: if flip_normals { -n } else { n },
            shape,
            uv: true,
        })
    }

    /// t in (0, t_max) where o + t·d crosses the disk, with the local (x, y) of the hit.
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f64) -> Option<(f64, [f64; 2])> {
        let ol = self.to_local64.transform_point3(o.as_dvec3());
        let dl = self.to_local64.transform_vector3(d.as_dvec3());
        let t = -ol.z / dl.z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let (x, y) = (ol.x + t * dl.x, ol.y + t * dl.y);
        if x * x + y * y > 1.0 {
            return None;
        }
        Some((t, [x, y]))
    }

    /// `intersect` for eight rays in f64 lanes (origins `o`, directions `d` widened from
    /// f32, segment ends `t_max`), lane by lane the same operations in the same order as
    /// glam's `transform_point3` and `transform_vector3` and the test above, so the same
    /// bits: the lanes of `m` that hit, their t and local (x, y).
    #[inline(always)]
    pub fn intersect_lanes(
        &self,
        o: &[F64x8; 3],
        d: &[F64x8; 3],
        t_max: F64x8,
        m: Mask8,
    ) -> (Mask8, F64x8, [F64x8; 2]) {
        let splat = F64x8::splat;
        let a = &self.to_local64;
        // Row k of the local point: x_axis·o.x, then y_axis·o.y + that, then z_axis·o.z +
        // that (then w_axis + that for a point), as glam sums the columns.
        let row = |k: usize, v: &[F64x8; 3]| {
            let r = splat(a.x_axis[k]) * v[0];
            let r = splat(a.y_axis[k]) * v[1] + r;
            splat(a.z_axis[k]) * v[2] + r
        };
        let ol = [0, 1, 2].map(|k| splat(a.w_axis[k]) + row(k, o));
        let dl = [0, 1, 2].map(|k| row(k, d));
        let t = -ol[2] / dl[2];
        let between = m & t.gt(splat(0.0)) & t.lt(t_max);
        if between.none() {
            return (Mask8::NONE, t, [t, t]);
        }
        let x = ol[0] + t * dl[0];
        let y = ol[1] + t * dl[1];
        let outside = (x * x + y * y).gt(splat(1.0));
        (between & !outside, t, [x, y])
    }

    /// The surface data at local point (x, y). The point is M·(x, y, 0, 1) in f64: exactly
    /// on the disk's plane up to f64 error (a few 2⁻⁵³ of Σ|M_ij·q_j|), then rounded to f32
    /// (u·|p|): bound γ(2)·|p| + 2⁻⁴⁶·Σ|M_ij·q_j|. uv as Mitsuba's disk: (r, φ/2π) with
    /// φ = atan2(y, x) in [0, 2π).
    pub fn hit(&self, local: [f64; 2]) -> AnalyticHit {
        let [x, y] = local;
        let p64 = self.to_world64.transform_point3(DVec3::new(x, y, 0.0));
        let p = p64.as_vec3();
        let m = &self.to_world;
        let scale = (m.x_axis.truncate() * x as f32).abs()
            + (m.y_axis.truncate() * y as f32).abs()
            + m.w_axis.truncate().abs();
        let p_error = p.abs() * gamma(2) + scale * (2.0f32).powi(-46);
        let uv = if self.uv {
            let mut v = y.atan2(x) / (2.0 * std::f64::consts::PI);
            if v < 0.0 {
                v += 1.0;
            }
            Vec2::new(x.hypot(y) as f32, v as f32)
        } else {
            Vec2::ZERO
        };
        AnalyticHit {
            p,
            p_error,
            n: self.n,
            uv,
        }
    }

    /// Bounding box (min, max) of the transformed unit square around the disk.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for (x, y) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            let p = self.to_world.transform_point3(Vec3::new(x, y, 0.0));
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_rotated_disk() {
        let m = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
            * Mat4::from_scale(Vec3::splat(2.0));
        let disk = Disk::new(&Transform::new(m).unwrap(), false, 0).unwrap();
        // local +z maps to world −y after the rotation about x by +90°
        assert!((disk.n - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6);
        let o = Vec3::new(1.5, -5.0, 3.0);
        let (t, local) = disk.intersect(o, Vec3::Y, f64::INFINITY).unwrap();
        assert!((t - 7.0).abs() < 1e-9);
        let h = disk.hit(local);
        assert!((h.p - Vec3::new(1.5, 2.0, 3.0)).length() < 1e-6);
        assert!((h.uv.x - 0.25).abs() < 1e-6);
        assert!(
            disk.intersect(Vec3::new(4.5, -5.0, 3.0), Vec3::Y, f64::INFINITY)
                .is_none()
        );
        let flipped = Disk::new(&Transform::new(m).unwrap(), true, 0).unwrap();
        assert_eq!(flipped.n, -disk.n);
    }
}
