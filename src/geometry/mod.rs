//! Ray casting: all triangles in one BVH (obvhs), analytic shapes beside it.
//!
//! Queries on `Geometry`: `closest_hit` (the kernel: which surface, how far),
//! `interaction` (its surface data), `intersect` (both), `intersect_stream` (`intersect`
//! for a slice of rays) and `occluded` (any hit, for shadow rays).
//!
//! - `bvh.rs`: the compressed 8-wide BVH over every triangle of every mesh, and its
//!   conservative traversal (closest hit and any hit).
//! - `bvh/stream.rs`: closest hits for a slice of rays with several traversals in flight
//!   (`Geometry::intersect_stream`), for scenes too large for the cache.
//! - `cwbvh.rs`: collapsing obvhs's binary BVH into the 8-wide one (compressed boxes).
//! - `wide_node.rs`: the node traversal reads, its boxes decoded to f32, and its ray test.
//! - `flat.rs`: small scenes answered without the tree, sixteen triangles per test.
//! - `packet.rs`: sixteen rays at a time on those small scenes (and on trees of at most
//!   `PACKET_LIMIT` triangles when enough lanes are active), one triangle per test.
//! - `triangle.rs`: the watertight ray/triangle test and the hit point's error bound.
//! - `sphere.rs`, `disk.rs`: analytic shapes, tested one by one in f64.
//! - `offset.rs`: error bounds and robust origins for rays leaving a surface.
//! - `procedural.rs`: meshes generated in code for tests and benchmarks.
//!
//! Conventions (Mitsuba 3's): the geometric normal `ng` is the front side of the surface:
//! counter-clockwise winding for triangles (mesh `flip_normals` is already applied by the
//! loader), outward for spheres, local +z for disks, negated by `flip_normals` for the
//! analytic shapes. The shading normal `ns` is the normalised barycentric interpolation of
//! the mesh's vertex normals, kept as interpolated even when it lies on the other side of
//! `ng` (Mitsuba does not flip it either; BSDFs and the adjoint correction see both), or
//! `ng` when the mesh has none.
//!
//! Rays leaving a surface start from `SurfaceInteraction::spawn_ray*`, which offset the
//! origin off the surface by the hit point's error bound: no epsilon anywhere, at any scene
//! scale (tests/geometry.rs checks scales 1 to 1e5 and scenes translated far from the
//! origin). Query cost is dominated by memory latency on large scenes; the BVH, the
//! triangle records and the per-triangle vertex attributes are all stored in leaf order.

pub mod bvh;
pub mod cwbvh;
pub mod disk;
pub mod flat;
pub mod offset;
pub mod packet;
mod packet_boxes;
pub mod procedural;
pub mod sphere;
pub mod triangle;
pub mod wide_node;

use glam::{Vec2, Vec3};

use crate::math::Frame;
use crate::scene::{ShapeDesc, ShapeGeometry, TriangleMesh};
use rayon::prelude::*;

use bvh::{TraversalRay, TriangleBvh, TriangleSource};
use disk::Disk;
use offset::offset_ray_origin;
use sphere::Sphere;
use triangle::TriangleHit;

/// A ray segment: points o + t·d for t in (0, t_max). Origins are already offset off
/// surfaces by `SurfaceInteraction::spawn_ray*`, so no epsilon is needed at t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    /// Direction; need not be unit length (t is in units of |d|).
    pub d: Vec3,
    pub t_max: f32,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// How much shorter than the full segment a ray aimed at a point stops (relative to the
/// segment): `spawn_ray_to*` rays have t_max = 1 − SHADOW_EPSILON, so a surface through the
/// target point itself is not reported as an occluder.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// What a closest-hit query returns about the surface it hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// Hit position.
    pub p: Vec3,
    /// Conservative absolute error bound on each coordinate of `p`: the exact surface point
    /// lies in the box p ± p_error.
    pub p_error: Vec3,
    /// Ray parameter of the hit (in units of the query ray's `d`).
    pub t: f32,
    /// Geometric normal (unit), on the shape's front side (after `flip_normals`).
    pub ng: Vec3,
    /// Shading normal (unit): the interpolated vertex normal as it is (possibly on the other
    /// side of `ng`, as in Mitsuba), or `ng` when there are no vertex normals.
    pub ns: Vec3,
    /// Mesh uvs interpolated, or the barycentrics (b1, b2) when the mesh has none; Mitsuba's
    /// spherical (φ/2π, θ/π) on spheres and polar (r, φ/2π) on disks.
    pub uv: Vec2,
    /// Index of the shape in `SceneDescription::shapes`.
    pub shape: u32,
    /// Triangle index within the shape (0 for analytic shapes).
    pub primitive: u32,
}

impl SurfaceInteraction {
    /// The shading frame around `ns` (`Frame::from_normal(ns)`), built on demand: a query
    /// that only needs the hit (a shadow test, a photon's first bounce) does not pay for it.
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.ns)
    }

    /// A ray leaving the surface in direction `d`, origin offset to the side `d` points to.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(offset_ray_origin(self.p, self.p_error, self.ng, d), d)
    }

    /// A ray from this surface towards point `target`, stopping just short of it:
    /// d = target − origin, t_max = 1 − SHADOW_EPSILON.
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let o = offset_ray_origin(self.p, self.p_error, self.ng, target - self.p);
        Ray {
            o,
            d: target - o,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }

    /// A ray from this surface towards a point on another surface, both ends offset off
    /// their surfaces (the robust choice for connecting two surface vertices).
    pub fn spawn_ray_to_interaction(&self, other: &SurfaceInteraction) -> Ray {
        self.spawn_ray_to_surface(other.p, other.p_error, other.ng)
    }

    /// A ray from this surface towards `target` on another surface (error box
    /// `target ± target_error`, unit geometric normal `target_n`), both ends offset off their
    /// surfaces. Without the target's offset, a point sampled on a light far from the origin
    /// can lie a rounding error behind the light's plane, and a grazing shadow ray then hits
    /// the light itself before `t_max` (1.5% of a direct-lit image lost at y + 10⁴).
    #[inline]
    pub fn spawn_ray_to_surface(&self, target: Vec3, target_error: Vec3, target_n: Vec3) -> Ray {
        let o = offset_ray_origin(self.p, self.p_error, self.ng, target - self.p);
        let target = offset_ray_origin(target, target_error, target_n, o - target);
        Ray {
            o,
            d: target - o,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Bounds3 {
    pub const EMPTY: Bounds3 = Bounds3 {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    pub fn union(&self, other: &Bounds3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn with_point(&self, p: Vec3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    /// A sphere containing the box: (centre, radius); radius 0 for an empty box.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        if self.is_empty() {
            return (Vec3::ZERO, 0.0);
        }
        (self.center(), self.diagonal().length() * 0.5)
    }
}

/// The closest hit found by traversal (before computing surface data).
#[derive(Clone, Copy)]
enum Hit {
    Triangle {
        record: u32,
        hit: TriangleHit,
    },
    Sphere {
        index: usize,
        t: f64,
    },
    Disk {
        index: usize,
        t: f64,
        local: [f64; 2],
    },
}

/// Surface data at a hit on an analytic shape (sphere or disk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyticHit {
    pub p: Vec3,
    pub p_error: Vec3,
    /// Unit normal: outward on spheres, the local +z on disks; negated by `flip_normals`.
    pub n: Vec3,
    pub uv: Vec2,
}

/// The interaction at analytic hit `h`, the surface data of `found`. Analytic shapes have
/// no separate shading normal.
#[inline(always)]
fn analytic_interaction(h: AnalyticHit, found: &ClosestHit) -> SurfaceInteraction {
    interaction(h.p, h.p_error, found.t, h.n, h.n, h.uv, found.shape, 0)
}

/// The closest hit of a ray as the kernel finds it (`Geometry::closest_hit`): the distance
/// and the surface, plus what `Geometry::interaction` needs to compute its surface data.
#[derive(Clone, Copy)]
pub struct ClosestHit {
    /// Ray parameter of the hit (in units of the query ray's `d`), as in `SurfaceInteraction`.
    pub t: f32,
    /// Index of the shape in `SceneDescription::shapes`.
    pub shape: u32,
    /// Triangle index within the shape (0 for analytic shapes).
    pub primitive: u32,
    hit: Hit,
    ray: ScaledRay,
}

/// The query ray with its direction scaled by a power of two so that its largest
/// component lies in [1, 2): exactly the same ray (the scaling is exact), with slab
/// reciprocals that cannot overflow whatever |d| the caller used. Distances t_s along it
/// convert back exactly: t = t_s / scale = t_s · inv_scale.
#[derive(Clone, Copy)]
struct ScaledRay {
    o: Vec3,
    d: Vec3,
    scale: f32,
    /// 1 / scale (a power of two too).
    inv_scale: f32,
    t_max: f32,
}

impl ScaledRay {
    /// None for rays that cannot hit anything (zero or non-finite direction, non-finite
    /// origin, t_max ≤ 0 or NaN).
    fn new(ray: &Ray) -> Option<ScaledRay> {
        let m = ray.d.abs().max_element();
        if !(m > 0.0 && m.is_finite() && ray.o.is_finite() && ray.t_max > 0.0) {
            return None;
        }
        // 2^e for the binary exponent e of m (clamped so that 2^±e are normal f32).
        let e = ((m.to_bits() >> 23) & 0xff) as i32 - 127;
        let e = e.clamp(-126, 126);
        let scale = f32::from_bits(((127 + e) as u32) << 23);
        // d / 2^e as a product with 2^−e (exact, the same value, no division).
        let inv_scale = f32::from_bits(((127 - e) as u32) << 23);
        Some(ScaledRay {
            o: ray.o,
            d: ray.d * inv_scale,
            scale,
            inv_scale,
            t_max: ray.t_max * scale,
        })
    }
}

/// The acceleration structure over all shapes of a scene.
pub struct Geometry {
    bvh: TriangleBvh,
    spheres: Vec<Sphere>,
    disks: Vec<Disk>,
    bounds: Bounds3,
    triangle_count: usize,
    skipped_shapes: usize,
    skipped_triangles: usize,
}

impl Geometry {
    /// Builds the BVH over all mesh triangles and collects the analytic shapes. Triangles
    /// that cannot be intersected (index out of range, non-finite vertex, zero area) and
    /// analytic shapes with invalid parameters are skipped (counted, see `skipped()`):
    /// the scene loader reports such input; here it must simply not break the tracer.
    /// Analytic shapes compute (u, v) at their hits only where `needs_uv(shape)` (a
    /// textured BSDF reads them); elsewhere their hits carry (0, 0), which saves two
    /// inverse trigonometric calls a hit (triangles interpolate theirs, at no such cost).
    pub fn keep_uv_only_for(&mut self, needs_uv: impl Fn(u32) -> bool) {
        for s in &mut self.spheres {
            s.uv = needs_uv(s.shape);
        }
        for d in &mut self.disks {
            d.uv = needs_uv(d.shape);
        }
    }

    pub fn build(shapes: &[ShapeDesc]) -> Geometry {
        let mut ids: Vec<[u32; 2]> = Vec::new();
        let mut spheres = Vec::new();
        let mut disks = Vec::new();
        let mut bounds = Bounds3::EMPTY;
        let mut skipped_shapes = 0;
        let mut skipped_triangles = 0;
        for (si, shape) in shapes.iter().enumerate() {
            let si = si as u32;
            match &shape.geometry {
                ShapeGeometry::Mesh(mesh) => {
                    let before = ids.len();
                    ids.par_extend(mesh.indices.par_iter().enumerate().filter_map(|(pi, idx)| {
                        triangle_is_usable(mesh, idx).then_some([si, pi as u32])
                    }));
                    skipped_triangles += mesh.indices.len() - (ids.len() - before);
                }
                ShapeGeometry::Sphere { center, radius } => {
                    let s = Sphere {
                        center: *center,
                        radius: *radius,
                        flip_normals: shape.flip_normals,
                        shape: si,
                        uv: true,
                    };
                    if s.is_valid() {
                        let (lo, hi) = s.bounds();
                        bounds = bounds.with_point(lo).with_point(hi);
                        spheres.push(s);
                    } else {
                        skipped_shapes += 1;
                    }
                }
                ShapeGeometry::Disk { to_world } => {
                    match Disk::new(to_world, shape.flip_normals, si) {
                        Some(d) => {
                            let (lo, hi) = d.bounds();
                            bounds = bounds.with_point(lo).with_point(hi);
                            disks.push(d);
                        }
                        None => skipped_shapes += 1,
                    }
                }
            }
        }
        let bvh = TriangleBvh::build(&MeshSource::new(shapes, &ids));
        if !ids.is_empty() {
            let (lo, hi) = bvh.bounds();
            bounds = bounds.with_point(lo).with_point(hi);
        }
        Geometry {
            bvh,
            spheres,
            disks,
            bounds,
            triangle_count: ids.len(),
            skipped_shapes,
            skipped_triangles,
        }
    }

    /// The scene's bounding box (empty when there is nothing to hit).
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Number of triangles in the BVH.
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// (analytic shapes, triangles) left out by `build` because they cannot be hit.
    pub fn skipped(&self) -> (usize, usize) {
        (self.skipped_shapes, self.skipped_triangles)
    }

    /// Closest hit along the ray, if any, with t < ray.t_max, with its surface data:
    /// `closest_hit` followed by `interaction`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        self.closest_hit(ray).map(|h| self.interaction(&h))
    }

    /// The ray-casting kernel alone: which surface the ray hits first (t < ray.t_max) and
    /// where along the ray, without the surface data. For a query that needs only the
    /// distance or the shape; `interaction` completes it.
    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<ClosestHit> {
        if self.bvh.is_flat() {
            self.closest_hit_flat(ray)
        } else {
            self.closest_hit_in::<false>(ray)
        }
    }

    /// `closest_hit` on a scene small enough to skip the tree (`flat.rs`). Out of line: with
    /// the flat test inlined beside the tree's traversal, the tree's incoherent closest hits
    /// ran 6% slower (`cargo bench --bench rays`); with this call beside it, 2.5% (four
    /// alternating runs each), while `pt` on the Cornell box keeps a 6% gain.
    #[inline(never)]
    fn closest_hit_flat(&self, ray: &Ray) -> Option<ClosestHit> {
        self.closest_hit_in::<true>(ray)
    }

    /// `closest_hit` with the triangles tested without the tree (`FLAT`) or through it.
    #[inline(always)]
    fn closest_hit_in<const FLAT: bool>(&self, ray: &Ray) -> Option<ClosestHit> {
        // Written out here: the same steps through a helper taking `&ScaledRay` made the
        // tree's incoherent closest hits 16% slower (`cargo bench --bench rays`, 100k).
        let r = ScaledRay::new(ray)?;
        let (mut hit, t_max) = self.closest_analytic(&r);
        if let Some((record, h)) = self
            .bvh
            .closest_in::<FLAT>(&TraversalRay::new(r.o, r.d), t_max)
        {
            hit = Some(Hit::Triangle { record, hit: h });
        }
        Some(self.found(hit?, r))
    }

    /// The `ClosestHit` of traversal result `hit` along `r`: its distance in the query ray's
    /// units and its shape and triangle ids, computed once here.
    #[inline(always)]
    fn found(&self, hit: Hit, r: ScaledRay) -> ClosestHit {
        let (t, [shape, primitive]) = match hit {
            Hit::Triangle { record, hit } => (hit.t * r.inv_scale, self.bvh.record(record).ids()),
            Hit::Sphere { index, t } => {
                ((t / r.scale as f64) as f32, [self.spheres[index].shape, 0])
            }
            Hit::Disk { index, t, .. } => {
                ((t / r.scale as f64) as f32, [self.disks[index].shape, 0])
            }
        };
        ClosestHit {
            t,
            shape,
            primitive,
            hit,
            ray: r,
        }
    }

    /// The surface data of a hit that `closest_hit` found (the same as `intersect` returns).
    #[inline]
    pub fn interaction(&self, hit: &ClosestHit) -> SurfaceInteraction {
        let r = &hit.ray;
        match hit.hit {
            Hit::Triangle { record, hit: h } => self.triangle_interaction(record, &h, hit),
            Hit::Sphere { index, t } => {
                let h = self.spheres[index].hit(r.o, r.d, t);
                analytic_interaction(h, hit)
            }
            Hit::Disk { index, local, .. } => {
                analytic_interaction(self.disks[index].hit(local), hit)
            }
        }
    }

    /// The (u, v) that `interaction(hit)` reports, without the rest of the surface data (for
    /// a texture lookup).
    pub fn uv(&self, hit: &ClosestHit) -> Vec2 {
        let r = &hit.ray;
        match hit.hit {
            Hit::Triangle { record, hit: h } => self.triangle_uv(record, h.barycentrics()),
            Hit::Sphere { index, t } => self.spheres[index].hit(r.o, r.d, t).uv,
            Hit::Disk { index, local, .. } => self.disks[index].hit(local).uv,
        }
    }

    /// `out[i] = self.intersect(&rays[i])` for every ray, with several BVH traversals in
    /// flight (`bvh/stream.rs`): the same results, faster where the scene does not fit in the
    /// cache and each node read waits on memory.
    pub fn intersect_stream(&self, rays: &[Ray], out: &mut Vec<Option<SurfaceInteraction>>) {
        out.clear();
        out.resize(rays.len(), None);
        let mut queued = Vec::with_capacity(rays.len());
        let mut traversal = Vec::with_capacity(rays.len());
        let mut t_max = Vec::with_capacity(rays.len());
        for (i, ray) in rays.iter().enumerate() {
            let Some(r) = ScaledRay::new(ray) else {
                continue;
            };
            let (hit, t) = self.closest_analytic(&r);
            traversal.push(TraversalRay::new(r.o, r.d));
            t_max.push(t);
            queued.push((i, r, hit));
        }
        self.bvh.closest_stream(&traversal, &t_max, |k, h| {
            if let Some((record, h)) = h {
                queued[k].2 = Some(Hit::Triangle { record, hit: h });
            }
        });
        for (i, r, hit) in queued {
            if let Some(h) = hit {
                out[i] = Some(self.interaction(&self.found(h, r)));
            }
        }
    }

    /// The closest sphere or disk hit and the segment left for the triangles: t_max in the
    /// scaled ray's units, shortened to the analytic hit if there is one.
    #[inline(always)]
    fn closest_analytic(&self, r: &ScaledRay) -> (Option<Hit>, f32) {
        let mut t_max64 = r.t_max as f64;
        let mut hit = None;
        for (index, s) in self.spheres.iter().enumerate() {
            if let Some(t) = s.intersect(r.o, r.d, t_max64) {
                t_max64 = t;
                hit = Some(Hit::Sphere { index, t });
            }
        }
        for (index, d) in self.disks.iter().enumerate() {
            if let Some((t, local)) = d.intersect(r.o, r.d, t_max64) {
                t_max64 = t;
                hit = Some(Hit::Disk { index, t, local });
            }
        }
        let t_max = if hit.is_some() {
            t_max64 as f32
        } else {
            r.t_max
        };
        (hit, t_max)
    }

    /// True when anything lies on the ray with t < ray.t_max (any-hit shadow query).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.bvh.is_flat() {
            self.occluded_flat(ray)
        } else {
            self.occluded_in::<false>(ray)
        }
    }

    /// `occluded` on a scene small enough to skip the tree, out of line as `closest_hit_flat`.
    #[inline(never)]
    fn occluded_flat(&self, ray: &Ray) -> bool {
        self.occluded_in::<true>(ray)
    }

    /// `occluded` with the triangles tested without the tree (`FLAT`) or through it.
    #[inline(always)]
    fn occluded_in<const FLAT: bool>(&self, ray: &Ray) -> bool {
        let Some(r) = ScaledRay::new(ray) else {
            return false;
        };
        let t_max64 = r.t_max as f64;
        if self
            .spheres
            .iter()
            .any(|s| s.intersect(r.o, r.d, t_max64).is_some())
            || self
                .disks
                .iter()
                .any(|d| d.intersect(r.o, r.d, t_max64).is_some())
        {
            return true;
        }
        self.bvh
            .any_in::<FLAT>(&TraversalRay::new(r.o, r.d), r.t_max)
    }

    /// The (u, v) of barycentrics `b` on record `record`: its vertex uvs interpolated, or
    /// (b1, b2) where its mesh has none.
    #[inline(always)]
    fn triangle_uv(&self, record: u32, b: [f32; 3]) -> Vec2 {
        self.bvh
            .uvs(record)
            .map(|uv| uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2])
            .unwrap_or(Vec2::new(b[1], b[2]))
    }

    #[inline(always)]
    fn triangle_interaction(
        &self,
        record: u32,
        h: &TriangleHit,
        found: &ClosestHit,
    ) -> SurfaceInteraction {
        let rec = self.bvh.record(record);
        let v = [rec.vertex(0), rec.vertex(1), rec.vertex(2)];
        let b = h.barycentrics();
        let (p, p_error) = triangle::hit_point(v, b);
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let ns = self
            .bvh
            .normals(record)
            .map(|n| (n[0] * b[0] + n[1] * b[1] + n[2] * b[2]).normalize_or_zero())
            .filter(|n| *n != Vec3::ZERO)
            .unwrap_or(ng);
        let uv = self.triangle_uv(record, b);
        interaction(
            p,
            p_error,
            found.t,
            ng,
            ns,
            uv,
            found.shape,
            found.primitive,
        )
    }
}

/// Whether a mesh triangle can be intersected: indices in range, finite vertices, and a
/// normal that normalises (non-zero area).
fn triangle_is_usable(mesh: &TriangleMesh, idx: &[u32; 3]) -> bool {
    if idx.iter().any(|&i| i as usize >= mesh.positions.len()) {
        return false;
    }
    let v = idx.map(|i| mesh.positions[i as usize]);
    v.iter().all(|p| p.is_finite()) && (v[1] - v[0]).cross(v[2] - v[0]).normalize().is_finite()
}

/// The scene's mesh triangles as the BVH builder reads them.
struct MeshSource<'a> {
    /// Per shape: the mesh, with its normals and uvs when they have one entry per vertex.
    meshes: Vec<Option<MeshView<'a>>>,
    ids: &'a [[u32; 2]],
    has_normals: bool,
    has_uvs: bool,
}

struct MeshView<'a> {
    mesh: &'a TriangleMesh,
    normals: Option<&'a [Vec3]>,
    uvs: Option<&'a [Vec2]>,
}

impl<'a> MeshSource<'a> {
    fn new(shapes: &'a [ShapeDesc], ids: &'a [[u32; 2]]) -> Self {
        let meshes: Vec<Option<MeshView>> = shapes
            .iter()
            .map(|s| match &s.geometry {
                ShapeGeometry::Mesh(mesh) => {
                    let n = mesh.positions.len();
                    Some(MeshView {
                        mesh,
                        normals: mesh.normals.as_deref().filter(|v| v.len() == n),
                        uvs: mesh.uvs.as_deref().filter(|v| v.len() == n),
                    })
                }
                _ => None,
            })
            .collect();
        let has_normals = meshes.iter().flatten().any(|m| m.normals.is_some());
        let has_uvs = meshes.iter().flatten().any(|m| m.uvs.is_some());
        MeshSource {
            meshes,
            ids,
            has_normals,
            has_uvs,
        }
    }

    /// The mesh and vertex indices of triangle i.
    fn triangle(&self, i: usize) -> (&MeshView<'a>, [usize; 3]) {
        let [shape, primitive] = self.ids[i];
        let view = self.meshes[shape as usize]
            .as_ref()
            .expect("triangle ids name mesh shapes");
        (
            view,
            view.mesh.indices[primitive as usize].map(|j| j as usize),
        )
    }
}

impl TriangleSource for MeshSource<'_> {
    fn triangle_count(&self) -> usize {
        self.ids.len()
    }

    fn vertices(&self, i: usize) -> [Vec3; 3] {
        let (view, idx) = self.triangle(i);
        idx.map(|j| view.mesh.positions[j])
    }

    fn ids(&self, i: usize) -> [u32; 2] {
        self.ids[i]
    }

    fn has_normals(&self) -> bool {
        self.has_normals
    }

    fn normals(&self, i: usize) -> Option<[Vec3; 3]> {
        let (view, idx) = self.triangle(i);
        view.normals.map(|n| idx.map(|j| n[j]))
    }

    fn has_uvs(&self) -> bool {
        self.has_uvs
    }

    fn uvs(&self, i: usize) -> Option<[Vec2; 3]> {
        let (view, idx) = self.triangle(i);
        view.uvs.map(|uv| idx.map(|j| uv[j]))
    }
}

#[allow(clippy::too_many_arguments)]
fn interaction(
    p: Vec3,
    p_error: Vec3,
    t: f32,
    ng: Vec3,
    ns: Vec3,
    uv: Vec2,
    shape: u32,
    primitive: u32,
) -> SurfaceInteraction {
    SurfaceInteraction {
        p,
        p_error,
        t,
        ng,
        ns,
        uv,
        shape,
        primitive,
    }
}
