//! Sampling points on the shapes that carry area lights, from the world-space shape data of
//! the scene description:
//!
//! - triangle meshes: a triangle by area (a cdf over the triangles), then a uniform point
//!   on it — uniform by area over the whole mesh;
//! - analytic spheres: seen from outside, a uniform direction in the cone the sphere
//!   subtends (uniform solid angle over the visible cap: no wasted samples on the far
//!   side); from inside, uniform by area;
//! - disks: uniform by area (a uniform point of the unit disk through the affine
//!   `to_world`, whose Jacobian is constant).
//!
//! Normals follow the geometry module (and Mitsuba): counter-clockwise triangle winding
//! (the loader has already applied `flip_normals` to meshes), outward sphere normals, the
//! disk's local +z through the inverse transpose, and `flip_normals` negating the latter two.
//! Whether a sampled point faces the reference point is for the caller (`area.rs`) to decide.

use glam::{DMat4, DVec3, Mat4, Vec2, Vec3};

use crate::geometry::offset::gamma;
use crate::light::distribution::Distribution1D;
use crate::math::lanes::{F32x16, Mask16, Real, V3};
use crate::math::{Frame, PI, Transform, warp};
use crate::scene::{ShapeDesc, ShapeGeometry, TriangleMesh};

mod sphere_lanes;

/// A point on a shape with its unit geometric normal, the normal of the side that emits, and
/// the triangle it lies on (0 for analytic shapes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapePoint {
    pub p: Vec3,
    /// The geometric normal: densities convert between area and solid angle with it.
    pub n: Vec3,
    /// Which side emits: the interpolated vertex normal on meshes that have them, as in
    /// Mitsuba 3 (which decides an emitter's side in the shading frame); `n` elsewhere.
    pub front: Vec3,
    /// A bound on the absolute rounding error of each coordinate of `p` (the true point on
    /// the shape lies in `p ± p_error`), so that rays can stop short of it robustly.
    pub p_error: Vec3,
    pub primitive: u32,
}

/// A point sampled as seen from a reference point, with its density in both measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    pub point: ShapePoint,
    /// Density of the direction from the reference point, per steradian.
    pub pdf_solid_angle: f32,
    /// Density of the point, per unit area of the shape.
    pub pdf_area: f32,
}

/// A shape ready for sampling.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeSampler {
    Mesh(MeshSampler),
    Sphere(SphereSampler),
    Disk(DiskSampler),
}

impl ShapeSampler {
    /// Err(reason) when the shape has no area that could emit (no valid triangle, radius
    /// not positive, singular disk transform, an area that underflows f32).
    pub fn new(shape: &ShapeDesc) -> Result<ShapeSampler, String> {
        let sampler = match &shape.geometry {
            ShapeGeometry::Mesh(mesh) => MeshSampler::new(mesh).map(ShapeSampler::Mesh),
            ShapeGeometry::Sphere { center, radius } => {
                SphereSampler::new(*center, *radius, shape.flip_normals).map(ShapeSampler::Sphere)
            }
            ShapeGeometry::Disk { to_world } => {
                DiskSampler::new(to_world, shape.flip_normals).map(ShapeSampler::Disk)
            }
        }?;
        // Points are drawn with density 1/A: it must be finite (a sphere of radius 1e-40 has
        // A = 0 in f32, and would emit nothing).
        let area = sampler.area();
        if !area.is_normal() {
            return Err(format!(
                "its surface area is {area:e} in f32, too small to sample (the density 1/area \
                 of its points is not finite)"
            ));
        }
        Ok(sampler)
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        match self {
            ShapeSampler::Mesh(m) => m.area,
            ShapeSampler::Sphere(s) => 4.0 * PI * s.radius * s.radius,
            ShapeSampler::Disk(d) => d.area,
        }
    }

    /// A point uniformly distributed by area (density 1 / area).
    pub fn sample_area(&self, u: Vec2) -> ShapePoint {
        match self {
            ShapeSampler::Mesh(m) => m.sample_area(u),
            ShapeSampler::Sphere(s) => s.sample_area(u),
            ShapeSampler::Disk(d) => d.sample_area(u),
        }
    }

    /// A point sampled for the reference point `r` (the strategy of the module docs).
    /// None when the point cannot be turned into a direction (it coincides with `r`, or is
    /// seen exactly edge-on).
    #[inline]
    pub fn sample_from(&self, r: Vec3, u: Vec2) -> Option<ShapeSample> {
        if let ShapeSampler::Sphere(s) = self
            && s.sees_outside(r)
        {
            return s.sample_cone(r, u);
        }
        let point = self.sample_area(u);
        let pdf_area = 1.0 / self.area();
        let pdf_solid_angle = area_to_solid_angle(pdf_area, r, point.p, point.n);
        (pdf_solid_angle > 0.0 && pdf_solid_angle.is_finite()).then_some(ShapeSample {
            point,
            pdf_solid_angle,
            pdf_area,
        })
    }

    /// `sample_from` for the lanes of `m`, lane by lane the same bits; None where the lanes
    /// cannot sample this shape (disks, spheres from a point on them).
    #[inline]
    pub fn sample_from_lanes(
        &self,
        r: V3<F32x16>,
        ux: F32x16,
        uy: F32x16,
        m: Mask16,
    ) -> Option<ShapeSampleLanes> {
        let mesh = match self {
            ShapeSampler::Mesh(mesh) => mesh,
            // From outside (in every lane), the cone; a lane on the sphere itself, by area,
            // is left to `sample_from`.
            ShapeSampler::Sphere(s) if (m & !s.sees_outside_lanes(r)).none() => {
                return Some(s.sample_cone_lanes(r, ux, uy, m));
            }
            _ => return None,
        };
        let point = mesh.sample_area_lanes(ux, uy, m)?;
        let pdf_area = 1.0 / self.area();
        let pdf_solid_angle = area_to_solid_angle_in(F32x16::splat(pdf_area), r, point.p, point.n);
        let ok = m & pdf_solid_angle.gt(F32x16::splat(0.0)) & pdf_solid_angle.is_finite();
        Some(ShapeSampleLanes {
            ok,
            point,
            pdf_solid_angle,
            pdf_area,
        })
    }

    /// `pdf_from` for sixteen lanes, lane by lane the same bits.
    #[inline]
    pub fn pdf_from_lanes(&self, r: V3<F32x16>, p: V3<F32x16>, n: V3<F32x16>) -> Option<F32x16> {
        let pdf = area_to_solid_angle_in(F32x16::splat(1.0 / self.area()), r, p, n);
        let pdf = F32x16::select(pdf.is_finite(), pdf, F32x16::splat(0.0));
        if let ShapeSampler::Sphere(s) = self {
            // The cone's density from outside, the area's from the sphere itself.
            return Some(F32x16::select(
                s.sees_outside_lanes(r),
                s.cone_pdf_lanes(r),
                pdf,
            ));
        }
        Some(pdf)
    }

    /// The solid-angle density with which `sample_from(r, ·)` produces point `p` (normal
    /// `n`) of this shape; 0 where that density is not finite.
    pub fn pdf_from(&self, r: Vec3, p: Vec3, n: Vec3) -> f32 {
        if let ShapeSampler::Sphere(s) = self
            && s.sees_outside(r)
        {
            return s.cone_pdf(r);
        }
        let pdf = area_to_solid_angle(1.0 / self.area(), r, p, n);
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}

/// Converts an area density at `p` (normal `n`) into a solid-angle density seen from `r`:
/// pdf_A · d² / |cos θ| (0 when the distance is 0, infinite when seen edge-on).
fn area_to_solid_angle(pdf_area: f32, r: Vec3, p: Vec3, n: Vec3) -> f32 {
    area_to_solid_angle_in(pdf_area, V3::from(r), V3::from(p), V3::from(n))
}

/// `area_to_solid_angle` over `Real` (one density, or sixteen in lanes).
#[inline(always)]
fn area_to_solid_angle_in<T: Real>(pdf_area: T, r: V3<T>, p: V3<T>, n: V3<T>) -> T {
    let d = p - r;
    let dist2 = d.length_squared();
    let cos = n.dot(d).abs() / dist2.sqrt();
    // 0 for a NaN or zero distance.
    T::select(
        dist2.gt(T::splat(0.0)),
        pdf_area * dist2 / cos,
        T::splat(0.0),
    )
}

/// Uniform-by-area sampling of a triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSampler {
    triangles: Vec<[Vec3; 3]>,
    normals: Vec<Vec3>,
    /// The vertex normals of each kept triangle, when the mesh has them.
    vertex_normals: Option<Vec<[Vec3; 3]>>,
    /// Index of each kept triangle in the mesh.
    primitives: Vec<u32>,
    /// Over the kept triangles, by area.
    by_area: Distribution1D,
    area: f32,
    /// The triangles laid out for gathers by lane.
    lanes: Box<MeshLanes>,
}

/// Each kept triangle's vertex coordinates (v0.x, v0.y, v0.z, v1.x, …, v2.z) and normal
/// (n.x, n.y, n.z), one table per coordinate, indexed by triangle.
#[derive(Clone, Debug, PartialEq)]
struct MeshLanes {
    coords: [Vec<f32>; 12],
    /// The vertex normals' coordinates (n0.x, n0.y, …, n2.z), when the mesh has them.
    vertex_normals: Option<[Vec<f32>; 9]>,
}

/// Points on a shape, one per lane (see `ShapePoint`).
#[derive(Clone, Copy, Debug)]
pub struct ShapePointLanes {
    pub p: V3<F32x16>,
    pub n: V3<F32x16>,
    /// Which side emits (`ShapePoint::front`).
    pub front: V3<F32x16>,
    pub p_error: V3<F32x16>,
}

/// `ShapeSample`s in lanes: the lanes of `ok` have a point (as `sample_from` returns Some).
#[derive(Clone, Copy, Debug)]
pub struct ShapeSampleLanes {
    pub ok: Mask16,
    pub point: ShapePointLanes,
    pub pdf_solid_angle: F32x16,
    pub pdf_area: f32,
}

impl MeshSampler {
    /// Keeps the triangles the ray caster keeps too (indices in range, finite vertices, a
    /// normal that can be normalised), weighted by their area (computed in f64).
    pub fn new(mesh: &TriangleMesh) -> Result<MeshSampler, String> {
        let mut triangles = Vec::new();
        let mut normals = Vec::new();
        let mut primitives = Vec::new();
        let mut areas = Vec::new();
        let mut vertex_normals = mesh.normals.as_ref().map(|_| Vec::new());
        let mut total = 0.0f64;
        let n_vertices = mesh.positions.len();
        for (pi, idx) in mesh.indices.iter().enumerate() {
            if idx.iter().any(|&i| i as usize >= n_vertices) {
                continue;
            }
            let v = idx.map(|i| mesh.positions[i as usize]);
            let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            if !(v.iter().all(|p| p.is_finite()) && ng.is_finite()) {
                continue;
            }
            let [a, b, c] = v.map(|p| p.as_dvec3());
            let area = 0.5 * (b - a).cross(c - a).length();
            if !(area > 0.0 && area.is_finite()) {
                continue;
            }
            total += area;
            triangles.push(v);
            normals.push(ng);
            if let (Some(kept), Some(vn)) = (&mut vertex_normals, &mesh.normals) {
                kept.push(idx.map(|i| vn.get(i as usize).copied().unwrap_or(Vec3::ZERO)));
            }
            primitives.push(pi as u32);
            areas.push(area as f32);
        }
        let by_area = Distribution1D::new(&areas)
            .ok_or_else(|| "the emitting mesh has no triangle of positive area".to_string())?;
        let area = total as f32;
        if !(area > 0.0 && area.is_finite()) {
            return Err(format!("the emitting mesh has an unusable area ({total})"));
        }
        let coords = std::array::from_fn(|k| {
            (0..triangles.len())
                .map(|t| {
                    let v = if k < 9 {
                        triangles[t][k / 3]
                    } else {
                        normals[t]
                    };
                    v[k % 3]
                })
                .collect()
        });
        let lane_normals = vertex_normals.as_ref().map(|vn: &Vec<[Vec3; 3]>| {
            std::array::from_fn(|k| vn.iter().map(|n| n[k / 3][k % 3]).collect())
        });
        let lanes = Box::new(MeshLanes {
            coords,
            vertex_normals: lane_normals,
        });
        Ok(MeshSampler {
            triangles,
            normals,
            vertex_normals,
            primitives,
            by_area,
            area,
            lanes,
        })
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    /// Number of triangles kept for sampling.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    fn sample_area(&self, u: Vec2) -> ShapePoint {
        let (i, _, ux) = self.by_area.sample_discrete(u.x);
        let b = warp::square_to_triangle(Vec2::new(ux, u.y));
        let [v0, v1, v2] = self.triangles[i];
        let n = self.normals[i];
        let front = match &self.vertex_normals {
            None => n,
            Some(vn) => interpolated_normal(vn[i], b, n),
        };
        let b0 = 1.0 - b.x - b.y;
        ShapePoint {
            p: v0 * b0 + v1 * b.x + v2 * b.y,
            n,
            front,
            // Barycentric interpolation: Pharr, Jakob & Humphreys, PBR 4th ed., §6.8.5.
            p_error: (v0.abs() * b0 + v1.abs() * b.x + v2.abs() * b.y) * gamma(6),
            primitive: self.primitives[i],
        }
    }

    /// `sample_area` for the lanes of `m`, lane by lane the same bits.
    #[inline]
    pub fn sample_area_lanes(&self, ux: F32x16, uy: F32x16, m: Mask16) -> Option<ShapePointLanes> {
        let lanes = &self.lanes;
        let (i, _, ux) = self.by_area.sample_discrete_lanes(ux, m);
        let (b1, b2) = warp::triangle_barycentrics(ux, uy);
        let g = |k: usize| F32x16::gather(&lanes.coords[k], i, m);
        let vertex = |j: usize| V3::new(g(3 * j), g(3 * j + 1), g(3 * j + 2));
        let (v0, v1, v2) = (vertex(0), vertex(1), vertex(2));
        let b0 = F32x16::splat(1.0) - b1 - b2;
        let n = vertex(3);
        let front = match &lanes.vertex_normals {
            None => n,
            Some(vn) => {
                // `interpolated_normal`: the normalised interpolation, or n where it
                // vanishes (`normalize_or_zero`'s test on the reciprocal length).
                let g = |k: usize| F32x16::gather(&vn[k], i, m);
                let normal = |j: usize| V3::new(g(3 * j), g(3 * j + 1), g(3 * j + 2));
                let v = normal(0) * b0 + normal(1) * b1 + normal(2) * b2;
                let rcp = F32x16::splat(1.0) / v.length();
                let fine = rcp.is_finite() & rcp.gt(F32x16::splat(0.0));
                let zero = F32x16::splat(0.0);
                let v = V3::select(fine, v * rcp, V3::new(zero, zero, zero));
                let vanished = v.x.eq(zero) & v.y.eq(zero) & v.z.eq(zero);
                V3::select(vanished, n, v)
            }
        };
        Some(ShapePointLanes {
            p: v0 * b0 + v1 * b1 + v2 * b2,
            n,
            front,
            p_error: (v0.abs() * b0 + v1.abs() * b1 + v2.abs() * b2) * F32x16::splat(gamma(6)),
        })
    }
}

/// The normalised interpolation of vertex normals `vn` at barycentrics `b` (as the ray
/// caster's shading normal), or `n` where it vanishes.
fn interpolated_normal(vn: [Vec3; 3], b: Vec2, n: Vec3) -> Vec3 {
    let [n0, n1, n2] = vn;
    let interpolated = (n0 * (1.0 - b.x - b.y) + n1 * b.x + n2 * b.y).normalize_or_zero();
    if interpolated == Vec3::ZERO {
        n
    } else {
        interpolated
    }
}

/// An analytic sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereSampler {
    pub center: Vec3,
    pub radius: f32,
    /// Normals point inward.
    pub flip_normals: bool,
}

impl SphereSampler {
    pub fn new(center: Vec3, radius: f32, flip_normals: bool) -> Result<SphereSampler, String> {
        if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
            return Err(format!(
                "the emitting sphere needs a finite centre and a positive radius, got centre \
                 {center:?} and radius {radius}"
            ));
        }
        Ok(SphereSampler {
            center,
            radius,
            flip_normals,
        })
    }

    /// A bound on the error of a sampled point: centre + radius · unit vector in f32 (the
    /// cone's f64 arithmetic, rounded once, stays inside it too).
    fn p_error(&self) -> Vec3 {
        (self.center.abs() + Vec3::splat(self.radius)) * gamma(5)
    }

    fn normal_at(&self, outward: Vec3) -> Vec3 {
        if self.flip_normals { -outward } else { outward }
    }

    /// True when `r` is clearly outside the sphere (the cone strategy applies). A point on
    /// the sphere itself (a path vertex on an emitting sphere, whose computed position may
    /// land a rounding error outside) is sampled by area: from there only the inside is
    /// visible, which the cone would miss. Area sampling is valid from anywhere, so the
    /// margin only trades variance, never bias.
    fn sees_outside(&self, r: Vec3) -> bool {
        const MARGIN: f32 = 1.0 + 1e-3;
        (self.center - r).length_squared() > self.radius * self.radius * MARGIN
    }

    /// 1 − cos θ_max of the cone the sphere subtends from outside point `r`, computed as
    /// sin²θ_max / (1 + cos θ_max) to keep its digits for small, distant spheres.
    fn one_minus_cos_max(&self, r: Vec3) -> f64 {
        let d2 = (self.center.as_dvec3() - r.as_dvec3()).length_squared();
        let radius = self.radius as f64;
        let sin2_max = (radius * radius / d2).min(1.0);
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        sin2_max / (1.0 + cos_max)
    }

    /// The uniform density over the cone, 1 / (2π (1 − cos θ_max)).
    fn cone_pdf(&self, r: Vec3) -> f32 {
        (1.0 / (2.0 * std::f64::consts::PI * self.one_minus_cos_max(r))) as f32
    }

    fn sample_area(&self, u: Vec2) -> ShapePoint {
        let w = warp::square_to_sphere(u);
        let n = self.normal_at(w);
        ShapePoint {
            p: self.center + w * self.radius,
            n,
            front: n,
            p_error: self.p_error(),
            primitive: 0,
        }
    }

    /// A direction uniform in the subtended cone, turned into the point it first meets on
    /// the sphere. The point is placed by its angle α at the centre rather than by a ray
    /// intersection: with k = d/r = 1/sin θ_max, the law of sines in the triangle
    /// (r, centre, p) gives cos α = k sin²θ + cos θ √(1 − k² sin²θ). Near the silhouette
    /// the root cancels (k² sin²θ → 1), so this runs in f64: in f32 a far sphere's sampled
    /// point could land ~10⁻⁴ rad past the silhouette, on the hidden side.
    fn sample_cone(&self, r: Vec3, u: Vec2) -> Option<ShapeSample> {
        let center = self.center.as_dvec3();
        let radius = self.radius as f64;
        let axis_v = r.as_dvec3() - center;
        let d2 = axis_v.length_squared();
        let d = d2.sqrt();
        let axis = axis_v / d;
        let sin2_max = (radius * radius / d2).min(1.0);
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        let one_minus_cos_max = sin2_max / (1.0 + cos_max);
        let one_minus_cos = u.x as f64 * one_minus_cos_max;
        let sin2 = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0);
        let cos = 1.0 - one_minus_cos;
        let k = d / radius;
        let cos_alpha = (k * sin2 + cos * (1.0 - k * k * sin2).max(0.0).sqrt()).clamp(-1.0, 1.0);
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        // The azimuth in f32 (`sin_cos_turns`, within 2·10⁻⁷, the same bits in lanes).
        let (sin_phi, cos_phi) = warp::sin_cos_turns(2.0 * PI * u.y);
        let frame = Frame::from_normal(axis.as_vec3());
        let (s, t) = (frame.s.as_dvec3(), frame.t.as_dvec3());
        let outward = (s * (sin_alpha * cos_phi as f64)
            + t * (sin_alpha * sin_phi as f64)
            + axis * cos_alpha)
            .normalize();
        let p = (center + outward * radius).as_vec3();
        let n = self.normal_at(outward.as_vec3());
        let dist2 = (p - r).length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return None;
        }
        let pdf_solid_angle = self.cone_pdf(r);
        let cos_light = n.dot(r - p).abs() / dist2.sqrt();
        Some(ShapeSample {
            point: ShapePoint {
                p,
                n,
                front: n,
                p_error: self.p_error(),
                primitive: 0,
            },
            pdf_solid_angle,
            pdf_area: pdf_solid_angle * cos_light / dist2,
        })
    }
}

/// An analytic disk: the unit disk of the local xy plane under an affine `to_world`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskSampler {
    to_world: DMat4,
    /// Unit front normal.
    pub n: Vec3,
    area: f32,
}

impl DiskSampler {
    /// The same normal as the ray caster: local +z through the inverse transpose (in f64),
    /// negated by `flip_normals`. The area is π |M x̂ × M ŷ|.
    pub fn new(to_world: &Transform, flip_normals: bool) -> Result<DiskSampler, String> {
        let m: Mat4 = to_world.matrix;
        let m64 = m.as_dmat4();
        let det = m64.determinant();
        if !(m.is_finite() && det.is_finite() && det != 0.0) {
            return Err("the emitting disk's to_world is singular or not finite".to_string());
        }
        let inv = m64.inverse();
        let n = DVec3::new(inv.x_axis.z, inv.y_axis.z, inv.z_axis.z);
        let n = (n / n.length()).as_vec3().normalize();
        let area =
            std::f64::consts::PI * m64.x_axis.truncate().cross(m64.y_axis.truncate()).length();
        if !(n.is_finite() && area > 0.0 && area.is_finite()) {
            return Err("the emitting disk has no usable area or normal".to_string());
        }
        Ok(DiskSampler {
            to_world: m64,
            n: if flip_normals { -n } else { n },
            area: area as f32,
        })
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    fn sample_area(&self, u: Vec2) -> ShapePoint {
        let q = warp::square_to_disk_concentric(u);
        let p = self
            .to_world
            .transform_point3(DVec3::new(q.x as f64, q.y as f64, 0.0))
            .as_vec3();
        ShapePoint {
            p,
            n: self.n,
            front: self.n,
            // Transformed in f64 and rounded once to f32.
            p_error: p.abs() * gamma(2),
            primitive: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_points_lie_on_the_sphere_and_face_the_reference() {
        for (c, radius, r) in [
            (Vec3::new(0.0, 0.0, 0.0), 1.0, Vec3::new(0.0, 0.0, 3.0)),
            (
                Vec3::new(10.0, -3.0, 2.0),
                0.01,
                Vec3::new(-90.0, 40.0, 7.0),
            ),
            (
                Vec3::new(0.0, 0.0, 0.0),
                1.0,
                Vec3::new(0.0, 1.0 + 1e-4, 0.0),
            ),
        ] {
            let s = SphereSampler::new(c, radius, false).unwrap();
            for k in 0..256 {
                let u = Vec2::new((k as f32 + 0.5) / 256.0, (k as f32 * 0.618).fract());
                let smp = s.sample_cone(r, u).unwrap();
                let on = ((smp.point.p - c).length() - radius).abs();
                assert!(on <= 1e-5 * (radius + c.length()), "{on}");
                assert!(smp.point.n.dot(r - smp.point.p) >= -1e-4 * radius);
            }
        }
    }

    #[test]
    fn disk_area_of_a_scaled_disk() {
        let t = Transform::new(Mat4::from_scale(Vec3::new(2.0, 3.0, 5.0))).unwrap();
        let d = DiskSampler::new(&t, false).unwrap();
        assert!((d.area() - 6.0 * PI).abs() < 1e-4);
        assert_eq!(d.n, Vec3::Z);
        let flipped = DiskSampler::new(&t, true).unwrap();
        assert_eq!(flipped.n, -Vec3::Z);
    }

    #[test]
    fn degenerate_meshes_are_refused() {
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            indices: vec![[0, 1, 2], [0, 1, 7]],
            ..TriangleMesh::default()
        };
        assert!(MeshSampler::new(&mesh).is_err());
    }
}
