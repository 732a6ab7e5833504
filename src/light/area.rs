//! Area lights: uniform radiance leaving the front side of a shape (Mitsuba 3's `area`
//! emitter: one-sided). The side is the shading normal's (`ShapePoint::front`: the
//! interpolated vertex normal on meshes that have them, as Mitsuba 3 decides it), while
//! densities convert between area and solid angle with the geometric normal.

use glam::{Vec2, Vec3};

use crate::light::shape_sampling::ShapeSampler;
use crate::light::{EmissionLanes, EmissionSample, LightPoint, LightSample, LightSampleLanes};
use crate::math::lanes::{F32x16, Mask16, V3};
use crate::math::{Frame, INV_PI, PI, Rgb, warp};

#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pub shape: ShapeSampler,
    /// Index of the shape in `SceneDescription::shapes`.
    pub shape_index: usize,
    pub radiance: Rgb,
}

impl AreaLight {
    pub fn new(shape: ShapeSampler, shape_index: usize, radiance: Rgb) -> Self {
        AreaLight {
            shape,
            shape_index,
            radiance,
        }
    }

    /// Φ = π A L̄: a Lambertian emitter of radiance L over area A sends π L per unit area
    /// into its hemisphere (L̄ the channel mean).
    pub fn power(&self) -> f32 {
        PI * self.shape.area() * self.radiance.mean()
    }

    /// Radiance leaving `hit` towards `w` (unit or not): L on the front side, black behind.
    pub fn le(&self, hit: &LightPoint, w: Vec3) -> Rgb {
        if hit.front.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::BLACK
        }
    }

    #[inline]
    pub fn sample_li(&self, r: Vec3, u: Vec2) -> Option<LightSample> {
        let s = self.shape.sample_from(r, u)?;
        let d = s.point.p - r;
        let dist = d.length();
        if dist.is_nan() || dist <= 0.0 {
            return None;
        }
        let wi = d / dist;
        // One-sided: the sampled point must face the reference point.
        let faces_r = s.point.front.dot(wi) < 0.0; // false for NaN too
        if !faces_r {
            return None;
        }
        Some(LightSample {
            p: s.point.p,
            n: s.point.n,
            front: s.point.front,
            p_error: s.point.p_error,
            primitive: s.point.primitive,
            wi,
            dist,
            radiance: self.radiance,
            pdf_solid_angle: s.pdf_solid_angle,
            pdf_area: s.pdf_area,
            delta: false,
        })
    }

    /// `sample_li` for the lanes of `m` (reference points `r`), lane by lane the same bits;
    /// None where the lanes cannot sample the shape (`ShapeSampler::sample_from_lanes`).
    #[inline]
    pub fn sample_li_lanes(
        &self,
        r: V3<F32x16>,
        ux: F32x16,
        uy: F32x16,
        m: Mask16,
    ) -> Option<LightSampleLanes> {
        let s = self.shape.sample_from_lanes(r, ux, uy, m)?;
        let d = s.point.p - r;
        let dist = d.length();
        let wi = d.div_scalar(dist);
        // One-sided, as `sample_li` (false for NaN too).
        let faces_r = s.point.front.dot(wi).lt(F32x16::splat(0.0));
        let c = |v: f32| F32x16::splat(v);
        Some(LightSampleLanes {
            ok: s.ok & dist.gt(c(0.0)) & faces_r,
            p: s.point.p,
            n: s.point.n,
            p_error: s.point.p_error,
            wi,
            radiance: V3::new(
                c(self.radiance.r()),
                c(self.radiance.g()),
                c(self.radiance.b()),
            ),
            pdf_solid_angle: s.pdf_solid_angle,
            pdf_area: s.pdf_area,
            delta: false,
            at_infinity: false,
        })
    }

    /// `le` towards `w` and `pdf_li` from `r` at hit points (`p`, `n`, `front`), per lane,
    /// as `le` and `pdf_li` compute them (None is kept for shapes whose density is not done
    /// in lanes; every shape's is).
    #[inline]
    pub fn emission_lanes(
        &self,
        p: V3<F32x16>,
        n: V3<F32x16>,
        front: V3<F32x16>,
        w: V3<F32x16>,
        r: V3<F32x16>,
    ) -> Option<EmissionLanes> {
        let zero = F32x16::splat(0.0);
        let pdf = self.shape.pdf_from_lanes(r, p, n)?;
        // One-sided: only points facing the reference point have a density.
        let faces_r = front.dot(r - p).gt(zero);
        let c = |v: f32| F32x16::splat(v);
        Some(EmissionLanes {
            emits: front.dot(w).gt(zero),
            radiance: V3::new(
                c(self.radiance.r()),
                c(self.radiance.g()),
                c(self.radiance.b()),
            ),
            pdf_li: F32x16::select(faces_r, pdf, zero),
        })
    }

    /// Solid-angle density of `sample_li(r, ·)` returning `hit`: 0 for points facing away.
    pub fn pdf_li(&self, r: Vec3, hit: &LightPoint) -> f32 {
        let faces_r = hit.front.dot(r - hit.p) > 0.0; // false for NaN too
        if !faces_r {
            return 0.0;
        }
        self.shape.pdf_from(r, hit.p, hit.n)
    }

    /// A point uniform by area, a direction cosine-distributed about the front normal.
    pub fn sample_le(&self, u1: Vec2, u2: Vec2) -> Option<EmissionSample> {
        let point = self.shape.sample_area(u1);
        let local = warp::square_to_cosine_hemisphere(u2);
        let pdf_dir = local.z * INV_PI;
        if pdf_dir.is_nan() || pdf_dir <= 0.0 {
            return None;
        }
        let direction = Frame::from_normal(point.front).to_world(local).normalize();
        Some(EmissionSample {
            origin: point.p,
            direction,
            n: point.n,
            front: point.front,
            p_error: point.p_error,
            primitive: point.primitive,
            radiance: self.radiance,
            pdf_pos: 1.0 / self.shape.area(),
            pdf_dir,
            delta_pos: false,
            delta_dir: false,
        })
    }

    /// (1/A, cos θ/π) for a point of the light with normal `n` and direction `dir`.
    pub fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        let cos = n.dot(dir.normalize_or_zero());
        (1.0 / self.shape.area(), cos.max(0.0) * INV_PI)
    }
}
