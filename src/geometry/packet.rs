//! Sixteen rays at once on a small scene: each triangle tested against all sixteen, one
//! ray per lane (`Geometry::closest_hits_lanes`, `Geometry::occluded_lanes`).
//!
//! `flat.rs` tests one ray against sixteen triangles; here the lanes hold rays, so the
//! watertight test's per-ray axis permutation becomes a per-lane one (a permute of the
//! triangle's twelve coordinates), and each lane keeps its own closest hit without a
//! horizontal search. The arithmetic is the per-triangle test's (`triangle.rs`), operation
//! for operation, so each lane reports exactly what `Geometry::closest_hit` and `occluded`
//! report for its ray: a lane whose edge functions are all non-zero and whose T exceeds its
//! rounding error bound is settled from its own values; any other candidate goes through
//! `triangle::intersect` itself. `tests/geometry.rs` compares both queries ray by ray.
//! Runs of four records share a box (`packet_boxes.rs`): lanes whose segment misses it skip
//! the run's four tests, and a run no lane meets costs one slab test instead of four.
//!
//! The analytic shapes of a small scene come first, as in the per-ray queries: spheres and
//! disks in f64 lanes (`Sphere::intersect_lanes`, `Disk::intersect_lanes`: the same
//! operations in the same order); the triangles are then tested within what is left of each segment.
//! Larger scenes are answered one lane at a time through the tree by the per-ray queries;
//! trees of at most `PACKET_LIMIT` triangles keep a packet too and use it when enough lanes
//! are active. The tree keeps the same triangle as the packet among hits at equal t (the
//! lowest record index, `bvh::replaces`), so either way gives the same bits.

use super::bvh::TraversalRay;
use super::offset::gamma;
use super::packet_boxes::{BoxRays, RUN, RunBoxes};
use super::sphere;
use super::triangle::{self, BoundArithmetic, TriangleHit, TriangleRay, TriangleRecord};
use super::{ClosestHit, Geometry, Hit, Ray, ScaledRay};
use crate::math::lanes::{F32x16, F64x8, LANES, Mask8, Mask16, U32x16, V3};

/// Trees of at most this many triangles keep a packet (`PacketTriangles`) beside the tree
/// for the sixteen-ray queries. A packet tests every triangle against all sixteen lanes,
/// whatever the lanes; the tree traces the active lanes one by one. Measured with `pt`
/// (full packets) on a rippled mesh of 54 to 396 triangles (`experiments/perf/water.xml`'s
/// scene, `docs/performance.md`): the packet is faster up to about 120 triangles, so a
/// traversal costs about as much as testing 120/16 ≈ 7 triangles in a packet, and
/// `Geometry::packet_pays` asks for enough active lanes by that rate.
pub const PACKET_LIMIT: usize = 112;

/// Sixteen rays: origins, directions (need not be unit length) and segment ends.
#[derive(Clone, Copy, Debug)]
pub struct RayLanes {
    pub o: V3<F32x16>,
    pub d: V3<F32x16>,
    pub t_max: F32x16,
}

impl RayLanes {
    /// Up to sixteen rays in lanes: lane k holds `ray(k)` for k < `n` where it is Some;
    /// with the mask of those lanes (others hold zeros).
    #[inline]
    pub fn from_rays(n: usize, mut ray: impl FnMut(usize) -> Option<Ray>) -> (RayLanes, Mask16) {
        let mut lanes = [[0.0f32; LANES]; 7];
        let mut m = Mask16::NONE;
        for k in 0..n.min(LANES) {
            if let Some(r) = ray(k) {
                for (a, v) in lanes
                    .iter_mut()
                    .zip([r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.t_max])
                {
                    a[k] = v;
                }
                m.set(k, true);
            }
        }
        let [ox, oy, oz, dx, dy, dz, t_max] = lanes.map(F32x16::from_array);
        let rays = RayLanes {
            o: V3::new(ox, oy, oz),
            d: V3::new(dx, dy, dz),
            t_max,
        };
        (rays, m)
    }

    /// Lane `i` as a `Ray`.
    pub fn lane(&self, i: usize) -> Ray {
        let g = |v: F32x16| v.to_array()[i];
        Ray {
            o: glam::Vec3::new(g(self.o.x), g(self.o.y), g(self.o.z)),
            d: glam::Vec3::new(g(self.d.x), g(self.d.y), g(self.d.z)),
            t_max: g(self.t_max),
        }
    }
}

impl BoundArithmetic for F32x16 {
    #[inline(always)]
    fn splat(v: f32) -> F32x16 {
        F32x16::splat(v)
    }
}

/// One triangle record as one vector: coordinate k of vertex j in lane 4k + j (lanes 3, 7,
/// 11 hold the record's identity, lanes 12–15 are unused).
type PacketTriangle = [f32; LANES];

/// True where each triangle is also kept as one vector per vertex (its x, y, z in lanes 0–2),
/// read by `F32x16::permute_low8`: with AVX2 (two registers per vector) a permutation within
/// the low eight lanes is one instruction per half, one across all sixteen four.
const BY_VERTEX: bool = cfg!(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
));

/// The records of a small scene, one vector each, for the sixteen-ray tests, and their
/// vertex normals for the surface data.
#[derive(Clone, Default)]
pub struct PacketTriangles {
    triangles: Vec<PacketTriangle>,
    /// With `BY_VERTEX`, per record: vertex j's coordinates in lanes 0–2 of vector j.
    by_vertex: Vec<[PacketTriangle; 3]>,
    /// Boxes around runs of records, tested before the records (`packet_boxes.rs`).
    runs: RunBoxes,
}

impl PacketTriangles {
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    pub fn new(records: &[TriangleRecord]) -> PacketTriangles {
        let triangles = records
            .iter()
            .map(|r| {
                let mut v = [0.0f32; LANES];
                for (k, row) in r.rows.iter().enumerate() {
                    v[4 * k..4 * k + 4].copy_from_slice(row);
                }
                v
            })
            .collect();
        let by_vertex = if BY_VERTEX {
            records
                .iter()
                .map(|r| {
                    std::array::from_fn(|j| {
                        let mut v = [0.0f32; LANES];
                        for (k, row) in r.rows.iter().enumerate() {
                            v[k] = row[j];
                        }
                        v
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        let runs = RunBoxes::new(records.len(), |i| {
            let rows = &records[i].rows;
            std::array::from_fn(|j| [rows[0][j], rows[1][j], rows[2][j]])
        });
        PacketTriangles {
            triangles,
            by_vertex,
            runs,
        }
    }

    /// Rays with origins `o` and directions `d` for the run boxes.
    #[inline(always)]
    fn box_rays(&self, o: &V3<F32x16>, d: &V3<F32x16>) -> BoxRays {
        BoxRays::new(&self.runs, o, d)
    }

    /// The records of run `run`, with their indices.
    #[inline(always)]
    fn run<'r>(
        &self,
        records: &'r [TriangleRecord],
        run: usize,
    ) -> impl Iterator<Item = (usize, &'r TriangleRecord)> {
        let first = run * RUN;
        let end = (first + RUN).min(self.triangles.len());
        (first..end).zip(&records[first..end])
    }
}

/// `ScaledRay::new` in lanes: `valid` where the ray can hit anything.
struct ScaledRayLanes {
    valid: Mask16,
    o: V3<F32x16>,
    d: V3<F32x16>,
    scale: F32x16,
    inv_scale: F32x16,
    t_max: F32x16,
}

impl ScaledRayLanes {
    #[inline(always)]
    fn new(r: &RayLanes) -> ScaledRayLanes {
        let a = r.d.abs();
        // `Vec3::max_element`.
        let m = a.x.max_gt(a.y).max_gt(a.z);
        let zero = F32x16::splat(0.0);
        let valid = m.gt(zero) & m.is_finite() & r.o.is_finite() & r.t_max.gt(zero);
        // The binary exponent of m clamped to [−126, 126], as its biased value in [1, 253].
        let biased = (m.to_bits().shr::<23>() & U32x16::splat(0xff))
            .max(U32x16::splat(1))
            .min(U32x16::splat(253));
        let scale = F32x16::from_bits(biased.shl::<23>());
        let inv_scale = F32x16::from_bits((U32x16::splat(254) - biased).shl::<23>());
        ScaledRayLanes {
            valid,
            o: r.o,
            d: r.d * inv_scale,
            scale,
            inv_scale,
            t_max: r.t_max * scale,
        }
    }

    /// Every lane's values, from which `ScaledRayArrays::get` makes the `ScaledRay` the
    /// per-ray query makes. (Not an array of `ScaledRay`s: the compiler writes such a
    /// transpose with scatter instructions, microcoded on Zen 4 and slower than the queries
    /// they feed.)
    #[inline(always)]
    fn lanes(&self) -> ScaledRayArrays {
        ScaledRayArrays(
            [
                self.o.x,
                self.o.y,
                self.o.z,
                self.d.x,
                self.d.y,
                self.d.z,
                self.scale,
                self.inv_scale,
                self.t_max,
            ]
            .map(F32x16::to_array),
        )
    }
}

/// `ScaledRayLanes` as arrays: o, d, scale, inv_scale, t_max.
struct ScaledRayArrays([[f32; LANES]; 9]);

impl ScaledRayArrays {
    /// Lane `i`'s `ScaledRay`.
    #[inline(always)]
    fn get(&self, i: usize) -> ScaledRay {
        let [ox, oy, oz, dx, dy, dz, scale, inv_scale, t_max] = &self.0;
        ScaledRay {
            o: glam::Vec3::new(ox[i], oy[i], oz[i]),
            d: glam::Vec3::new(dx[i], dy[i], dz[i]),
            scale: scale[i],
            inv_scale: inv_scale[i],
            t_max: t_max[i],
        }
    }
}

/// Component `k` (0, 1, 2 per lane) of `v`.
#[inline(always)]
fn pick(v: &V3<F32x16>, k: U32x16) -> F32x16 {
    F32x16::select(
        k.eq(U32x16::splat(0)),
        v.x,
        F32x16::select(k.eq(U32x16::splat(1)), v.y, v.z),
    )
}

/// Scaled rays widened to f64 (exactly) in two halves of eight lanes, for the analytic
/// shapes' tests.
struct WideRays {
    o: [(F64x8, F64x8); 3],
    d: [(F64x8, F64x8); 3],
    t_max: (F64x8, F64x8),
}

impl WideRays {
    #[inline(always)]
    fn new(r: &ScaledRayLanes) -> WideRays {
        WideRays {
            o: [r.o.x, r.o.y, r.o.z].map(F32x16::to_f64_halves),
            d: [r.d.x, r.d.y, r.d.z].map(F32x16::to_f64_halves),
            t_max: r.t_max.to_f64_halves(),
        }
    }

    /// The origins and directions of half `h` (lanes 8h to 8h + 7).
    #[inline(always)]
    fn half(&self, h: usize) -> ([F64x8; 3], [F64x8; 3]) {
        let pick = |v: &(F64x8, F64x8)| if h == 0 { v.0 } else { v.1 };
        (self.o.each_ref().map(pick), self.d.each_ref().map(pick))
    }
}

/// `TriangleRay::new` in lanes: the permutation as indices into a `PacketTriangle`, the
/// permuted origin and the shear.
struct TriangleRayLanes {
    /// For vertex j: the lanes of its kx, ky and kz coordinates.
    index: [[U32x16; 3]; 3],
    /// kx, ky and kz (the lanes of a vertex's coordinates in a `by_vertex` vector).
    axis: [U32x16; 3],
    ox: F32x16,
    oy: F32x16,
    oz: F32x16,
    sx: F32x16,
    sy: F32x16,
    sz: F32x16,
}

impl TriangleRayLanes {
    /// `d` must be non-zero and finite in the lanes used.
    #[inline(always)]
    fn new(o: &V3<F32x16>, d: &V3<F32x16>) -> TriangleRayLanes {
        let u = U32x16::splat;
        let a = d.abs();
        // kz = index of the largest |d| component (the first of equals).
        let z_largest = a.z.gt(a.x.max_gt(a.y));
        let kz = U32x16::select(z_largest, u(2), U32x16::select(a.y.gt(a.x), u(1), u(0)));
        let kx0 = U32x16::select(kz.eq(u(0)), u(1), U32x16::select(kz.eq(u(1)), u(2), u(0)));
        let ky0 = U32x16::select(kz.eq(u(0)), u(2), U32x16::select(kz.eq(u(1)), u(0), u(1)));
        // A negative d[kz] swaps x and y to keep the winding.
        let dz = pick(d, kz);
        let negative = dz.lt(F32x16::splat(0.0));
        let kx = U32x16::select(negative, ky0, kx0);
        let ky = U32x16::select(negative, kx0, ky0);
        let sz = F32x16::splat(1.0) / dz;
        let lanes_of = |k: U32x16| std::array::from_fn(|j| k.shl::<2>() + u(j as u32));
        let (ix, iy, iz): ([U32x16; 3], [U32x16; 3], [U32x16; 3]) =
            (lanes_of(kx), lanes_of(ky), lanes_of(kz));
        TriangleRayLanes {
            index: std::array::from_fn(|j| [ix[j], iy[j], iz[j]]),
            axis: [kx, ky, kz],
            ox: pick(o, kx),
            oy: pick(o, ky),
            oz: pick(o, kz),
            sx: pick(d, kx) * sz,
            sy: pick(d, ky) * sz,
            sz,
        }
    }
}

/// One triangle in the ray space of each lane: the sheared vertex coordinates and the
/// edge functions, exactly as `triangle::intersect_scalar` computes them.
struct Sheared {
    x: [F32x16; 3],
    y: [F32x16; 3],
    z: [F32x16; 3],
    e: [F32x16; 3],
}

/// `Sheared` for the triangle whose coordinate `coord(k, j)` (k = 0, 1, 2 for the lane's
/// kx, ky, kz axis; vertex j) each lane reads.
#[inline(always)]
fn shear(r: &TriangleRayLanes, coord: impl Fn(usize, usize) -> F32x16) -> Sheared {
    let vertex = |j: usize| {
        let z = coord(2, j) - r.oz;
        let x = (coord(0, j) - r.ox) - r.sx * z;
        let y = (coord(1, j) - r.oy) - r.sy * z;
        (x, y, z)
    };
    let (x0, y0, z0) = vertex(0);
    let (x1, y1, z1) = vertex(1);
    let (x2, y2, z2) = vertex(2);
    Sheared {
        e: [x2 * y1 - y2 * x1, x0 * y2 - y0 * x2, x1 * y0 - y1 * x0],
        x: [x0, x1, x2],
        y: [y0, y1, y2],
        z: [z0, z1, z2],
    }
}

impl Sheared {
    /// (e0 + e1) + e2, as the per-triangle test sums it.
    #[inline(always)]
    fn det(&self) -> F32x16 {
        (self.e[0] + self.e[1]) + self.e[2]
    }
}

/// What the lanes computed for one triangle (see `lane_tests`).
struct LaneTests {
    sheared: Sheared,
    /// T and det made positive (both negated where det < 0).
    t_num_p: F32x16,
    det_p: F32x16,
    /// Lanes that may pass the test within (0, t_max): the others certainly fail it.
    candidate: Mask16,
    /// Candidates without a zero edge function and with 0 < t < t_max: they pass unless
    /// T is within its rounding error bound of zero (`settled`).
    in_range: Mask16,
}

/// The watertight test of record `record` against the lanes of `m`, within (0, t_max) per
/// lane, up to the error bound of T (`settled`).
#[inline(always)]
fn lane_tests(
    triangles: &PacketTriangles,
    record: usize,
    r: &TriangleRayLanes,
    t_max: F32x16,
    m: Mask16,
) -> LaneTests {
    let sheared = if BY_VERTEX {
        let v = triangles.by_vertex[record]
            .each_ref()
            .map(|a| F32x16::from_array(*a));
        shear(r, |k, j| v[j].permute_low8(r.axis[k]))
    } else {
        let v = F32x16::from_array(triangles.triangles[record]);
        shear(r, |k, j| v.permute(r.index[j][k]))
    };
    let [e0, e1, e2] = sheared.e;
    let [z0, z1, z2] = sheared.z;
    let zero = F32x16::splat(0.0);
    // Edge functions of both signs: no hit. (A NaN among them may be read either way
    // here: such a lane has NaN in T and det, fails `in_range`, and cannot hit.)
    let lowest = e0.min_lt(e1).min_lt(e2);
    let highest = e0.max_gt(e1).max_gt(e2);
    let mixed = lowest.lt(zero) & highest.gt(zero);
    // No zero edge function. A product that underflows to zero only sends the lane to
    // `triangle::intersect`, which decides it exactly.
    let all_nonzero = ((e0 * e1) * e2).ne(zero);
    let det = sheared.det();
    let t_num = (e0 * (z0 * r.sz) + e1 * (z1 * r.sz)) + e2 * (z2 * r.sz);
    // t = T/det with both made positive, as `triangle::hit_from` (which flips for det < 0;
    // flipping by det's sign bit differs only for det = −0 or NaN, lanes that fail
    // `in_range` either way).
    let sign = det.to_bits() & U32x16::splat(0x8000_0000);
    let t_num_p = F32x16::from_bits(t_num.to_bits() ^ sign);
    let det_p = det.abs();
    let in_range = t_num_p.gt(zero) & t_num_p.le(triangle::cut_bound(t_max, det_p));
    let candidate = m & !mixed & (!all_nonzero | in_range);
    LaneTests {
        sheared,
        t_num_p,
        det_p,
        candidate,
        in_range: candidate & all_nonzero & in_range,
    }
}

impl LaneTests {
    /// The lanes of `m` (within `in_range`) whose T exceeds its rounding error bound: their
    /// t > 0 is certain, so they hit as the per-triangle test decides it without the f64
    /// sign test. The bound from the largest |x|, |y|, |z| and |e|, as that test computes it.
    #[inline(always)]
    fn settled(&self, m: Mask16, r: &TriangleRayLanes) -> Mask16 {
        let s = &self.sheared;
        let max3 = |v: &[F32x16; 3]| v[0].abs().max_gt(v[1].abs()).max_gt(v[2].abs());
        let bound = triangle::t_num_error_bound_in(
            max3(&s.x).max_gt(max3(&s.y)),
            max3(&s.z),
            max3(&s.e),
            r.sz.abs(),
        );
        m & bound.lt(self.t_num_p) & bound.lt(F32x16::splat(f32::INFINITY))
    }

    /// t = T/det (meaningful in `in_range` lanes).
    #[inline(always)]
    fn t(&self) -> F32x16 {
        self.t_num_p / self.det_p
    }
}

/// The closest hit of each lane: its t (in the scaled ray's units), record, edge functions
/// and det (lanes of `hit`).
#[derive(Clone, Copy)]
struct BestLanes {
    t: F32x16,
    record: U32x16,
    e: [F32x16; 3],
    det: F32x16,
    hit: Mask16,
}

/// The hits `triangle::intersect` decided during the scan (it may have recomputed their
/// edge functions in f64): kept aside, since the others' are recomputed at the end.
struct ScalarHits {
    lanes: Mask16,
    e: [[f32; 3]; LANES],
    det: [f32; LANES],
}

impl PacketTriangles {
    /// For each lane of `m`: the closest record with 0 < t < t_max, as the per-triangle test
    /// finds it scanning the records in order (the first of equal t). `tri_ray(i)` is lane
    /// i's ray for that test.
    #[allow(clippy::too_many_arguments)]
    fn closest(
        &self,
        records: &[TriangleRecord],
        r: &TriangleRayLanes,
        boxes: &BoxRays,
        tri_ray: impl Fn(usize) -> TriangleRay,
        t_max: F32x16,
        m: Mask16,
        best: &mut BestLanes,
    ) {
        let zero = F32x16::splat(0.0);
        *best = BestLanes {
            t: t_max,
            record: U32x16::splat(0),
            e: [zero; 3],
            det: zero,
            hit: Mask16::NONE,
        };
        let mut scalar = ScalarHits {
            lanes: Mask16::NONE,
            e: [[0.0; 3]; LANES],
            det: [0.0; LANES],
        };
        // One record per triangle, in the same order, skipping the runs whose box no lane
        // meets within its closest hit so far.
        for run in 0..self.runs.len() {
            let m = self.runs.hits(run, boxes, best.t, m);
            if m.none() {
                continue;
            }
            for (k, record) in self.run(records, run) {
                self.closest_step(k, record, r, &tri_ray, m, best, &mut scalar);
            }
        }
        self.edges_of_best(best, &scalar, r);
    }

    /// `closest`'s test of record `k` for the lanes of `m`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn closest_step(
        &self,
        k: usize,
        record: &TriangleRecord,
        r: &TriangleRayLanes,
        tri_ray: &impl Fn(usize) -> TriangleRay,
        m: Mask16,
        best: &mut BestLanes,
        scalar: &mut ScalarHits,
    ) {
        let lanes = lane_tests(self, k, r, best.t, m);
        if lanes.candidate.none() {
            return;
        }
        // Only a lane that would take this hit as its closest needs the error bound; a
        // farther one is rejected by the per-triangle test's final t < t_max anyway.
        let t = lanes.t();
        let closer = lanes.in_range & t.lt(best.t);
        let settled = if closer.any() {
            lanes.settled(closer, r)
        } else {
            Mask16::NONE
        };
        best.t = F32x16::select(settled, t, best.t);
        best.record = U32x16::select(settled, U32x16::splat(k as u32), best.record);
        best.hit |= settled;
        scalar.lanes &= !settled;
        for i in ((lanes.candidate & !lanes.in_range) | (closer & !settled)).lanes() {
            let t_max_i = best.t.to_array()[i];
            if let Some(h) = triangle::intersect(record, &tri_ray(i), t_max_i) {
                let m = Mask16(1 << i);
                best.t = F32x16::select(m, F32x16::splat(h.t), best.t);
                best.record = U32x16::select(m, U32x16::splat(k as u32), best.record);
                best.hit |= m;
                scalar.lanes |= m;
                (scalar.e[i], scalar.det[i]) = (h.e, h.det);
            }
        }
    }

    /// The edge functions and det of each lane's closest hit: recomputed from its record
    /// with the same arithmetic for hits settled in lanes, kept for the others.
    #[inline(always)]
    fn edges_of_best(&self, best: &mut BestLanes, scalar: &ScalarHits, r: &TriangleRayLanes) {
        let m = best.hit & !scalar.lanes;
        if m.any() {
            let table = self.triangles.as_flattened();
            let base = best.record.shl::<4>();
            let sheared = shear(r, |k, j| F32x16::gather(table, base + r.index[j][k], m));
            best.det = sheared.det();
            best.e = sheared.e;
        }
        for i in scalar.lanes.lanes() {
            let m = Mask16(1 << i);
            for (e, v) in best.e.iter_mut().zip(scalar.e[i]) {
                *e = F32x16::select(m, F32x16::splat(v), *e);
            }
            best.det = F32x16::select(m, F32x16::splat(scalar.det[i]), best.det);
        }
    }

    /// The lanes of `m` for which some record lies at 0 < t < t_max.
    fn any(
        &self,
        records: &[TriangleRecord],
        r: &TriangleRayLanes,
        boxes: &BoxRays,
        tri_ray: impl Fn(usize) -> TriangleRay,
        t_max: F32x16,
        m: Mask16,
    ) -> Mask16 {
        let mut found = Mask16::NONE;
        // Run by run, the records of the runs whose box an open lane meets.
        for run in 0..self.runs.len() {
            let open = m & !found;
            if open.none() {
                break;
            }
            let open = self.runs.hits(run, boxes, t_max, open);
            for (k, record) in self.run(records, run) {
                let open = open & !found;
                if open.none() {
                    break;
                }
                let lanes = lane_tests(self, k, r, t_max, open);
                if lanes.candidate.none() {
                    continue;
                }
                let settled = lanes.settled(lanes.in_range, r);
                found |= settled & lanes.t().lt(t_max);
                for i in (lanes.candidate & !settled).lanes() {
                    let t_max_i = t_max.to_array()[i];
                    if triangle::intersect(record, &tri_ray(i), t_max_i).is_some() {
                        found.set(i, true);
                    }
                }
            }
        }
        found
    }
}

/// The closest hits of sixteen rays, as `Geometry::closest_hits_lanes` fills them in.
pub struct ClosestLanes {
    /// Lanes whose ray hit something.
    pub hit: Mask16,
    /// The lanes whose closest hit is a triangle (`best.hit`), and that hit.
    best: BestLanes,
    /// Each lane's closest sphere or disk hit (taken where no triangle is closer,
    /// `best.hit` unset).
    analytic: [Option<Hit>; LANES],
}

impl Default for ClosestLanes {
    fn default() -> Self {
        let zero = F32x16::splat(0.0);
        ClosestLanes {
            hit: Mask16::NONE,
            best: BestLanes {
                t: zero,
                record: U32x16::splat(0),
                e: [zero; 3],
                det: zero,
                hit: Mask16::NONE,
            },
            analytic: [None; LANES],
        }
    }
}

impl ClosestLanes {
    /// Lane `i`'s hit as the per-ray query `closest_hit` returns it for lane `i` of `rays`
    /// (the rays these hits were found for).
    pub fn closest_hit(
        &self,
        geometry: &Geometry,
        rays: &RayLanes,
        i: usize,
    ) -> Option<ClosestHit> {
        if !self.hit.get(i) {
            return None;
        }
        let ray = ScaledRay::new(&rays.lane(i))?;
        if !self.best.hit.get(i) {
            return self.analytic[i].map(|h| geometry.found(h, ray));
        }
        let g = |v: F32x16| v.to_array()[i];
        let best = &self.best;
        let hit = TriangleHit {
            t: g(best.t),
            e: best.e.map(g),
            det: g(best.det),
        };
        let record = best.record.to_array()[i];
        Some(geometry.found(Hit::Triangle { record, hit }, ray))
    }
}

/// Surface data of sixteen hits, as `SurfaceInteraction` holds it (meaningful in the
/// lanes of `hit`): the parts a wavefront reads for every hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceLanes {
    pub hit: Mask16,
    pub p: V3<F32x16>,
    pub p_error: V3<F32x16>,
    pub ng: V3<F32x16>,
    pub ns: V3<F32x16>,
    pub shape: U32x16,
    pub primitive: U32x16,
}

impl SurfaceLanes {
    /// Takes the lanes of `m` from `other`.
    fn merge(&mut self, m: Mask16, other: &SurfaceLanes) {
        self.p = V3::select(m, other.p, self.p);
        self.p_error = V3::select(m, other.p_error, self.p_error);
        self.ng = V3::select(m, other.ng, self.ng);
        self.ns = V3::select(m, other.ns, self.ns);
        self.shape = U32x16::select(m, other.shape, self.shape);
        self.primitive = U32x16::select(m, other.primitive, self.primitive);
    }
}

impl Geometry {
    /// `closest_hit` for the rays of the lanes of `m`: the same answers, sixteen rays per
    /// triangle and sphere test on a small scene (`packet.rs`) and on a small tree when
    /// enough lanes are active (`packet_pays`), else one ray at a time through the tree.
    pub fn closest_hits_lanes(&self, rays: &RayLanes, m: Mask16, out: &mut ClosestLanes) {
        if !self.packet_pays(m) {
            self.closest_hits_one_by_one(rays, m, out);
            return;
        }
        let scaled = ScaledRayLanes::new(rays);
        let m = m & scaled.valid;
        // The analytic shapes first, then the triangles within what they left of each
        // segment (`closest_hit_in`).
        let (analytic, t_max) = self.closest_analytic_lanes(&scaled, m, &mut out.analytic);
        let tri = TriangleRayLanes::new(&scaled.o, &scaled.d);
        let tri_ray = |i: usize| {
            let s = scaled.lanes().get(i);
            TriangleRay::new(s.o, s.d)
        };
        let packet = self.bvh.packet();
        let boxes = packet.box_rays(&scaled.o, &scaled.d);
        packet.closest(
            self.bvh.records(),
            &tri,
            &boxes,
            tri_ray,
            t_max,
            m,
            &mut out.best,
        );
        out.hit = out.best.hit | analytic;
    }

    /// `closest_hits_lanes` through the tree, one ray at a time (`closest_hit`), each
    /// lane's hit written where the sixteen-ray test writes it (so that the surface data
    /// of triangle hits is computed in lanes all the same).
    fn closest_hits_one_by_one(&self, rays: &RayLanes, m: Mask16, out: &mut ClosestLanes) {
        let mut t = [0.0f32; LANES];
        let mut record = [0u32; LANES];
        let mut e = [[0.0f32; LANES]; 3];
        let mut det = [0.0f32; LANES];
        let mut triangles = Mask16::NONE;
        // `closest_hit_in`'s steps: the analytic shapes first (in lanes), then the tree
        // within what they left of each segment (one ray at a time).
        let scaled = ScaledRayLanes::new(rays);
        let m = m & scaled.valid;
        let (analytic, t_max) = self.closest_analytic_lanes(&scaled, m, &mut out.analytic);
        if !self.has_analytic_shapes() {
            out.analytic = [None; LANES];
        }
        let (t_max, scaled) = (t_max.to_array(), scaled.lanes());
        for i in m.lanes() {
            let s = &scaled.get(i);
            if let Some((id, hit)) = self
                .bvh
                .closest_in::<false>(&TraversalRay::new(s.o, s.d), t_max[i])
            {
                (t[i], record[i], det[i]) = (hit.t, id, hit.det);
                for (k, e) in e.iter_mut().enumerate() {
                    e[i] = hit.e[k];
                }
                triangles.set(i, true);
                out.analytic[i] = None;
            }
        }
        let any = triangles | analytic;
        out.best = BestLanes {
            t: F32x16::from_array(t),
            record: U32x16::from_array(record),
            e: e.map(F32x16::from_array),
            det: F32x16::from_array(det),
            hit: triangles,
        };
        out.hit = any;
    }

    /// `closest_analytic` for the lanes of `m`: spheres, then disks, in f64 lanes. Writes
    /// each lane's hit to `hits` and returns the lanes that hit and the segment left for
    /// the triangles (t_max in the scaled rays' units, shortened to the hit where there is
    /// one).
    #[inline(always)]
    fn closest_analytic_lanes(
        &self,
        r: &ScaledRayLanes,
        m: Mask16,
        hits: &mut [Option<Hit>; LANES],
    ) -> (Mask16, F32x16) {
        if !self.has_analytic_shapes() {
            return (Mask16::NONE, r.t_max);
        }
        *hits = [None; LANES];
        let wide = WideRays::new(r);
        let (m_lo, m_hi) = m.halves();
        let mut found = [Mask8::NONE; 2];
        let mut t_max = [wide.t_max.0, wide.t_max.1];
        for (h, m) in [m_lo, m_hi].into_iter().enumerate() {
            let (o, d) = wide.half(h);
            for (index, s) in self.spheres.iter().enumerate() {
                let (hit, t) = s.intersect_lanes(&o, &d, t_max[h], m);
                if hit.none() {
                    continue;
                }
                t_max[h] = F64x8::select(hit, t, t_max[h]);
                found[h] |= hit;
                let t = t.to_array();
                for i in hit.lanes() {
                    hits[8 * h + i] = Some(Hit::Sphere { index, t: t[i] });
                }
            }
        }
        for (h, m) in [m_lo, m_hi].into_iter().enumerate() {
            let (o, d) = wide.half(h);
            for (index, disk) in self.disks.iter().enumerate() {
                let (hit, t, [x, y]) = disk.intersect_lanes(&o, &d, t_max[h], m);
                if hit.none() {
                    continue;
                }
                t_max[h] = F64x8::select(hit, t, t_max[h]);
                found[h] |= hit;
                let [t, x, y] = [t, x, y].map(F64x8::to_array);
                for i in hit.lanes() {
                    hits[8 * h + i] = Some(Hit::Disk {
                        index,
                        t: t[i],
                        local: [x[i], y[i]],
                    });
                }
            }
        }
        let found = Mask16::from_halves(found[0], found[1]);
        let shortened = F32x16::from_f64_halves(t_max[0], t_max[1]);
        (found, F32x16::select(found, shortened, r.t_max))
    }

    /// Lanes of `m` whose segment meets a sphere or a disk (`occluded_in`'s first test).
    #[inline(always)]
    fn analytic_blocks_lanes(&self, r: &ScaledRayLanes, m: Mask16) -> Mask16 {
        if !self.has_analytic_shapes() {
            return Mask16::NONE;
        }
        let wide = WideRays::new(r);
        let t_max = [wide.t_max.0, wide.t_max.1];
        let (m_lo, m_hi) = m.halves();
        let mut found = [Mask8::NONE; 2];
        for (h, m) in [m_lo, m_hi].into_iter().enumerate() {
            let (o, d) = wide.half(h);
            for s in &self.spheres {
                let open = m & !found[h];
                if open.none() {
                    break;
                }
                found[h] |= s.intersect_lanes(&o, &d, t_max[h], open).0;
            }
            for disk in &self.disks {
                let open = m & !found[h];
                if open.none() {
                    break;
                }
                found[h] |= disk.intersect_lanes(&o, &d, t_max[h], open).0;
            }
        }
        Mask16::from_halves(found[0], found[1])
    }

    /// The surface data of `hits`: in lanes for triangle hits, through `interaction` lane
    /// by lane for spheres and disks. Lane by lane the same bits as `interaction`.
    pub fn surface_lanes(&self, hits: &ClosestLanes, rays: &RayLanes) -> SurfaceLanes {
        let mut surface = self.triangle_surface_lanes(hits);
        surface.hit = hits.hit;
        let analytic = hits.hit & !hits.best.hit;
        if analytic.none() {
            return surface;
        }
        // Spheres in lanes (their (u, v), which `SurfaceLanes` does not hold, is read
        // lane by lane where a texture needs it: `Geometry::uv`); disks through
        // `interaction`, lane by lane.
        let spheres = Mask16::from_fn(|i| {
            analytic.get(i) && matches!(hits.analytic[i], Some(Hit::Sphere { .. }))
        });
        if spheres.any() {
            surface.merge(spheres, &self.sphere_surface_lanes(hits, rays, spheres));
        }
        let others = analytic & !spheres;
        if others.any() {
            surface.merge(others, &self.surface_one_by_one(hits, rays, others));
        }
        surface
    }

    /// `surface_lanes` for the lanes of `m`, whose closest hits are spheres: `Sphere::hit`
    /// but its (u, v), each lane on its own sphere, in f64 lanes and then f32 ones, the same
    /// operations and so the same bits.
    fn sphere_surface_lanes(
        &self,
        hits: &ClosestLanes,
        rays: &RayLanes,
        m: Mask16,
    ) -> SurfaceLanes {
        let mut center = [[0.0f32; LANES]; 3];
        let mut radius = [0.0f32; LANES];
        let mut t = [0.0f64; LANES];
        let (mut shape, mut flip) = ([0u32; LANES], Mask16::NONE);
        for i in m.lanes() {
            if let Some(Hit::Sphere { index, t: hit_t }) = hits.analytic[i] {
                let s = &self.spheres[index];
                for (k, c) in center.iter_mut().enumerate() {
                    c[i] = s.center[k];
                }
                (radius[i], t[i], shape[i]) = (s.radius, hit_t, s.shape);
                flip.set(i, s.flip_normals);
            }
        }
        let center = center.map(F32x16::from_array);
        let radius = F32x16::from_array(radius);
        let (c_wide, r_wide) = (center.map(F32x16::to_f64_halves), radius.to_f64_halves());
        let wide = WideRays::new(&ScaledRayLanes::new(rays));
        let mut p = [(F64x8::splat(0.0), F64x8::splat(0.0)); 3];
        let mut n = p;
        for h in 0..2 {
            let pick = |v: (F64x8, F64x8)| if h == 0 { v.0 } else { v.1 };
            let (o, d) = wide.half(h);
            let t = F64x8::from_array(std::array::from_fn(|i| t[8 * h + i]));
            let (ph, nh) = sphere::reproject_lanes(&c_wide.map(pick), pick(r_wide), &o, &d, t);
            for k in 0..3 {
                let (pk, nk) = if h == 0 {
                    (&mut p[k].0, &mut n[k].0)
                } else {
                    (&mut p[k].1, &mut n[k].1)
                };
                (*pk, *nk) = (ph[k], nh[k]);
            }
        }
        let narrow = |v: [(F64x8, F64x8); 3]| {
            let [x, y, z] = v.map(|(lo, hi)| F32x16::from_f64_halves(lo, hi));
            V3::new(x, y, z)
        };
        let p = narrow(p);
        let n = narrow(n).normalize();
        let n = V3::select(flip, -n, n);
        let [cx, cy, cz] = center;
        let p_error = p.abs() * F32x16::splat(gamma(2))
            + (V3::new(cx, cy, cz).abs() + V3::new(radius, radius, radius))
                * F32x16::splat((2.0f32).powi(-46));
        SurfaceLanes {
            hit: m,
            p,
            p_error,
            ng: n,
            ns: n,
            shape: U32x16::from_array(shape),
            primitive: U32x16::splat(0),
        }
    }

    /// `surface_lanes` for the lanes whose closest hit is a triangle.
    #[inline(always)]
    fn triangle_surface_lanes(&self, hits: &ClosestLanes) -> SurfaceLanes {
        let best = &hits.best;
        let m = best.hit;
        // Each record's twelve coordinates: the three vertices' x, y and z rows, each with
        // an id in its fourth place.
        let table = self.bvh.record_coordinates();
        let base = best.record.shl::<3>() + best.record.shl::<2>();
        let at = |lane: u32| F32x16::gather(table, base + U32x16::splat(lane), m);
        let vertex = |j: u32| V3::new(at(j), at(4 + j), at(8 + j));
        let v = [vertex(0), vertex(1), vertex(2)];
        // `TriangleHit::barycentrics`.
        let inv = F32x16::splat(1.0) / best.det;
        let b = best.e.map(|e| e * inv);
        let (p, p_error) = triangle::hit_point_in(v, b);
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let ns = match self.bvh.normal_coordinates() {
            None => ng,
            Some(normals) => {
                // The interpolated vertex normal, normalised, where the record has normals
                // and it does not vanish (`triangle_interaction`).
                let base = best.record.shl::<3>() + best.record;
                let n = |j: u32| {
                    let c = |k: u32| F32x16::gather(normals, base + U32x16::splat(3 * j + k), m);
                    V3::new(c(0), c(1), c(2))
                };
                let n = [n(0), n(1), n(2)];
                let zero = F32x16::splat(0.0);
                let is_zero = |v: &V3<F32x16>| v.x.eq(zero) & v.y.eq(zero) & v.z.eq(zero);
                let none = is_zero(&n[0]) & is_zero(&n[1]) & is_zero(&n[2]);
                let interpolated = n[0] * b[0] + n[1] * b[1] + n[2] * b[2];
                let rcp = F32x16::splat(1.0) / interpolated.length();
                let ok = !none & rcp.is_finite() & rcp.gt(zero);
                V3::select(ok, interpolated * rcp, ng)
            }
        };
        let (shape, primitive) = triangle::ids_lanes([at(3), at(7), at(11)].map(F32x16::to_bits));
        SurfaceLanes {
            hit: m,
            p,
            p_error,
            ng,
            ns,
            shape,
            primitive,
        }
    }

    /// `surface_lanes` through `interaction`, one lane at a time, for the lanes of `m`.
    fn surface_one_by_one(&self, hits: &ClosestLanes, rays: &RayLanes, m: Mask16) -> SurfaceLanes {
        let mut v = [[[0.0f32; 3]; LANES]; 4];
        let (mut shape, mut primitive) = ([0u32; LANES], [0u32; LANES]);
        for i in m.lanes() {
            let Some(h) = hits.closest_hit(self, rays, i) else {
                continue;
            };
            let si = self.interaction(&h);
            for (k, x) in [si.p, si.p_error, si.ng, si.ns].iter().enumerate() {
                v[k][i] = x.to_array();
            }
            (shape[i], primitive[i]) = (si.shape, si.primitive);
        }
        let lanes = |k: usize| {
            let c = |axis: usize| F32x16::from_array(std::array::from_fn(|i| v[k][i][axis]));
            V3::new(c(0), c(1), c(2))
        };
        SurfaceLanes {
            hit: hits.hit,
            p: lanes(0),
            p_error: lanes(1),
            ng: lanes(2),
            ns: lanes(3),
            shape: U32x16::from_array(shape),
            primitive: U32x16::from_array(primitive),
        }
    }

    /// `occluded` for the rays of the lanes of `m`: the lanes whose segment is blocked
    /// (sixteen rays per triangle test where `closest_hits_lanes` uses it).
    pub fn occluded_lanes(&self, rays: &RayLanes, m: Mask16) -> Mask16 {
        let scaled = ScaledRayLanes::new(rays);
        let m = m & scaled.valid;
        let blocked = self.analytic_blocks_lanes(&scaled, m);
        let m = m & !blocked;
        if m.none() {
            return blocked;
        }
        if !self.packet_pays(m) {
            // The tree one ray at a time, for what the analytic shapes left.
            let scaled = scaled.lanes();
            return blocked
                | Mask16::from_fn(|i| {
                    let s = scaled.get(i);
                    m.get(i)
                        && self
                            .bvh
                            .any_in::<false>(&TraversalRay::new(s.o, s.d), s.t_max)
                });
        }
        let tri = TriangleRayLanes::new(&scaled.o, &scaled.d);
        let tri_ray = |i: usize| {
            let s = scaled.lanes().get(i);
            TriangleRay::new(s.o, s.d)
        };
        let packet = self.bvh.packet();
        let boxes = packet.box_rays(&scaled.o, &scaled.d);
        blocked | packet.any(self.bvh.records(), &tri, &boxes, tri_ray, scaled.t_max, m)
    }

    /// Whether the lanes of `m` are tested against every triangle in lanes rather than
    /// one by one through the tree: always on a flat scene; on a tree with packets, when
    /// enough lanes are active for the packet's cost (one vector test per triangle,
    /// whatever the lanes) to beat that many traversals.
    #[inline(always)]
    fn packet_pays(&self, m: Mask16) -> bool {
        self.bvh.is_flat()
            || (!self.bvh.packet().is_empty()
                && m.count() as usize * PACKET_LIMIT >= LANES * self.bvh.records().len())
    }

    fn has_analytic_shapes(&self) -> bool {
        !(self.spheres.is_empty() && self.disks.is_empty())
    }
}
