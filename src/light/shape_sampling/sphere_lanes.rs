//! The emitting sphere's cone sampling and density for sixteen reference points at once:
//! `SphereSampler::sample_cone`, `sees_outside` and `cone_pdf` step by step, the f64 steps in
//! two halves of eight f64 lanes, so that each lane holds the bits of the scalar call.

use glam::Vec3;

use super::{ShapePointLanes, ShapeSampleLanes, SphereSampler};
use crate::math::frame::LaneFrame;
use crate::math::lanes::{F32x16, F64x8, Mask16, V3};
use crate::math::{PI, warp};

/// A vector of f64 lanes, by coordinate.
type Wide3 = [F64x8; 3];

/// `f64::min(x, 1.0)` per lane (NaN gives 1).
#[inline(always)]
fn min_one(x: F64x8) -> F64x8 {
    F64x8::select(x.lt(F64x8::splat(1.0)), x, F64x8::splat(1.0))
}

/// `f64::max(x, 0.0)` per lane (NaN gives 0).
#[inline(always)]
fn max_zero(x: F64x8) -> F64x8 {
    F64x8::select(x.gt(F64x8::splat(0.0)), x, F64x8::splat(0.0))
}

/// `f64::clamp(x, −1.0, 1.0)` per lane (NaN stays NaN).
#[inline(always)]
fn clamp_unit(x: F64x8) -> F64x8 {
    let x = F64x8::select(x.lt(F64x8::splat(-1.0)), F64x8::splat(-1.0), x);
    F64x8::select(x.gt(F64x8::splat(1.0)), F64x8::splat(1.0), x)
}

/// `DVec3::dot`: (x·x' + y·y') + z·z'.
#[inline(always)]
fn dot(a: &Wide3, b: &Wide3) -> F64x8 {
    (a[0] * b[0]) + (a[1] * b[1]) + (a[2] * b[2])
}

/// `v` in every lane.
#[inline(always)]
fn splat3(v: Vec3) -> V3<F32x16> {
    V3::new(F32x16::splat(v.x), F32x16::splat(v.y), F32x16::splat(v.z))
}

/// The two f64 halves of each coordinate of `v`.
#[inline(always)]
fn widen(v: &V3<F32x16>) -> [Wide3; 2] {
    let [(x0, x1), (y0, y1), (z0, z1)] = [v.x, v.y, v.z].map(F32x16::to_f64_halves);
    [[x0, y0, z0], [x1, y1, z1]]
}

/// `DVec3::as_vec3` of both halves.
#[inline(always)]
fn narrow(v: &[Wide3; 2]) -> V3<F32x16> {
    let c = |k: usize| F32x16::from_f64_halves(v[0][k], v[1][k]);
    V3::new(c(0), c(1), c(2))
}

impl SphereSampler {
    /// `sees_outside` per lane.
    #[inline(always)]
    pub(super) fn sees_outside_lanes(&self, r: V3<F32x16>) -> Mask16 {
        const MARGIN: f32 = 1.0 + 1e-3;
        (splat3(self.center) - r)
            .length_squared()
            .gt(F32x16::splat(self.radius * self.radius * MARGIN))
    }

    /// `one_minus_cos_max` for one half of the lanes (reference points `r`), with the
    /// distance d and the unit axis from the centre towards `r` that `sample_cone` also
    /// uses.
    #[inline(always)]
    fn cone_of(&self, r: &Wide3) -> (F64x8, F64x8, Wide3) {
        let c = self.center.as_dvec3();
        let radius = self.radius as f64;
        let axis_v = [
            r[0] - F64x8::splat(c.x),
            r[1] - F64x8::splat(c.y),
            r[2] - F64x8::splat(c.z),
        ];
        let d2 = dot(&axis_v, &axis_v);
        let d = d2.sqrt();
        let axis = axis_v.map(|v| v / d);
        let sin2_max = min_one(F64x8::splat(radius * radius) / d2);
        let cos_max = max_zero(F64x8::splat(1.0) - sin2_max).sqrt();
        (sin2_max / (F64x8::splat(1.0) + cos_max), d, axis)
    }

    /// `cone_pdf` per lane.
    #[inline(always)]
    pub(super) fn cone_pdf_lanes(&self, r: V3<F32x16>) -> F32x16 {
        let pdf = widen(&r).map(|r| {
            let (one_minus_cos_max, _, _) = self.cone_of(&r);
            F64x8::splat(1.0) / (F64x8::splat(2.0 * std::f64::consts::PI) * one_minus_cos_max)
        });
        F32x16::from_f64_halves(pdf[0], pdf[1])
    }

    /// `sample_cone` for the lanes of `m` (every one outside the sphere): the lanes of `ok`
    /// have a point; the area density is folded into `ok` (finite where `sample_li` keeps
    /// the sample), its one value left at 1.
    pub(super) fn sample_cone_lanes(
        &self,
        r: V3<F32x16>,
        ux: F32x16,
        uy: F32x16,
        m: Mask16,
    ) -> ShapeSampleLanes {
        let one = F64x8::splat(1.0);
        let radius = F64x8::splat(self.radius as f64);
        let r_wide = widen(&r);
        let ux = ux.to_f64_halves();
        let ux = [ux.0, ux.1];
        // Per half: the cone, cos α and sin α of the point's angle at the centre, the axis.
        let mut cone = [(F64x8::splat(0.0), [F64x8::splat(0.0); 3]); 2];
        let mut alpha = [(F64x8::splat(0.0), F64x8::splat(0.0)); 2];
        for h in 0..2 {
            let (one_minus_cos_max, d, axis) = self.cone_of(&r_wide[h]);
            let one_minus_cos = ux[h] * one_minus_cos_max;
            let sin2 = max_zero(one_minus_cos * (F64x8::splat(2.0) - one_minus_cos));
            let cos = one - one_minus_cos;
            let k = d / radius;
            let root = max_zero(one - (k * k) * sin2).sqrt();
            let cos_alpha = clamp_unit(k * sin2 + cos * root);
            let sin_alpha = max_zero(one - cos_alpha * cos_alpha).sqrt();
            cone[h] = (one_minus_cos_max, axis);
            alpha[h] = (cos_alpha, sin_alpha);
        }
        // The frame about the axis (in f32, as `Frame::from_normal(axis.as_vec3())`).
        let axis32 = narrow(&[cone[0].1, cone[1].1]);
        let frame = LaneFrame::from_normal(axis32);
        let (s, t) = (widen(&frame.s), widen(&frame.t));
        let (sin_phi, cos_phi) = warp::sin_cos_turns(F32x16::splat(2.0 * PI) * uy);
        let (sin_phi, cos_phi) = (sin_phi.to_f64_halves(), cos_phi.to_f64_halves());
        let (sin_phi, cos_phi) = ([sin_phi.0, sin_phi.1], [cos_phi.0, cos_phi.1]);
        let c = self.center.as_dvec3();
        let center = [c.x, c.y, c.z].map(F64x8::splat);
        let mut outward = [[F64x8::splat(0.0); 3]; 2];
        let mut p = [[F64x8::splat(0.0); 3]; 2];
        for h in 0..2 {
            let (cos_alpha, sin_alpha) = alpha[h];
            let (a, b) = (sin_alpha * cos_phi[h], sin_alpha * sin_phi[h]);
            let axis = cone[h].1;
            let o: Wide3 =
                std::array::from_fn(|k| (s[h][k] * a + t[h][k] * b) + axis[k] * cos_alpha);
            // `DVec3::normalize`: times the reciprocal of the length.
            let inv = one / dot(&o, &o).sqrt();
            outward[h] = o.map(|v| v * inv);
            p[h] = std::array::from_fn(|k| center[k] + outward[h][k] * radius);
        }
        let p = narrow(&p);
        let outward = narrow(&outward);
        let n = if self.flip_normals { -outward } else { outward };
        let dist2 = (p - r).length_squared();
        let pdf = [0, 1].map(|h| one / (F64x8::splat(2.0 * std::f64::consts::PI) * cone[h].0));
        let pdf_solid_angle = F32x16::from_f64_halves(pdf[0], pdf[1]);
        let cos_light = n.dot(r - p).abs() / dist2.sqrt();
        let pdf_area = pdf_solid_angle * cos_light / dist2;
        // Not NaN and positive (`sample_cone`), an area density `sample_li` keeps.
        let ok = m & dist2.gt(F32x16::splat(0.0)) & pdf_area.is_finite();
        let p_error = self.p_error();
        ShapeSampleLanes {
            ok,
            point: ShapePointLanes {
                p,
                n,
                front: n,
                p_error: splat3(p_error),
            },
            pdf_solid_angle,
            pdf_area: 1.0,
        }
    }
}
