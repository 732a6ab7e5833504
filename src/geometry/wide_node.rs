//! The 8-wide BVH node that traversal reads, and its ray test.
//!
//! The tree is built in the compressed layout of Ylitie, Karras & Laine (HPG 2017:
//! `cwbvh.rs`), whose child boxes are 8-bit offsets from a per-node origin. Decoding them
//! costs every node visit a chain of dependent operations (the node's scale and origin
//! into per-ray slab constants, the bytes into floats) before the first comparison, and a
//! single ray's traversal waits on that chain at every level. Here each node's boxes are
//! decoded once, at build time, into f32 planes rounded outward, so the ray test is a
//! subtraction and a multiplication per plane (the layout of a wide node in Embree, Wald et
//! al. 2014). Measured on the development machine (`pt`, 2 threads): water +9%, 11.5k
//! triangles +11%, 330k triangles unchanged; docs/performance.md has the figures.
//!
//! Each node takes four cache lines (the compressed one 80 bytes): what it saves is
//! latency, which matters while a tree fits in the caches.

use obvhs::cwbvh::node::CwBvhNode;

use super::bvh::TraversalRay;
use super::offset::gamma;

/// One node: its children's boxes and how to find the children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNode {
    /// Rows min x, max x, min y, max y, min z, max z; column c is child slot c. Each plane
    /// is its exact compressed plane rounded outward, so a box contains its subtree.
    pub planes: [[f32; 8]; 6],
    /// Per slot, as `CwBvhNode::child_meta`: 0 for an empty slot; an internal child
    /// `0b001_11sss` (slot s); a leaf its triangle count in unary (high 3 bits) and the
    /// offset of its first triangle from `primitive_base` (low 5 bits).
    pub meta: [u8; 8],
    /// Index of the first internal child (the others follow in slot order).
    pub child_base: u32,
    /// Record index the leaves' offsets count from.
    pub primitive_base: u32,
    /// Bit s set when slot s is an internal child.
    pub imask: u8,
}

// The ray's near and far planes along each axis are rows 2k and 2k + 1 (swapped for a
// negative direction), the whole node four cache lines.
const _: () = assert!(std::mem::size_of::<WideNode>() == 256);

impl WideNode {
    /// The node of compressed node `node`, its planes p + q·2^e computed exactly in f64
    /// and rounded outward to f32.
    pub fn decode(node: &CwBvhNode) -> WideNode {
        let q = quantised_rows(node);
        let planes = std::array::from_fn(|row| {
            let k = row / 2;
            let scale = f32::from_bits((node.e[k] as u32) << 23) as f64;
            std::array::from_fn(|c| {
                let exact = node.p[k] as f64 + q[row][c] as f64 * scale;
                if row % 2 == 0 {
                    round_down(exact)
                } else {
                    round_up(exact)
                }
            })
        });
        WideNode {
            planes,
            meta: node.child_meta,
            child_base: node.child_base_idx,
            primitive_base: node.primitive_base_idx,
            imask: node.imask,
        }
    }

    /// The traversal's hit mask for the ray's segment (0, t_max): internal children set bit
    /// 24 + (slot ^ octant), leaves set their triangles' bits (`hit_bits`).
    #[inline(always)]
    pub fn hitmask(&self, ray: &TraversalRay, t_max: f32) -> u32 {
        #[cfg(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        ))]
        {
            self.hitmask_avx2(ray, t_max)
        }
        #[cfg(not(all(
            target_arch = "x86_64",
            target_feature = "avx2",
            target_feature = "fma"
        )))]
        {
            self.hitmask_scalar(ray, t_max)
        }
    }

    /// `hitmask` one child at a time: builds without AVX2, and the reference for the
    /// vector version in tests.
    pub fn hitmask_scalar(&self, ray: &TraversalRay, t_max: f32) -> u32 {
        let (near, far) = ray.plane_rows();
        let mut hitmask = 0;
        for c in 0..8 {
            // In the vector version's order, NaN handled as its instructions do.
            let t = |row: usize, k: usize| (self.planes[row][c] - ray.o[k]) * ray.inv_d[k];
            let t_enter = max(max(t(near[0], 0), t(near[1], 1)), max(t(near[2], 2), 0.0));
            let t_exit = min(min(t(far[0], 0), t(far[1], 1)), min(t(far[2], 2), t_max));
            if t_enter <= t_exit * EXIT_SCALE {
                hitmask |= hit_bits(self.meta[c], ray.octant());
            }
        }
        hitmask
    }

    /// `hitmask` with the eight children in one AVX2 register, the same operations lane
    /// by lane as `hitmask_scalar`.
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ))]
    #[inline(always)]
    fn hitmask_avx2(&self, ray: &TraversalRay, t_max: f32) -> u32 {
        use std::arch::x86_64::*;
        let (near, far) = ray.plane_rows();
        // SAFETY: AVX2 is enabled for this build (cfg above); each row is 32 bytes at a
        // 32-byte-aligned offset of a 64-byte-aligned node, and `meta` is 8 bytes.
        unsafe {
            let t = |row: usize, k: usize| {
                let plane = _mm256_load_ps(self.planes[row].as_ptr());
                _mm256_mul_ps(
                    _mm256_sub_ps(plane, _mm256_set1_ps(ray.o[k])),
                    _mm256_set1_ps(ray.inv_d[k]),
                )
            };
            let t_enter = _mm256_max_ps(
                _mm256_max_ps(t(near[0], 0), t(near[1], 1)),
                _mm256_max_ps(t(near[2], 2), _mm256_setzero_ps()),
            );
            let t_exit = _mm256_min_ps(
                _mm256_min_ps(t(far[0], 0), t(far[1], 1)),
                _mm256_min_ps(t(far[2], 2), _mm256_set1_ps(t_max)),
            );
            let hit = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(
                t_enter,
                _mm256_mul_ps(t_exit, _mm256_set1_ps(EXIT_SCALE)),
            ));
            // `hit_bits` of every slot: internal children (m & 0x18 == 0x18) place their bit
            // at (m ^ octant) & 31, leaves their unary count at m & 31.
            let m = _mm256_cvtepu8_epi32(_mm_loadl_epi64(self.meta.as_ptr() as *const __m128i));
            let set1 = _mm256_set1_epi32;
            let inner = _mm256_cmpeq_epi32(_mm256_and_si256(m, set1(0x18)), set1(0x18));
            let octant = _mm256_and_si256(inner, set1(ray.octant() as i32));
            let index = _mm256_and_si256(_mm256_xor_si256(m, octant), set1(0x1f));
            let bits = _mm256_and_si256(_mm256_srli_epi32::<5>(m), set1(7));
            let v = _mm256_and_si256(_mm256_sllv_epi32(bits, index), hit);
            let v = _mm_or_si128(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
            let v = _mm_or_si128(v, _mm_shuffle_epi32::<0b01_00_11_10>(v));
            let v = _mm_or_si128(v, _mm_shuffle_epi32::<0b10_11_00_01>(v));
            _mm_cvtsi128_si32(v) as u32
        }
    }
}

/// A compressed node's 8-bit planes in `WideNode::planes`' row order.
fn quantised_rows(node: &CwBvhNode) -> [[u8; 8]; 6] {
    [
        node.child_min_x,
        node.child_max_x,
        node.child_min_y,
        node.child_max_y,
        node.child_min_z,
        node.child_max_z,
    ]
}

/// What a hit child adds to the hit mask, from its meta byte m: a leaf sets its triangle
/// count (unary, m >> 5) of bits from its first triangle's offset (m & 31); an internal
/// child (m = 0b001_11sss for slot s) sets one bit (m >> 5 = 1) at 24 + (s ^ octant) =
/// (m ^ octant) & 31; an empty slot (m = 0) sets none.
#[inline(always)]
fn hit_bits(m: u8, octant: u32) -> u32 {
    let m = m as u32;
    let octant = if m & 0x18 == 0x18 { octant } else { 0 };
    ((m >> 5) & 7) << ((m ^ octant) & 31)
}

/// The slab test's allowance for rounding (Ize, "Robust BVH Ray Traversal", JCGT 2013).
/// Each computed distance fl(fl(plane − o)·fl(1/d)) is the exact one times (1 + ε) with
/// |ε| ≤ γ(3), whatever the plane: one subtraction, one reciprocal, one product, no
/// cancellation between separately rounded terms. If the exact segment meets a box at
/// some t* ≥ 0, every computed entry distance is at most t*(1 + γ(3)) (negative ones are
/// below the 0 they are compared with) and every computed exit distance at least
/// t*(1 − γ(3)), t_max included (exact, ≥ t*). So t_enter ≤ t_exit·(1 + γ(3))/(1 − γ(3)),
/// which t_exit·EXIT_SCALE exceeds even after its own rounding (2γ(5) > 2γ(3)/(1 − γ(3)) + u).
/// An exit distance below zero only grows more negative, and no such box is met.
///
/// A direction component of ±0 has reciprocal ±∞: a plane the origin is off gives ±∞ (the
/// exact distance of a parallel ray), one the origin lies on gives NaN. The max and min
/// chains return their second operand when either is NaN, so a NaN distance drops out,
/// together with at most one other of its chain: fewer constraints, never a missed box;
/// the 0 and t_max that close the chains are never NaN, so neither are t_enter and t_exit.
pub(super) const EXIT_SCALE: f32 = 1.0 + 2.0 * gamma(5);

/// `maxps`'s maximum: `b` when either is NaN (so a NaN first operand is ignored).
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `minps`'s minimum: `b` when either is NaN.
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The largest f32 at or below `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// The smallest f32 at or above `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::bvh::{TriangleBvh, TriangleList};
    use glam::Vec3;

    /// A tree over 2,000 small random triangles, and a uniform number generator.
    fn random_tree(next: &mut impl FnMut() -> f32) -> TriangleBvh {
        let mut tris = Vec::new();
        for _ in 0..2000 {
            let c = Vec3::new(next(), next(), next()) * 10.0;
            let mut v = || c + Vec3::new(next(), next(), next()) * 0.5;
            tris.push([v(), v(), v()]);
        }
        let ids: Vec<[u32; 2]> = (0..tris.len() as u32).map(|i| [0, i]).collect();
        TriangleBvh::build(&TriangleList {
            vertices: &tris,
            ids: &ids,
        })
    }

    fn xorshift(mut s: u64) -> impl FnMut() -> f32 {
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn vector_hitmask_matches_scalar() {
        let mut next = xorshift(12345);
        let bvh = random_tree(&mut next);
        for _ in 0..2000 {
            let o = Vec3::new(next(), next(), next()) * 12.0 - 1.0;
            let d = (Vec3::new(next(), next(), next()) - 0.5).normalize();
            let r = TraversalRay::new(o, d);
            for node in bvh.wide_nodes() {
                let t_max = next() * 20.0;
                assert_eq!(node.hitmask(&r, t_max), node.hitmask_scalar(&r, t_max));
            }
        }
    }

    /// Outward rounding: every decoded plane bounds its exact compressed plane.
    #[test]
    fn decoded_boxes_contain_the_compressed_ones() {
        let mut next = xorshift(777);
        let mut node = CwBvhNode {
            p: Vec3::new(-3.7, 1e-3, 12345.678),
            e: [120, 127, 135],
            imask: 0,
            child_base_idx: 0,
            primitive_base_idx: 0,
            child_meta: [0; 8],
            child_min_x: [0; 8],
            child_max_x: [0; 8],
            child_min_y: [0; 8],
            child_max_y: [0; 8],
            child_min_z: [0; 8],
            child_max_z: [0; 8],
        };
        for _ in 0..200 {
            let mut bytes = || std::array::from_fn(|_| (next() * 256.0) as u8);
            (node.child_min_x, node.child_max_x) = (bytes(), bytes());
            (node.child_min_y, node.child_max_y) = (bytes(), bytes());
            (node.child_min_z, node.child_max_z) = (bytes(), bytes());
            let wide = WideNode::decode(&node);
            let q = quantised_rows(&node);
            for (row, (q_row, planes)) in q.iter().zip(&wide.planes).enumerate() {
                let k = row / 2;
                let scale = 2f64.powi(node.e[k] as i32 - 127);
                for (&q, &plane) in q_row.iter().zip(planes) {
                    let exact = node.p[k] as f64 + q as f64 * scale;
                    // Outward, and by at most one float.
                    let gap = (plane as f64 - exact).abs();
                    assert!(gap < 1e-6 * exact.abs().max(1.0), "{plane} for {exact}");
                    if row % 2 == 0 {
                        assert!(plane as f64 <= exact, "min plane {plane} above {exact}");
                    } else {
                        assert!(plane as f64 >= exact, "max plane {plane} below {exact}");
                    }
                }
            }
        }
    }

    /// The test never drops a box the exact segment meets: against a slab test in f64 on
    /// the same planes, over rays that graze box faces (origins on planes, directions
    /// along axes and nearly so, segments ending at a face).
    #[test]
    fn no_box_the_segment_meets_is_dropped() {
        let mut next = xorshift(99);
        let bvh = random_tree(&mut next);
        let mut tested = 0;
        for node in bvh.wide_nodes().iter().take(40) {
            for c in 0..8 {
                if node.meta[c] == 0 {
                    continue;
                }
                let lo = Vec3::new(node.planes[0][c], node.planes[2][c], node.planes[4][c]);
                let hi = Vec3::new(node.planes[1][c], node.planes[3][c], node.planes[5][c]);
                for _ in 0..200 {
                    // A point on the box's surface or inside, a ray through it from afar.
                    let u = Vec3::new(next(), next(), next());
                    let mut p = lo + (hi - lo) * u;
                    let face = (next() * 3.0) as usize % 3;
                    p[face] = if next() < 0.5 { lo[face] } else { hi[face] };
                    let mut d = (Vec3::new(next(), next(), next()) - 0.5).normalize();
                    if next() < 0.3 {
                        d[face] *= 1e-6;
                        d = d.normalize();
                    }
                    let back = 1.0 + 20.0 * next();
                    let o = p - d * back;
                    let r = TraversalRay::new(o, d);
                    let t_max = if next() < 0.5 { f32::INFINITY } else { back };
                    if exact_slab(lo, hi, o, d, t_max) {
                        tested += 1;
                        let mask = node.hitmask(&r, t_max);
                        let bits = hit_bits(node.meta[c], r.octant());
                        assert_eq!(mask & bits, bits, "child {c} dropped: o {o} d {d}");
                    }
                }
            }
        }
        assert!(tested > 10_000, "{tested} rays met their boxes");
    }

    /// The f64 slab test of the segment (0, t_max) of o + t·d against [lo, hi].
    fn exact_slab(lo: Vec3, hi: Vec3, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let (mut t0, mut t1) = (0.0f64, t_max as f64);
        for k in 0..3 {
            let (o, d) = (o[k] as f64, d[k] as f64);
            let (l, h) = (lo[k] as f64, hi[k] as f64);
            if d == 0.0 {
                if o < l || o > h {
                    return false;
                }
                continue;
            }
            let (a, b) = ((l - o) / d, (h - o) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        t0 <= t1
    }
}
