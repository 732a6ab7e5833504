//! Watertight ray/triangle intersection (Woop, Benthin & Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013) and the hit point with its error bound.
//!
//! The ray is made the +z axis of a sheared coordinate system (a per-ray permutation and
//! shear); the three vertices are transformed the same way whichever triangle they belong
//! to, and the 2D edge functions are evaluated as `a·b − c·d` with no fused operations, so
//! the edge shared by two triangles gets exactly opposite values in both: a ray cannot slip
//! between them. An edge function that rounds to zero is recomputed in f64 (exact signs).
//!
//! The sign of t is then decided separately, in f64, from the original vertices: the
//! origin's side of the triangle's plane against the direction's. That is exact to ~1e-16
//! relative, far below the f32 offsets of spawned ray origins, so a ray leaving a triangle
//! can never report it again at t ≈ 0, and a legitimate hit however close to the origin is
//! kept. (Pharr et al., PBR 4th ed. §6.8.6, instead reject t below an error bound on t; that
//! bound is loose by orders of magnitude and dropped real hits up to ~1e-5 of the triangle's
//! size from the origin in mltbench's tests.)

use glam::Vec3;

use crate::math::lanes::{Real, U32x16, V3};

use super::offset::gamma;

/// One triangle in the BVH's order, laid out for the test: `rows[k]` holds coordinate k of
/// vertices 0, 1, 2. The fourth lanes carry the triangle's (shape, primitive) identity, so
/// the closest hit needs no further memory access to name it; they hold floats in [1, 2)
/// (23 payload bits each, never denormal or NaN), and the SIMD test masks that lane out of
/// every sum, maximum and sign test.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(16))]
pub struct TriangleRecord {
    pub rows: [[f32; 4]; 3],
}

const PAYLOAD: u32 = 0x7f_ffff;

fn encode(bits: u32) -> f32 {
    f32::from_bits(0x3f80_0000 | (bits & PAYLOAD))
}

fn decode(v: f32) -> u32 {
    v.to_bits() & PAYLOAD
}

impl TriangleRecord {
    pub fn new(v: [Vec3; 3], shape: u32, primitive: u32) -> Self {
        // The low 23 bits of each id in rows 0 and 1, the 9 + 9 high bits in row 2.
        let high = (shape >> 23) | ((primitive >> 23) << 9);
        let ids = [encode(shape), encode(primitive), encode(high)];
        let row = |k: usize| [v[0][k], v[1][k], v[2][k], ids[k]];
        TriangleRecord {
            rows: [row(0), row(1), row(2)],
        }
    }

    pub fn vertex(&self, i: usize) -> Vec3 {
        Vec3::new(self.rows[0][i], self.rows[1][i], self.rows[2][i])
    }

    /// (shape, primitive) given to `new`.
    pub fn ids(&self) -> [u32; 2] {
        let high = decode(self.rows[2][3]);
        [
            decode(self.rows[0][3]) | ((high & 0x1ff) << 23),
            decode(self.rows[1][3]) | ((high >> 9) << 23),
        ]
    }
}

/// Per-ray constants of the watertight test: the axis permutation (z = the direction's
/// largest component, x/y swapped when it is negative to keep the winding) and the shear.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    /// Origin coordinates along kx, ky, kz.
    pub ox: f32,
    pub oy: f32,
    pub oz: f32,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
    /// The ray itself, for the f64 sign test.
    pub o: Vec3,
    pub d: Vec3,
}

impl TriangleRay {
    /// `d` must be non-zero and finite.
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        // Branch-free, and without indexing arrays on the stack (a store and a reload per
        // lookup): ray directions are random, branches on them mispredict.
        let a = d.abs();
        // kz = index of the largest |d| component (the first of equals, as a scan would),
        // in integer arithmetic (compilers turn selects on it into branches).
        let z_largest = (a.z > a.x.max(a.y)) as usize;
        let kz = 2 * z_largest + (1 - z_largest) * (a.y > a.x) as usize;
        let kx0 = [1, 2, 0][kz];
        let ky0 = [2, 0, 1][kz];
        // A negative d[kz] swaps x and y to keep the winding.
        let negative = (d.cmplt(Vec3::ZERO).bitmask() as usize >> kz) & 1;
        let swap = (kx0 ^ ky0) & negative.wrapping_neg();
        let (kx, ky) = (kx0 ^ swap, ky0 ^ swap);
        let (op, dp) = permute(o, d, [kx, ky, kz]);
        let sz = 1.0 / dp.z;
        TriangleRay {
            kx,
            ky,
            kz,
            ox: op.x,
            oy: op.y,
            oz: op.z,
            sx: dp.x * sz,
            sy: dp.y * sz,
            sz,
            o,
            d,
        }
    }
}

/// (o, d) with their components reordered as (k[0], k[1], k[2]) (each k < 3).
#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
#[inline(always)]
fn permute(o: Vec3, d: Vec3, k: [usize; 3]) -> (Vec3, Vec3) {
    use std::arch::x86_64::*;
    // SAFETY: AVX is enabled for this build (cfg above); register operations only.
    unsafe {
        let idx = _mm_setr_epi32(k[0] as i32, k[1] as i32, k[2] as i32, 2);
        let op = _mm_permutevar_ps(glam::Vec3A::from(o).into(), idx);
        let dp = _mm_permutevar_ps(glam::Vec3A::from(d).into(), idx);
        (glam::Vec3A::from(op).into(), glam::Vec3A::from(dp).into())
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
#[inline(always)]
fn permute(o: Vec3, d: Vec3, k: [usize; 3]) -> (Vec3, Vec3) {
    let (oa, da) = (o.to_array(), d.to_array());
    (
        Vec3::new(oa[k[0]], oa[k[1]], oa[k[2]]),
        Vec3::new(da[k[0]], da[k[1]], da[k[2]]),
    )
}

/// What the test found: the edge functions (proportional to the barycentrics of vertices
/// 0, 1, 2) and their sum, both with the sign of the determinant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub e: [f32; 3],
    pub det: f32,
}

impl TriangleHit {
    /// Barycentrics (b0, b1, b2) of the hit: non-negative, summing to one up to rounding.
    pub fn barycentrics(&self) -> [f32; 3] {
        let inv = 1.0 / self.det;
        [self.e[0] * inv, self.e[1] * inv, self.e[2] * inv]
    }
}

/// Whether the exact ray meets the triangle's plane at t > 0: the origin lies on the side
/// of the plane opposite to where the direction points, n·(v0 − o) and n·d of equal signs.
/// In f64 from the f32 inputs: the differences are exact, the cross product rounds once,
/// the dot products a few times, all relative to ~2⁻⁵², so the sign is wrong only for an
/// origin within ~1e-15·|v0 − o| of the plane (spawned origins sit ~1e-7 away).
/// Inlined: a call would spill every vector register the traversal keeps live.
#[inline(always)]
fn t_is_positive(tri: &TriangleRecord, r: &TriangleRay) -> bool {
    let v = [0, 1, 2].map(|i| tri.vertex(i).as_dvec3());
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let side = n.dot(v[0] - r.o.as_dvec3());
    let towards = n.dot(r.d.as_dvec3());
    (side > 0.0 && towards > 0.0) || (side < 0.0 && towards < 0.0)
}

/// The three edge functions recomputed in f64 from the same sheared f32 coordinates
/// (products of two f32 are exact in f64; one rounding in the difference keeps the sign).
#[inline(never)]
#[cold]
fn edges_f64(x: [f32; 3], y: [f32; 3]) -> [f64; 3] {
    let (x, y) = (x.map(f64::from), y.map(f64::from));
    [
        x[2] * y[1] - y[2] * x[1],
        x[0] * y[2] - y[0] * x[2],
        x[1] * y[0] - y[1] * x[0],
    ]
}

/// Portable reference implementation of the test. Returns the hit with 0 < t < t_max, if
/// any (t in units of the ray direction the `TriangleRay` was made from).
pub fn intersect_scalar(tri: &TriangleRecord, r: &TriangleRay, t_max: f32) -> Option<TriangleHit> {
    let rx = &tri.rows[r.kx];
    let ry = &tri.rows[r.ky];
    let rz = &tri.rows[r.kz];
    let mut ax = [0.0f32; 3];
    let mut ay = [0.0f32; 3];
    let mut z = [0.0f32; 3];
    let mut x = [0.0f32; 3];
    let mut y = [0.0f32; 3];
    for i in 0..3 {
        ax[i] = rx[i] - r.ox;
        ay[i] = ry[i] - r.oy;
        z[i] = rz[i] - r.oz;
        x[i] = ax[i] - r.sx * z[i];
        y[i] = ay[i] - r.sy * z[i];
    }
    let mut e = [
        x[2] * y[1] - y[2] * x[1],
        x[0] * y[2] - y[0] * x[2],
        x[1] * y[0] - y[1] * x[0],
    ];
    finish(tri, r, &mut e, x, y, z, t_max)
}

/// The part of the test after the edge functions, shared by both implementations; written
/// to perform the same operations in the same order as the SIMD path (bit-identical).
#[inline(always)]
fn finish(
    tri: &TriangleRecord,
    r: &TriangleRay,
    e: &mut [f32; 3],
    x: [f32; 3],
    y: [f32; 3],
    z: [f32; 3],
    t_max: f32,
) -> Option<TriangleHit> {
    let neg = e.iter().any(|&v| v < 0.0);
    let pos = e.iter().any(|&v| v > 0.0);
    if neg && pos {
        return None;
    }
    if e.contains(&0.0) {
        let e64 = edges_f64(x, y);
        let neg = e64.iter().any(|&v| v < 0.0);
        let pos = e64.iter().any(|&v| v > 0.0);
        if neg && pos {
            return None;
        }
        *e = e64.map(|v| v as f32);
    }
    let det = (e[0] + e[1]) + e[2];
    if det == 0.0 {
        return None;
    }
    let zs = z.map(|v| v * r.sz);
    let t_num = (e[0] * zs[0] + e[1] * zs[1]) + e[2] * zs[2];
    let e_copy = *e;
    hit_from(tri, r, t_num, det, e_copy, t_max, || {
        let max_abs = |v: [f32; 3]| v[0].abs().max(v[1].abs()).max(v[2].abs());
        t_num_error_bound(
            max_abs(x).max(max_abs(y)),
            max_abs(z),
            max_abs(e_copy),
            r.sz,
        )
    })
}

/// The bound of every test's first cut T ≤ t_max·det·(1 + 2⁻²¹), taken before dividing:
/// wide enough never to drop a hit whose computed t = T/det lies below t_max (the two
/// roundings of the product and the one of the quotient stay within 2⁻²³; a subnormal
/// product is met by ≤), so that the hit is decided by t < t_max alone. With the strict
/// cut T < t_max·det the decision also depended on the product's rounding: a triangle one
/// float nearer than the best hit could fail it, and which of two nearly tied triangles a
/// closest-hit query kept then depended on the order it met them in
/// (`flat::tests::the_nearest_hit_wins_whatever_the_order`).
#[inline(always)]
pub(super) fn cut_bound<T: BoundArithmetic>(t_max: T, det_p: T) -> T {
    t_max * det_p * T::splat(1.0 + 1.0 / (1 << 21) as f32)
}

/// Accepts the candidate: t = T/det within (0, t_max). The sign of t is certain when T
/// exceeds its rounding error bound (`error_bound()`, evaluated only for candidates);
/// otherwise it is decided in f64 (`t_is_positive`).
#[inline(always)]
pub(super) fn hit_from(
    tri: &TriangleRecord,
    r: &TriangleRay,
    t_num: f32,
    det: f32,
    e: [f32; 3],
    t_max: f32,
    error_bound: impl FnOnce() -> f32,
) -> Option<TriangleHit> {
    // Make the determinant positive: t = T/det with both signs flipped.
    let (t_num_p, det_p) = if det < 0.0 {
        (-t_num, -det)
    } else {
        (t_num, det)
    };
    if !(t_num_p > 0.0 && t_num_p <= cut_bound(t_max, det_p)) {
        return None;
    }
    if t_num_p <= error_bound() && !t_is_positive(tri, r) {
        return None;
    }
    let t = t_num_p / det_p;
    (t < t_max).then_some(TriangleHit { t, e, det })
}

/// A bound on the rounding error of the computed T = Σ e_i·z_i·sz, from the largest sheared
/// |x|, |y| (`max_xy`), unscaled |z| (`max_z`) and edge function |e| (`max_e`) of the
/// triangle: the running error analysis of Pharr, Jakob & Humphreys, "Physically Based
/// Rendering" (3rd ed. §3.9.6, 4th ed. §6.8.6), redone for this test's order of operations:
/// - x = (v_x − o_x) − s_x·z: s_x = d_x·(1/d_z) carries γ(2), |s_x| ≤ 1 (z is the largest
///   direction component), so |Δx|, |Δy| ≤ γ(6)·(max_xy + 2·max_z) (one γ to spare);
/// - e = x_j·y_k − y_j·x_k: |Δe| ≤ 2·(γ(2)·max_xy² + |Δy|·max_xy + |Δx|·max_xy);
/// - z_s = (v_z − o_z)·s_z: |Δz_s| ≤ γ(3)·max|z_s|, and |z_s| ≤ max_z·|s_z|·(1 + γ(2));
/// - T, three products summed: |ΔT| ≤ 3·(γ(3)·max_e·max|z_s| + |Δe|·max|z_s| + |Δz_s|·max_e).
///
/// Doubled, to cover the rounding of this bound itself and the second-order terms. When
/// T > bound, the exact T has the computed sign: t > 0 without the f64 test.
#[inline(always)]
fn t_num_error_bound(max_xy: f32, max_z: f32, max_e: f32, sz: f32) -> f32 {
    t_num_error_bound_in(max_xy, max_z, max_e, sz.abs())
}

/// Arithmetic `t_num_error_bound_in` runs on: one f32, or sixteen lanes (`flat.rs`).
pub(super) trait BoundArithmetic:
    Copy + std::ops::Add<Output = Self> + std::ops::Mul<Output = Self>
{
    fn splat(v: f32) -> Self;
}

impl BoundArithmetic for f32 {
    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }
}

/// `t_num_error_bound` written once for scalars and lanes: the same operations in the same
/// order (no fused multiply-adds), so both give the same bits.
#[inline(always)]
pub(super) fn t_num_error_bound_in<T: BoundArithmetic>(
    max_xy: T,
    max_z: T,
    max_e: T,
    abs_sz: T,
) -> T {
    let c = T::splat;
    let max_zs = max_z * abs_sz * c(1.0 + gamma(2));
    let delta_xy = c(gamma(6)) * (max_xy + c(2.0) * max_z);
    let delta_e = c(2.0) * (c(gamma(2)) * max_xy * max_xy + c(2.0) * delta_xy * max_xy);
    let delta_zs = c(gamma(3)) * max_zs;
    c(2.0 * 3.0) * (c(gamma(3)) * max_e * max_zs + delta_e * max_zs + delta_zs * max_e)
}

/// The test with 4-wide SSE arithmetic (one lane per vertex); same results as
/// `intersect_scalar`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn intersect(tri: &TriangleRecord, r: &TriangleRay, t_max: f32) -> Option<TriangleHit> {
    use std::arch::x86_64::*;
    // Lane permutations: (2, 0, 1, 3) and (1, 2, 0, 3).
    const P201: i32 = 0b11_01_00_10;
    const P120: i32 = 0b11_00_10_01;
    // SAFETY: SSE2 is part of the x86_64 baseline; the loads read whole 16-byte aligned
    // rows of `tri` (`kx, ky, kz` < 3 by construction).
    unsafe {
        let rows = tri.rows.as_ptr() as *const f32;
        let ax = _mm_sub_ps(_mm_load_ps(rows.add(4 * r.kx)), _mm_set1_ps(r.ox));
        let ay = _mm_sub_ps(_mm_load_ps(rows.add(4 * r.ky)), _mm_set1_ps(r.oy));
        let z = _mm_sub_ps(_mm_load_ps(rows.add(4 * r.kz)), _mm_set1_ps(r.oz));
        let x = _mm_sub_ps(ax, _mm_mul_ps(_mm_set1_ps(r.sx), z));
        let y = _mm_sub_ps(ay, _mm_mul_ps(_mm_set1_ps(r.sy), z));
        let x201 = _mm_shuffle_ps::<P201>(x, x);
        let y120 = _mm_shuffle_ps::<P120>(y, y);
        let y201 = _mm_shuffle_ps::<P201>(y, y);
        let x120 = _mm_shuffle_ps::<P120>(x, x);
        // Lanes 0-2 only: the fourth lane holds identity bits, not a vertex.
        let lanes012 = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
        let e = _mm_and_ps(
            _mm_sub_ps(_mm_mul_ps(x201, y120), _mm_mul_ps(y201, x120)),
            lanes012,
        );
        let zero = _mm_setzero_ps();
        let neg = _mm_movemask_ps(_mm_cmplt_ps(e, zero)) & 7;
        let pos = _mm_movemask_ps(_mm_cmpgt_ps(e, zero)) & 7;
        if neg != 0 && pos != 0 {
            return None;
        }
        let lanes = |v: __m128| -> [f32; 4] {
            let mut a = [0.0f32; 4];
            _mm_storeu_ps(a.as_mut_ptr(), v);
            a
        };
        let three = |a: [f32; 4]| [a[0], a[1], a[2]];
        if (neg | pos) != 7 {
            // Some edge function is zero (or the inputs were not finite): rare, scalar path.
            let mut ev = three(lanes(e));
            return finish(
                tri,
                r,
                &mut ev,
                three(lanes(x)),
                three(lanes(y)),
                three(lanes(z)),
                t_max,
            );
        }
        // Horizontal sums as (l0 + l1) + (l2 + l3), lane 3 being zero.
        let hsum = |v: __m128| -> f32 {
            let s = _mm_add_ps(v, _mm_shuffle_ps::<0b10_11_00_01>(v, v)); // (l0+l1, _, l2+l3, _)
            _mm_cvtss_f32(_mm_add_ss(s, _mm_movehl_ps(s, s)))
        };
        let det = hsum(e);
        if det == 0.0 {
            return None;
        }
        let zs = _mm_mul_ps(z, _mm_set1_ps(r.sz));
        let t_num = hsum(_mm_and_ps(_mm_mul_ps(e, zs), lanes012));
        let ev = lanes(e);
        hit_from(tri, r, t_num, det, [ev[0], ev[1], ev[2]], t_max, || {
            // Largest |lane| of lanes 0-2 (lane 3 holds identity bits, not a vertex).
            let abs012 = _mm_castsi128_ps(_mm_set_epi32(0, 0x7fff_ffff, 0x7fff_ffff, 0x7fff_ffff));
            let hmax = |v: __m128| -> f32 {
                let v = _mm_and_ps(v, abs012);
                let m = _mm_max_ps(v, _mm_shuffle_ps::<0b10_11_00_01>(v, v));
                _mm_cvtss_f32(_mm_max_ss(m, _mm_movehl_ps(m, m)))
            };
            let xy = _mm_max_ps(_mm_and_ps(x, abs012), _mm_and_ps(y, abs012));
            t_num_error_bound(hmax(xy), hmax(z), hmax(e), r.sz)
        })
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn intersect(tri: &TriangleRecord, r: &TriangleRay, t_max: f32) -> Option<TriangleHit> {
    intersect_scalar(tri, r, t_max)
}

/// The hit point Σ b_i·v_i and a bound on its error.
///
/// Take as the exact surface point the convex combination with the exact normalised
/// barycentrics b_i = e_i / Σ e_j of the computed edge functions (non-negative, so it lies on
/// the triangle; whether it is exactly the ray's hit does not matter for offsetting). The
/// computed b̂_i went through the sum (two roundings, same-sign terms), a reciprocal and a
/// product: within γ(4) of b_i relatively. The sum Σ b̂_i·v_i adds three rounded products: γ(3)·Σ|b̂_i v_i|
/// more. So |p̂ − p| ≤ γ(4)·Σ|b_i v_i| + γ(3)·Σ|b̂_i v_i| ≤ γ(8)·Σ|b̂_i v_i| per coordinate;
/// γ(9) leaves room for replacing b by b̂ in the bound.
pub fn hit_point(v: [Vec3; 3], b: [f32; 3]) -> (Vec3, Vec3) {
    let (p, p_error) = hit_point_in(v.map(V3::from), b);
    (p.into(), p_error.into())
}

/// `hit_point` over `Real` (one hit, or sixteen in lanes).
#[inline(always)]
pub fn hit_point_in<T: Real>(v: [V3<T>; 3], b: [T; 3]) -> (V3<T>, V3<T>) {
    let w = [v[0] * b[0], v[1] * b[1], v[2] * b[2]];
    let p = w[0] + w[1] + w[2];
    let sum_abs = w[0].abs() + w[1].abs() + w[2].abs();
    (p, sum_abs * T::splat(gamma(9)))
}

/// The (shape, primitive) identity `TriangleRecord::new` stores in the fourth lanes of its
/// rows, from those three lanes' bits (per lane).
#[inline(always)]
pub(super) fn ids_lanes(rows: [U32x16; 3]) -> (U32x16, U32x16) {
    let payload = U32x16::splat(PAYLOAD);
    let [r0, r1, r2] = rows.map(|r| r & payload);
    let shape = r0 | (r2 & U32x16::splat(0x1ff)).shl::<23>();
    let primitive = r1 | r2.shr::<9>().shl::<23>();
    (shape, primitive)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(state: &mut u64) -> f32 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    #[test]
    fn simd_and_scalar_agree_bit_for_bit() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut hits = 0;
        for i in 0..200_000u32 {
            let mut v = || Vec3::new(rng(&mut s), rng(&mut s), rng(&mut s)) * 2.0 - 1.0;
            let tri = TriangleRecord::new([v(), v(), v()], i, 7 * i);
            let o = v() * 3.0;
            let mut d = v();
            if i % 7 == 0 {
                d.x = 0.0; // exercise exact-zero direction components
            }
            if d.length_squared() == 0.0 {
                continue;
            }
            let r = TriangleRay::new(o, d);
            let a = intersect(&tri, &r, f32::INFINITY);
            let b = intersect_scalar(&tri, &r, f32::INFINITY);
            assert_eq!(
                a.map(|h| (h.t.to_bits(), h.det.to_bits())),
                b.map(|h| (h.t.to_bits(), h.det.to_bits()))
            );
            hits += a.is_some() as u32;
        }
        assert!(hits > 1000);
    }

    #[test]
    fn error_bound_never_accepts_a_hit_behind_the_origin() {
        // Origins on or within a few ulps of the triangle's plane (where rounding decides
        // the sign of t), at several scales and distances from the world origin: every hit
        // the test reports must lie at exact t > 0 (the f64 plane-side test agrees), and
        // far from the plane the bound must let most hits skip that test.
        let mut s = 0x1234_5678_9abc_def1u64;
        let (mut hits, mut near_hits, mut skipped) = (0u32, 0u32, 0u32);
        for i in 0..400_000u32 {
            let scale = [1e-3f32, 1.0, 1e3, 1e5][(i % 4) as usize];
            let shift = Vec3::splat([0.0f32, 1.0, 100.0][(i % 3) as usize]) * scale;
            let v = |s: &mut u64| (Vec3::new(rng(s), rng(s), rng(s)) * 2.0 - 1.0) * scale;
            let tri_v = [v(&mut s) + shift, v(&mut s) + shift, v(&mut s) + shift];
            let tri = TriangleRecord::new(tri_v, 0, i);
            let near_plane = i % 2 == 0;
            let o = if near_plane {
                // A point of the plane (barycentrics outside [0,1] too), nudged a few ulps.
                let (b1, b2) = (rng(&mut s) * 3.0 - 1.0, rng(&mut s) * 3.0 - 1.0);
                let p = tri_v[0] + (tri_v[1] - tri_v[0]) * b1 + (tri_v[2] - tri_v[0]) * b2;
                let k = (rng(&mut s) * 7.0) as i32 - 3;
                p.to_array()
                    .map(|c| f32::from_bits((c.to_bits() as i32 + k) as u32))
                    .into()
            } else {
                v(&mut s) * 3.0 + shift
            };
            let d = v(&mut s);
            if d.length_squared() == 0.0 {
                continue;
            }
            let r = TriangleRay::new(o, d);
            if let Some(h) = intersect(&tri, &r, f32::INFINITY) {
                hits += 1;
                near_hits += near_plane as u32;
                assert!(
                    t_is_positive(&tri, &r),
                    "hit behind the origin: {o} {d} {h:?}"
                );
                let t_num_p = h.t * h.det.abs();
                let max_abs = |v: [f32; 3]| v[0].abs().max(v[1].abs()).max(v[2].abs());
                let bound = t_num_error_bound(
                    max_abs([0, 1, 2].map(|j| tri.rows[r.kx][j] - r.ox))
                        .max(max_abs([0, 1, 2].map(|j| tri.rows[r.ky][j] - r.oy))),
                    max_abs([0, 1, 2].map(|j| tri.rows[r.kz][j] - r.oz)),
                    max_abs(h.e),
                    r.sz,
                );
                skipped += (!near_plane && t_num_p > bound * 1.01) as u32;
            }
        }
        assert!(
            near_hits > 2_000,
            "{near_hits} hits from origins near the plane"
        );
        assert!(
            skipped as f64 > 0.9 * (hits - near_hits) as f64,
            "the bound let {skipped} of {} hits skip the f64 test",
            hits - near_hits
        );
    }

    #[test]
    fn hits_the_middle_and_reports_barycentrics() {
        let tri = TriangleRecord::new([Vec3::ZERO, Vec3::X, Vec3::Y], 3, 4);
        assert_eq!(tri.ids(), [3, 4]);
        let big = TriangleRecord::new([Vec3::ZERO; 3], u32::MAX, 0x9abc_def1);
        assert_eq!(big.ids(), [u32::MAX, 0x9abc_def1]);
        let o = Vec3::new(0.25, 0.5, 2.0);
        let r = TriangleRay::new(o, -Vec3::Z * 0.5);
        let h = intersect(&tri, &r, f32::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-6);
        let b = h.barycentrics();
        assert!(
            (b[0] - 0.25).abs() < 1e-6 && (b[1] - 0.25).abs() < 1e-6 && (b[2] - 0.5).abs() < 1e-6
        );
        assert!(intersect(&tri, &r, 3.9).is_none());
        // from behind, and pointing away
        let below = Vec3::new(o.x, o.y, -o.z);
        assert!(intersect(&tri, &TriangleRay::new(below, Vec3::Z), f32::INFINITY).is_some());
        assert!(intersect(&tri, &TriangleRay::new(o, Vec3::Z), f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edge_is_hit_exactly_once_or_twice_never_zero() {
        // Two triangles sharing the diagonal of a square; rays aimed exactly at the diagonal.
        let (a, b, c, d) = (
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(1.3, 0.1, 0.2),
            Vec3::new(1.2, 1.4, 0.5),
            Vec3::new(0.2, 1.1, 0.4),
        );
        let t1 = TriangleRecord::new([a, b, c], 0, 0);
        let t2 = TriangleRecord::new([a, c, d], 0, 1);
        let mut s = 7u64;
        for _ in 0..100_000 {
            let f = rng(&mut s);
            let target = a + (c - a) * f;
            let o = Vec3::new(rng(&mut s), rng(&mut s), 3.0 + rng(&mut s));
            let r = TriangleRay::new(o, target - o);
            let n = intersect(&t1, &r, f32::INFINITY).is_some() as u32
                + intersect(&t2, &r, f32::INFINITY).is_some() as u32;
            assert!(n >= 1, "ray slipped through the shared edge at f = {f}");
        }
    }
}
