//! Small scenes without a tree: every triangle tested against the ray, sixteen at a time.
//!
//! On a few dozen triangles (the Cornell box has 36) a BVH query spends most of its time
//! deciding what not to test: decoding nodes, ordering children, then testing the surviving
//! leaf triangles one by one. Testing all triangles in lanes costs a few vector operations
//! per sixteen triangles instead. `TriangleBvh` answers its queries this way up to
//! `FLAT_LIMIT` triangles (the crossover measured in `benches/rays.rs`, README
//! "Performance").
//!
//! The lanes compute exactly the arithmetic of the watertight test (`triangle.rs`, same
//! operations in the same order, no fused multiply-adds). A lane whose edge functions have
//! mixed signs, or whose t lies outside (0, t_max), cannot pass that test and is dropped.
//! A lane that remains with no zero edge function and T above its rounding error bound is
//! settled: its hit follows from the lane's values through the test's last step (the
//! division and the t < t_max check, `triangle::hit_from`). The others (zero edge functions,
//! decided in f64; T too close to 0 for its sign to be certain) go through
//! `triangle::intersect` itself. So this path reports a hit exactly when the per-triangle
//! test does, with the same t and edge functions. Among hits at exactly equal t the lowest
//! record index wins, here and in the tree (`bvh::replaces`).
//!
//! Larger scenes (up to `LANE_LEAVES_LIMIT` triangles) keep the same chunks beside their
//! tree: traversal tests each node's hit leaf triangles (up to 24, contiguous in record
//! order) in the lanes of the one to three chunks that hold them, the others masked off
//! (`hits_of`). One vector test with one branch replaced a branchy per-triangle test per
//! leaf triangle; `pt` on the 330k-triangle mesh ran 12% faster, on the 4k-triangle water
//! mesh 3% (docs/performance.md).

use super::triangle::{self, TriangleHit, TriangleRay, TriangleRecord, cut_bound};
use crate::math::lanes::{F32x16, NATIVE, Real, U32x16};

/// Triangles per chunk: one `F32x16` (one AVX-512 register, or two AVX2 ones).
const LANES: usize = 16;

/// Scenes with at most this many triangles (three chunks) are answered by `FlatTriangles`.
/// `cargo bench --bench rays -- flat_crossover` (one thread, incoherent rays): at 36
/// triangles flat closest hits run 13% faster than the tree's, at 68 closest hits are 4%
/// faster and any hits 14% slower, at 132 both are 1.5–2× slower (`docs/performance.md`).
pub const FLAT_LIMIT: usize = 48;

/// Trees of at most this many triangles keep the chunks for `hits_of` (36 bytes more per
/// triangle); larger ones test their leaf triangles one by one. Incoherent rays, one thread
/// (`cargo bench --bench rays`): on 100k triangles the lanes ran 7% faster (9.28 → 9.91 M
/// rays/s), on 1M 22% slower (1.97 → 1.54: nine cache lines per chunk against one record per
/// triangle, in a tree beyond the cache); `pt` on the 330k-triangle mesh ran 12% faster.
pub const LANE_LEAVES_LIMIT: usize = 500_000;

/// Sixteen triangles, coordinates by axis, then vertex, then lane.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Chunk {
    v: [[[f32; LANES]; 3]; 3],
}

/// The triangles of `records`, in the same order, laid out for lane-parallel tests.
#[derive(Clone, Default)]
pub struct FlatTriangles {
    chunks: Vec<Chunk>,
}

impl FlatTriangles {
    pub fn new(records: &[TriangleRecord]) -> FlatTriangles {
        let mut chunks = Vec::with_capacity(records.len().div_ceil(LANES));
        for group in records.chunks(LANES) {
            // Lanes past the end hold NaN: all their edge functions are NaN, which
            // `lane_tests` drops.
            let mut c = Chunk {
                v: [[[f32::NAN; LANES]; 3]; 3],
            };
            for (lane, record) in group.iter().enumerate() {
                for axis in 0..3 {
                    for vertex in 0..3 {
                        c.v[axis][vertex][lane] = record.rows[axis][vertex];
                    }
                }
            }
            chunks.push(c);
        }
        FlatTriangles { chunks }
    }

    /// The closest triangle with 0 < t < t_max: (record index, its hit data), as
    /// `triangle::intersect` finds it.
    #[inline(always)]
    pub fn closest(
        &self,
        records: &[TriangleRecord],
        r: &TriangleRay,
        t_max: f32,
    ) -> Option<(u32, TriangleHit)> {
        let mut best = None;
        self.hits(records, r, t_max, |index, h, t_max| {
            *t_max = h.t;
            best = Some((index as u32, h));
            false
        });
        best
    }

    /// True when some triangle lies at 0 < t < t_max.
    #[inline(always)]
    pub fn any(&self, records: &[TriangleRecord], r: &TriangleRay, t_max: f32) -> bool {
        self.hits(records, r, t_max, |_, _, _| true)
    }

    /// `hits` over the records `base + b` for the bits b of `bits` only (a tree node's hit
    /// leaf triangles, `bvh.rs`): the chunks that hold them, each tested once with the
    /// other lanes masked off.
    #[inline(always)]
    pub fn hits_of(
        &self,
        records: &[TriangleRecord],
        r: &TriangleRay,
        base: u32,
        bits: u32,
        t_max: &mut f32,
        mut found: impl FnMut(usize, TriangleHit, &mut f32) -> bool,
    ) -> bool {
        if self.chunks.is_empty() {
            // A tree too large for the chunks (`LANE_LEAVES_LIMIT`): one by one.
            let mut rest = bits;
            while rest != 0 {
                let index = (base + rest.trailing_zeros()) as usize;
                rest &= rest - 1;
                if let Some(h) = triangle::intersect(&records[index], r, *t_max)
                    && found(index, h, t_max)
                {
                    return true;
                }
            }
            return false;
        }
        let first = base as usize / LANES;
        // The node's bits placed at their lanes from chunk `first` on (at most 24 + 15 bits).
        let mut lanes_wanted = (bits as u64) << (base as usize % LANES);
        let mut c = first;
        while lanes_wanted != 0 {
            let wanted = (lanes_wanted & 0xffff) as u32;
            lanes_wanted >>= LANES;
            if wanted != 0 {
                let lanes = lane_tests(&self.chunks[c], r, *t_max);
                let mut keep = lanes.keep & wanted;
                while keep != 0 {
                    let lane = keep.trailing_zeros() as usize;
                    keep &= keep - 1;
                    let index = c * LANES + lane;
                    if let Some(h) = lanes.hit(&records[index], r, lane, *t_max)
                        && found(index, h, t_max)
                    {
                        return true;
                    }
                }
            }
            c += 1;
        }
        false
    }

    /// Hands every hit within (0, t_max) to `found(record index, hit, t_max)` in record
    /// order, `t_max` as `found` leaves it (a closer hit shortens the segment); stops and
    /// returns true when `found` does.
    #[inline(always)]
    fn hits(
        &self,
        records: &[TriangleRecord],
        r: &TriangleRay,
        mut t_max: f32,
        mut found: impl FnMut(usize, TriangleHit, &mut f32) -> bool,
    ) -> bool {
        for (c, chunk) in self.chunks.iter().enumerate() {
            let lanes = lane_tests(chunk, r, t_max);
            let mut keep = lanes.keep;
            while keep != 0 {
                let lane = keep.trailing_zeros() as usize;
                keep &= keep - 1;
                let index = c * LANES + lane;
                if let Some(h) = lanes.hit(&records[index], r, lane, t_max)
                    && found(index, h, &mut t_max)
                {
                    return true;
                }
            }
        }
        false
    }
}

/// What the lanes found for one chunk and one ray.
#[repr(C, align(64))]
struct LaneTests {
    /// Edge functions and T = Σ e_i·z_i·s_z, exactly as the per-triangle test computes them.
    e: [[f32; LANES]; 3],
    t_num: [f32; LANES],
    /// Bit i set unless lane i certainly fails the watertight test within (0, t_max): its
    /// edge functions have mixed signs, or they are all non-zero and the hit's t lies
    /// outside the range. Lanes with a zero edge function stay set: `triangle::intersect`
    /// decides them in f64.
    keep: u32,
    /// The lanes of `keep` settled here: no zero edge function, and T above its rounding
    /// error bound (so t > 0 without the f64 sign test). Their hit follows from `e` and
    /// `t_num` through the per-triangle test's last step; the others go through the whole
    /// test again.
    settled: u32,
}

impl LaneTests {
    /// `triangle::intersect(record, r, t_max)` for lane `lane` of `keep`, with `t_max` no
    /// larger than the chunk was tested with.
    #[inline(always)]
    fn hit(
        &self,
        record: &TriangleRecord,
        r: &TriangleRay,
        lane: usize,
        t_max: f32,
    ) -> Option<TriangleHit> {
        if self.settled >> lane & 1 == 0 {
            return triangle::intersect(record, r, t_max);
        }
        let e = [self.e[0][lane], self.e[1][lane], self.e[2][lane]];
        let det = (e[0] + e[1]) + e[2];
        // T exceeds its error bound (`settled`): no bound can send it to the f64 test.
        triangle::hit_from(record, r, self.t_num[lane], det, e, t_max, || {
            f32::NEG_INFINITY
        })
    }
}

/// The watertight test's arithmetic on the sixteen lanes of `c` (see `LaneTests`), in the
/// lane types (`math::lanes`) where they are vector registers, else the portable loop.
#[inline(always)]
fn lane_tests(c: &Chunk, r: &TriangleRay, t_max: f32) -> LaneTests {
    if NATIVE {
        lane_tests_in_registers(c, r, t_max)
    } else {
        lane_tests_portable(c, r, t_max)
    }
}

/// A chunk's vertices sheared into the ray's frame and its edge functions, as
/// `triangle::intersect_scalar` computes them: `[x, y, z]` per vertex, then `e`.
struct Sheared<T> {
    v: [[T; 3]; 3],
    e: [T; 3],
}

/// `Sheared` for ray `r`, each coordinate read by `load(row of one axis and vertex)`: all
/// sixteen lanes in `F32x16`, or one lane in `f32`.
#[inline(always)]
fn shear<T: Real>(c: &Chunk, r: &TriangleRay, load: impl Fn(&[f32; LANES]) -> T) -> Sheared<T> {
    let (cx, cy, cz) = (&c.v[r.kx], &c.v[r.ky], &c.v[r.kz]);
    let splat = T::splat;
    let vertex = |j: usize| {
        let z = load(&cz[j]) - splat(r.oz);
        let x = (load(&cx[j]) - splat(r.ox)) - splat(r.sx) * z;
        let y = (load(&cy[j]) - splat(r.oy)) - splat(r.sy) * z;
        [x, y, z]
    };
    let v = [vertex(0), vertex(1), vertex(2)];
    let [[x0, y0, _], [x1, y1, _], [x2, y2, _]] = v;
    let e = [x2 * y1 - y2 * x1, x0 * y2 - y0 * x2, x1 * y0 - y1 * x0];
    Sheared { v, e }
}

/// `lane_tests` in `F32x16`: the operations of `lane_tests_portable`, lane for lane.
#[inline(always)]
fn lane_tests_in_registers(c: &Chunk, r: &TriangleRay, t_max: f32) -> LaneTests {
    let splat = F32x16::splat;
    let sz = splat(r.sz);
    let Sheared {
        v: [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2]],
        e: [e0, e1, e2],
    } = shear(c, r, |row| F32x16::from_array(*row));
    let zero = splat(0.0);
    let any_neg = e0.lt(zero) | e1.lt(zero) | e2.lt(zero);
    let any_pos = zero.lt(e0) | zero.lt(e1) | zero.lt(e2);
    // NaN counts as non-zero.
    let all_nonzero = e0.ne(zero) & e1.ne(zero) & e2.ne(zero);
    let det = (e0 + e1) + e2;
    let t_num = (e0 * (z0 * sz) + e1 * (z1 * sz)) + e2 * (z2 * sz);
    // Both made positive by the determinant's sign bit. For det = ±0 the flip differs from
    // the portable code's, but such lanes have a zero edge and are kept anyway.
    let sign = U32x16::splat(0x8000_0000);
    let t_num_p = F32x16::from_bits(t_num.to_bits() ^ (det.to_bits() & sign));
    let det_p = det.abs();
    let in_range = zero.lt(t_num_p) & t_num_p.le(cut_bound(splat(t_max), det_p));
    let keep = !(any_neg & any_pos) & (!all_nonzero | in_range);
    let mut out = LaneTests {
        e: [[0.0; LANES]; 3],
        t_num: [0.0; LANES],
        keep: keep.0 as u32,
        settled: 0,
    };
    if keep.none() {
        // Most chunks: nothing crosses the segment.
        return out;
    }
    // T's error bound from the largest |x|, |y|, |z| and |e|, as the per-triangle test
    // computes it (exact maxima: the same values in any order).
    let max3 = |a: F32x16, b: F32x16, c: F32x16| a.abs().max_gt(b.abs()).max_gt(c.abs());
    let max_xy = max3(x0, x1, x2).max_gt(max3(y0, y1, y2));
    let bound = triangle::t_num_error_bound_in(
        max_xy,
        max3(z0, z1, z2),
        max3(e0, e1, e2),
        splat(r.sz.abs()),
    );
    let settled =
        keep & all_nonzero & in_range & bound.lt(t_num_p) & bound.lt(splat(f32::INFINITY));
    out.settled = settled.0 as u32;
    out.e = [e0.to_array(), e1.to_array(), e2.to_array()];
    out.t_num = t_num.to_array();
    out
}

/// `lane_tests` in portable code, one lane after another: targets without vector lane
/// types, and the reference the tests hold the registers' version to.
#[inline(always)]
fn lane_tests_portable(c: &Chunk, r: &TriangleRay, t_max: f32) -> LaneTests {
    let mut out = LaneTests {
        e: [[0.0; LANES]; 3],
        t_num: [0.0; LANES],
        keep: 0,
        settled: 0,
    };
    for i in 0..LANES {
        let Sheared {
            v: [[x0, y0, z0], [x1, y1, z1], [x2, y2, z2]],
            e: [e0, e1, e2],
        } = shear(c, r, |row| row[i]);
        let any_neg = (e0 < 0.0) | (e1 < 0.0) | (e2 < 0.0);
        let any_pos = (e0 > 0.0) | (e1 > 0.0) | (e2 > 0.0);
        let all_nonzero = (e0 != 0.0) & (e1 != 0.0) & (e2 != 0.0);
        let det = (e0 + e1) + e2;
        let t_num = (e0 * (z0 * r.sz) + e1 * (z1 * r.sz)) + e2 * (z2 * r.sz);
        // t = T/det with both made positive, as `triangle::hit_from`.
        let (t_num_p, det_p) = if det < 0.0 {
            (-t_num, -det)
        } else {
            (t_num, det)
        };
        // False when det or T is NaN. Such a lane with no zero edge function (padding
        // lanes; overflowing coordinates) is dropped, as the per-triangle test rejects it
        // (its det is NaN too); one with a zero edge is kept by `!all_nonzero`, for f64.
        let in_range = (t_num_p > 0.0) & (t_num_p <= cut_bound(t_max, det_p));
        let keep = !(any_neg & any_pos) & (!all_nonzero | in_range);
        let max3 = |a: f32, b: f32, c: f32| a.abs().max(b.abs()).max(c.abs());
        let bound = triangle::t_num_error_bound_in(
            max3(x0, x1, x2).max(max3(y0, y1, y2)),
            max3(z0, z1, z2),
            max3(e0, e1, e2),
            r.sz.abs(),
        );
        let settled = keep & all_nonzero & in_range & (t_num_p > bound) & (bound < f32::INFINITY);
        out.keep |= (keep as u32) << i;
        out.settled |= (settled as u32) << i;
        out.e[0][i] = e0;
        out.e[1][i] = e1;
        out.e[2][i] = e2;
        out.t_num[i] = t_num;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn rng(state: &mut u64) -> f32 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A point uniform in [−offset, scale − offset)³.
    fn random_point(s: &mut u64, scale: f32, offset: f32) -> Vec3 {
        Vec3::new(rng(s), rng(s), rng(s)) * scale - offset
    }

    /// A hit's t, edge functions and determinant, as bits (NaN-safe equality).
    fn bits(h: &TriangleHit) -> [u32; 5] {
        [h.t, h.e[0], h.e[1], h.e[2], h.det].map(f32::to_bits)
    }

    /// An origin uniform in [−offset, scale − offset)³ and a direction uniform in
    /// [−1, 1)³; None for a zero direction.
    fn random_ray(s: &mut u64, scale: f32, offset: f32) -> Option<(Vec3, Vec3)> {
        let o = random_point(s, scale, offset);
        let d = random_point(s, 2.0, 1.0);
        (d.length_squared() != 0.0).then_some((o, d))
    }

    /// The per-triangle test over all records in order, keeping the first of the closest.
    fn scan(
        records: &[TriangleRecord],
        r: &TriangleRay,
        mut t_max: f32,
    ) -> Option<(u32, [u32; 5])> {
        let mut best = None;
        for (i, rec) in records.iter().enumerate() {
            if let Some(h) = triangle::intersect(rec, r, t_max) {
                t_max = h.t;
                best = Some((i as u32, bits(&h)));
            }
        }
        best
    }

    /// Asserts that both of `flat`'s queries answer as the scan; returns the scan's answer.
    fn answers_as_scan(
        flat: &FlatTriangles,
        records: &[TriangleRecord],
        r: &TriangleRay,
        t_max: f32,
        what: &str,
    ) -> Option<(u32, [u32; 5])> {
        let expected = scan(records, r, t_max);
        let found = flat.closest(records, r, t_max).map(|(i, h)| (i, bits(&h)));
        assert_eq!(found, expected, "{what}");
        assert_eq!(flat.any(records, r, t_max), expected.is_some(), "{what}");
        expected
    }

    /// A 5×5 grid of unit squares (50 triangles sharing edges and vertices at integer
    /// coordinates) in the plane z = 0, plus `extra` random triangles around it.
    fn scene(extra: usize, s: &mut u64) -> Vec<TriangleRecord> {
        let mut records = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                let p = |a: i32, b: i32| Vec3::new((i + a) as f32, (j + b) as f32, 0.0);
                let n = records.len() as u32;
                records.push(TriangleRecord::new([p(0, 0), p(1, 0), p(1, 1)], 0, n));
                records.push(TriangleRecord::new([p(0, 0), p(1, 1), p(0, 1)], 0, n + 1));
            }
        }
        for _ in 0..extra {
            let mut v = || Vec3::new(rng(s) * 6.0 - 0.5, rng(s) * 6.0 - 0.5, rng(s) * 4.0 - 2.0);
            let n = records.len() as u32;
            records.push(TriangleRecord::new([v(), v(), v()], 1, n));
        }
        records
    }

    /// Rays at random, and rays through the grid's vertices and edges (zero edge
    /// functions), from origins on both sides of the plane and on it.
    fn ray(i: u32, s: &mut u64) -> (TriangleRay, f32) {
        let grid = |s: &mut u64| (rng(s) * 6.0).floor() - 0.25 + 0.25 * (rng(s) * 3.0).floor();
        let target = match i % 3 {
            0 => Vec3::new(grid(s), grid(s), 0.0),
            1 => Vec3::new(grid(s), rng(s) * 6.0 - 0.5, 0.0),
            _ => Vec3::new(rng(s) * 6.0 - 0.5, rng(s) * 6.0 - 0.5, rng(s) * 4.0 - 2.0),
        };
        let o = match i % 5 {
            0 => Vec3::new(target.x, target.y, 3.0), // axis-aligned, exactly through it
            1 => Vec3::new(rng(s) * 6.0, rng(s) * 6.0, 0.0), // on the grid's plane
            _ => Vec3::new(rng(s) * 10.0 - 2.0, rng(s) * 10.0 - 2.0, rng(s) * 8.0 - 4.0),
        };
        let d = target - o;
        let t_max = [f32::INFINITY, 1.0, 0.5, 1e-3][(i % 4) as usize];
        (TriangleRay::new(o, d), t_max)
    }

    #[test]
    fn answers_as_the_per_triangle_test_in_record_order() {
        let mut s = 0x5DEE_CE66_D1CE_4E5Bu64;
        let (mut hits, mut misses, mut occluded) = (0, 0, 0);
        // Record counts that fill chunks exactly, leave one lane, and leave most empty.
        for (k, extra) in [14usize, 15, 0, 3].into_iter().enumerate() {
            let records = scene(extra, &mut s);
            let flat = FlatTriangles::new(&records);
            for i in 0..50_000u32 {
                let (r, t_max) = ray(i + k as u32, &mut s);
                if r.d.length_squared() == 0.0 {
                    continue;
                }
                let expected =
                    answers_as_scan(&flat, &records, &r, t_max, &format!("ray {i} of scene {k}"));
                hits += expected.is_some() as u32;
                misses += expected.is_none() as u32;
                occluded += (expected.is_some() && t_max.is_finite()) as u32;
            }
        }
        // The rays exercise both outcomes, including segments that end before a hit.
        assert!(hits > 40_000 && misses > 40_000 && occluded > 10_000);
    }

    #[test]
    fn a_nodes_triangles_answer_as_the_per_triangle_test_over_them() {
        // `hits_of` as the tree calls it: up to 24 records from any base, so that the
        // selected lanes start anywhere in a chunk and spread over up to three chunks.
        let mut s = 0x1B87_3593_C2B2_AE3Du64;
        let records = scene(14, &mut s); // 64 records, four chunks
        let flat = FlatTriangles::new(&records);
        let (mut hits, mut chunks_spanned) = (0, [0u32; 4]);
        for i in 0..50_000u32 {
            let (r, t_max) = ray(i, &mut s);
            if r.d.length_squared() == 0.0 {
                continue;
            }
            let base = (rng(&mut s) * 40.0) as u32;
            let mut mask = ((rng(&mut s) * 16_777_216.0) as u32) & 0xff_ffff;
            mask &= [u32::MAX, 0x7, 0xff_f000, 0x80_0001][(i % 4) as usize];
            let chosen: Vec<u32> = (0..24).filter(|b| mask >> b & 1 == 1).collect();
            if let (Some(first), Some(last)) = (chosen.first(), chosen.last()) {
                chunks_spanned[((base + last) / 16 - (base + first) / 16) as usize] += 1;
            }
            // The per-triangle test over the chosen records, in order, keeping the first of
            // the closest.
            let (mut expected, mut t) = (None, t_max);
            for &b in &chosen {
                let index = base + b;
                if let Some(h) = triangle::intersect(&records[index as usize], &r, t) {
                    t = h.t;
                    expected = Some((index, bits(&h)));
                }
            }
            let (mut found, mut t) = (None, t_max);
            flat.hits_of(&records, &r, base, mask, &mut t, |index, h, t| {
                *t = h.t;
                found = Some((index as u32, bits(&h)));
                false
            });
            assert_eq!(found, expected, "ray {i}, base {base}, mask {mask:#x}");
            let mut t = t_max;
            let any = flat.hits_of(&records, &r, base, mask, &mut t, |_, _, _| true);
            assert_eq!(
                any,
                expected.is_some(),
                "ray {i}, base {base}, mask {mask:#x}"
            );
            // Without chunks (a tree beyond `LANE_LEAVES_LIMIT`): the same, one by one.
            let (mut one_by_one, mut t) = (None, t_max);
            FlatTriangles::default().hits_of(&records, &r, base, mask, &mut t, |index, h, t| {
                *t = h.t;
                one_by_one = Some((index as u32, bits(&h)));
                false
            });
            assert_eq!(one_by_one, expected, "ray {i}, no chunks");
            hits += expected.is_some() as u32;
        }
        assert!(hits > 2_000, "{hits}");
        assert!(
            chunks_spanned[1] > 1_000 && chunks_spanned[2] > 100,
            "{chunks_spanned:?}"
        );
    }

    #[test]
    fn lanes_keep_every_triangle_the_test_accepts_and_settle_as_it() {
        // Stronger than the agreement above: the filter alone never drops an accepted
        // triangle, lane by lane, and (where AVX-512 or AVX2 is compiled) both versions agree.
        let mut s = 0xA076_1D64_78BD_642Fu64;
        let (mut accepted, mut settled) = (0, 0);
        // 64 triangles (full chunks) and 53 (eleven padding lanes).
        let scenes = [scene(14, &mut s), scene(3, &mut s)];
        let flats = scenes.each_ref().map(|records| FlatTriangles::new(records));
        for i in 0..50_000u32 {
            let (records, flat) = (&scenes[(i % 2) as usize], &flats[(i % 2) as usize]);
            let (r, t_max) = ray(i, &mut s);
            if r.d.length_squared() == 0.0 {
                continue;
            }
            for (c, chunk) in flat.chunks.iter().enumerate() {
                let lanes = lane_tests(chunk, &r, t_max);
                let portable = lane_tests_portable(chunk, &r, t_max);
                assert_eq!(
                    (lanes.keep, lanes.settled),
                    (portable.keep, portable.settled)
                );
                // Padding lanes (NaN) are never candidates.
                let filled = LANES.min(records.len() - c * LANES);
                assert_eq!(lanes.keep >> filled, 0, "ray {i}: a padding lane kept");
                assert_eq!(lanes.settled & !lanes.keep, 0);
                for lane in 0..filled {
                    let rec = &records[c * LANES + lane];
                    let expected = triangle::intersect(rec, &r, t_max);
                    if expected.is_some() {
                        accepted += 1;
                        assert!(lanes.keep & (1 << lane) != 0, "ray {i} lane {lane} dropped");
                    }
                    if lanes.keep & (1 << lane) == 0 {
                        continue;
                    }
                    // A kept lane answers as the per-triangle test, also with a shorter
                    // segment (as after a closer hit), whether settled here or not.
                    for t in [t_max, t_max * 0.5] {
                        for tests in [&lanes, &portable] {
                            assert_eq!(
                                tests.hit(rec, &r, lane, t).map(|h| bits(&h)),
                                triangle::intersect(rec, &r, t).map(|h| bits(&h)),
                                "ray {i} lane {lane}"
                            );
                        }
                    }
                    settled += lanes.settled >> lane & 1;
                }
            }
        }
        assert!(accepted > 20_000);
        // Most accepted lanes are settled by the lanes; the rest (zero edge functions, T
        // within its error bound) are still exercised through the full test.
        assert!(
            settled > accepted / 2 && settled < accepted,
            "{settled} of {accepted}"
        );
    }

    /// The same triangles answered through a tree and without one (`FLAT_LIMIT` 0 and ∞).
    fn tree_and_flat(
        vertices: &[[Vec3; 3]],
    ) -> (
        crate::geometry::bvh::TriangleBvh,
        crate::geometry::bvh::TriangleBvh,
    ) {
        use crate::geometry::bvh::{TriangleBvh, TriangleList};
        let ids: Vec<[u32; 2]> = (0..vertices.len() as u32).map(|i| [0, i]).collect();
        let list = TriangleList {
            vertices,
            ids: &ids,
        };
        let tree = TriangleBvh::build_with_flat_limit(&list, 0);
        let flat = TriangleBvh::build_with_flat_limit(&list, usize::MAX);
        (tree, flat)
    }

    #[test]
    fn agrees_with_the_tree_on_the_cornell_box() {
        use crate::geometry::bvh::TraversalRay;
        use crate::geometry::procedural::cornell_box;
        use crate::scene::ShapeGeometry;
        let mut vertices = Vec::new();
        for shape in cornell_box(2.0) {
            if let ShapeGeometry::Mesh(m) = &shape.geometry {
                vertices.extend(m.indices.iter().map(|t| t.map(|i| m.positions[i as usize])));
            }
        }
        let (tree, flat) = tree_and_flat(&vertices);
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut hits = 0;
        for i in 0..100_000u32 {
            let Some((o, d)) = random_ray(&mut s, 2.4, 0.2) else {
                continue;
            };
            let r = TraversalRay::new(o, d);
            let t_max = [f32::INFINITY, 0.3][(i % 2) as usize];
            // The same triangle at the same distance (ties included: `replaces`).
            let a = tree.closest(&r, t_max).map(|(id, h)| (id, h.t.to_bits()));
            let b = flat.closest(&r, t_max).map(|(id, h)| (id, h.t.to_bits()));
            assert_eq!(a, b, "ray {i}");
            assert_eq!(tree.any(&r, t_max), flat.any(&r, t_max), "ray {i}");
            hits += a.is_some() as u32;
        }
        // Half the rays are long enough to hit a wall (the box is open at the front).
        assert!(hits > 40_000, "{hits} hits");
    }

    /// Every query returns the nearest hit among all triangles (the lowest record index
    /// among equal t), whatever order it meets them in: `argmin (t, index)` over the
    /// per-triangle test of each record alone. Near ties make this fail if a hit's
    /// acceptance depends on the segment end in any other way than t < t_max: on the
    /// Cornell box the blocks' bottom faces lie on the floor, so rays onto the floor under
    /// them meet two triangles whose computed t differ by a float or none.
    #[test]
    fn the_nearest_hit_wins_whatever_the_order() {
        use crate::geometry::bvh::TraversalRay;
        use crate::geometry::procedural::{cornell_box, uv_sphere_with_triangles};
        use crate::scene::ShapeGeometry;
        let mut vertices = Vec::new();
        let sphere = uv_sphere_with_triangles(Vec3::new(0.7, 0.5, 0.3), 0.12, 2000);
        let meshes = cornell_box(1.0)
            .into_iter()
            .filter_map(|s| match s.geometry {
                ShapeGeometry::Mesh(m) => Some(m),
                _ => None,
            })
            .chain([sphere]);
        for m in meshes {
            vertices.extend(m.indices.iter().map(|t| t.map(|i| m.positions[i as usize])));
        }
        let (tree, flat) = tree_and_flat(&vertices);
        let nearest = |bvh: &crate::geometry::bvh::TriangleBvh, r: &TraversalRay, t_max: f32| {
            let mut best: Option<(f32, u32)> = None;
            for (k, rec) in bvh.records().iter().enumerate() {
                if let Some(h) = triangle::intersect(rec, &r.tri, t_max)
                    && best.is_none_or(|b| (h.t, k as u32) < b)
                {
                    best = Some((h.t, k as u32));
                }
            }
            best.map(|(t, k)| (k, t.to_bits()))
        };
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut checked = 0;
        for i in 0..20_000u32 {
            // Half from anywhere in the box, half down onto the floor under the blocks.
            let (o, d) = if i % 2 == 0 {
                let Some(ray) = random_ray(&mut s, 1.0, 0.0) else {
                    continue;
                };
                ray
            } else {
                let target = Vec3::new(0.1 + 0.8 * rng(&mut s), 0.0, 0.1 + 0.8 * rng(&mut s));
                let o = random_point(&mut s, 1.0, 0.0) * Vec3::new(1.0, 0.3, 1.0);
                (o, target - o)
            };
            let r = TraversalRay::new(o, d);
            for (bvh, what) in [(&tree, "tree"), (&flat, "flat")] {
                let want = nearest(bvh, &r, f32::INFINITY);
                let got = bvh
                    .closest(&r, f32::INFINITY)
                    .map(|(k, h)| (k, h.t.to_bits()));
                assert_eq!(got, want, "{what}, ray {i} from {o} along {d}");
                let mut streamed = None;
                bvh.closest_stream(&[r], &[f32::INFINITY], |_, h| {
                    streamed = h.map(|(k, h)| (k, h.t.to_bits()))
                });
                assert_eq!(streamed, want, "{what} streamed, ray {i}");
                checked += want.is_some() as u32;
            }
        }
        assert!(checked > 20_000, "{checked} hits");
    }

    /// A floor of 30 × 30 unit squares, two triangles each, hit straight down on the
    /// edges, diagonals and corners the triangles share: the arithmetic is exact there, so
    /// two to six triangles report the same t. The tree meets them in traversal order and
    /// must keep the one the flat scan keeps (the lowest record index), so that both kinds
    /// of query report the same triangle.
    #[test]
    fn the_tree_keeps_the_flat_scans_triangle_among_exact_ties() {
        use crate::geometry::bvh::TraversalRay;
        const N: u32 = 30;
        let corner = |i: u32, j: u32| Vec3::new(i as f32, 0.0, j as f32);
        let mut vertices = Vec::new();
        for j in 0..N {
            for i in 0..N {
                let (a, b) = (corner(i, j), corner(i + 1, j));
                let (c, d) = (corner(i, j + 1), corner(i + 1, j + 1));
                vertices.push([a, b, d]);
                vertices.push([a, d, c]);
            }
        }
        let (tree, flat) = tree_and_flat(&vertices);
        assert!(!tree.is_flat() && flat.is_flat());
        let mut rays = Vec::new();
        for j in 1..N {
            for i in 1..N {
                // A corner, the middles of two shared edges, and a point of the diagonal.
                for (x, z) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.25, 0.25)] {
                    let o = Vec3::new(i as f32 + x, 1.0, j as f32 + z);
                    rays.push(TraversalRay::new(o, Vec3::NEG_Y));
                }
            }
        }
        let found = |hit: Option<(u32, TriangleHit)>| hit.map(|(id, h)| (id, h.t.to_bits()));
        let mut streamed = vec![None; rays.len()];
        let ends = vec![f32::INFINITY; rays.len()];
        tree.closest_stream(&rays, &ends, |k, hit| streamed[k] = found(hit));
        for (r, streamed) in rays.iter().zip(streamed) {
            let want = found(flat.closest(r, f32::INFINITY));
            assert!(want.is_some(), "every ray hits the floor");
            assert_eq!(
                found(tree.closest(r, f32::INFINITY)),
                want,
                "ray down from {}",
                r.o
            );
            assert_eq!(streamed, want, "streamed ray down from {}", r.o);
        }
    }

    #[test]
    fn odd_triangles_and_counts_answer_as_the_scan() {
        // Zero-area, huge (overflowing the edge functions), infinite and NaN vertices, at
        // 0, 1, 16, 48 and 49 triangles, with rays of every length including 0 and NaN.
        let mut s = 0x853C_49E6_748F_EA9Bu64;
        let odd = [0.0, -0.0, 1e-40, 3e38, -3e38, f32::INFINITY, f32::NAN];
        let mut checked = 0;
        for count in [0usize, 1, 16, 48, 49] {
            let records: Vec<TriangleRecord> = (0..count as u32)
                .map(|i| {
                    let mut v = || random_point(&mut s, 4.0, 2.0);
                    let mut tri = [v(), v(), v()];
                    match i % 5 {
                        0 => tri[2] = tri[0] + (tri[1] - tri[0]) * 0.5, // zero area
                        1 => tri[1].x = odd[(rng(&mut s) * 7.0) as usize],
                        2 => tri[0] *= 1e30, // large, finite
                        _ => {}
                    }
                    TriangleRecord::new(tri, 0, i)
                })
                .collect();
            let flat = FlatTriangles::new(&records);
            for i in 0..20_000u32 {
                let Some((o, d)) = random_ray(&mut s, 6.0, 3.0) else {
                    continue;
                };
                let r = TriangleRay::new(o, d);
                let t_max = [f32::INFINITY, 1.0, 0.0, f32::NAN][(i % 4) as usize];
                let what = format!("{count} triangles, ray {i}");
                let expected = answers_as_scan(&flat, &records, &r, t_max, &what);
                checked += expected.is_some() as u32;
            }
        }
        // Half the segments are empty (t_max 0 or NaN), and the triangles are small.
        assert!(checked > 2_000, "{checked} hits");
    }
}
