//! Every lane operation against the scalar operation it stands for, lane by lane and bit
//! for bit, on inputs that include NaN, ±∞, ±0, subnormals and huge values.

#![allow(clippy::needless_range_loop)]

use super::*;

/// 16·K values: special ones first, then pseudo-random magnitudes of both signs.
fn inputs(seed: u64) -> Vec<f32> {
    let mut v = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        f32::NAN,
        -f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1e-40,
        -1e-40,
        f32::MAX,
        f32::MIN_POSITIVE,
        0.5,
        3.0e7,
        -2.5,
        0.1,
    ];
    let mut s = seed | 1;
    while v.len() < 16 * 64 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let mantissa = (s >> 40) as f32 / (1u64 << 24) as f32;
        let exponent = ((s >> 8) % 40) as i32 - 20;
        let sign = if s & 1 == 0 { 1.0 } else { -1.0 };
        v.push(sign * mantissa * 2f32.powi(exponent));
    }
    v
}

/// Vectors of 16 from `inputs`, paired with a shifted copy (so specials meet each other).
fn pairs() -> Vec<([f32; 16], [f32; 16])> {
    let a = inputs(7);
    let b = inputs(99);
    let mut out = Vec::new();
    for shift in [0, 1, 5, 16] {
        for k in 0..a.len() / 16 {
            let x: [f32; 16] = std::array::from_fn(|i| a[k * 16 + i]);
            let y: [f32; 16] = std::array::from_fn(|i| {
                if shift == 16 {
                    b[k * 16 + i]
                } else {
                    a[(k * 16 + i + shift) % a.len()]
                }
            });
            out.push((x, y));
        }
    }
    out
}

fn same_bits(got: [f32; 16], want: impl Fn(usize) -> f32, what: &str) {
    for i in 0..16 {
        let w = want(i);
        // Any NaN payload stands for NaN.
        let ok = got[i].to_bits() == w.to_bits() || (got[i].is_nan() && w.is_nan());
        assert!(ok, "{what}: lane {i}: got {:?}, want {:?}", got[i], w);
    }
}

/// The two sixteen-lane f32 types, for tests run on both.
trait LaneArray: Real<Mask = Mask16> {
    fn from_array(a: [f32; 16]) -> Self;
    fn to_array(self) -> [f32; 16];
}

impl LaneArray for portable::F32x16 {
    fn from_array(a: [f32; 16]) -> Self {
        portable::F32x16(a)
    }
    fn to_array(self) -> [f32; 16] {
        self.0
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
impl LaneArray for avx512::F32x16 {
    fn from_array(a: [f32; 16]) -> Self {
        avx512::F32x16::from_array(a)
    }
    fn to_array(self) -> [f32; 16] {
        avx512::F32x16::to_array(self)
    }
}

#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
))]
impl LaneArray for avx2::F32x16 {
    fn from_array(a: [f32; 16]) -> Self {
        avx2::F32x16::from_array(a)
    }
    fn to_array(self) -> [f32; 16] {
        avx2::F32x16::to_array(self)
    }
}

/// `T`'s arithmetic, comparisons and selects against the scalar operations.
fn f32_operations_equal_scalar_ones<T: LaneArray>() {
    for (a, b) in pairs() {
        let (x, y) = (T::from_array(a), T::from_array(b));
        same_bits((x + y).to_array(), |i| a[i] + b[i], "add");
        same_bits((x - y).to_array(), |i| a[i] - b[i], "sub");
        same_bits((x * y).to_array(), |i| a[i] * b[i], "mul");
        same_bits((x / y).to_array(), |i| a[i] / b[i], "div");
        same_bits((-x).to_array(), |i| -a[i], "neg");
        same_bits(x.sqrt().to_array(), |i| a[i].sqrt(), "sqrt");
        same_bits(x.abs().to_array(), |i| a[i].abs(), "abs");
        same_bits(
            x.copysign(y).to_array(),
            |i| a[i].copysign(b[i]),
            "copysign",
        );
        let gt = |p: f32, q: f32| if p > q { p } else { q };
        let lt = |p: f32, q: f32| if p < q { p } else { q };
        same_bits(x.max_gt(y).to_array(), |i| gt(a[i], b[i]), "max_gt");
        same_bits(x.min_lt(y).to_array(), |i| lt(a[i], b[i]), "min_lt");
        same_bits(
            x.step_towards(y).to_array(),
            |i| a[i].step_towards(b[i]),
            "step_towards",
        );
        let masks = [
            (x.lt(y), (|p, q| p < q) as fn(f32, f32) -> bool, "lt"),
            (x.le(y), |p, q| p <= q, "le"),
            (x.gt(y), |p, q| p > q, "gt"),
            (x.ge(y), |p, q| p >= q, "ge"),
            (x.eq(y), |p, q| p == q, "eq"),
            (x.ne(y), |p, q| p != q, "ne"),
            (x.is_finite(), |p, _| p.is_finite(), "is_finite"),
        ];
        for (m, f, what) in masks {
            for i in 0..16 {
                assert_eq!(
                    m.get(i),
                    f(a[i], b[i]),
                    "{what} lane {i}: {} {}",
                    a[i],
                    b[i]
                );
            }
        }
        same_bits(
            T::select(x.lt(y), x, y).to_array(),
            |i| if a[i] < b[i] { a[i] } else { b[i] },
            "select",
        );
    }
}

#[test]
fn f32_lane_operations_equal_scalar_ones() {
    f32_operations_equal_scalar_ones::<portable::F32x16>();
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    f32_operations_equal_scalar_ones::<avx512::F32x16>();
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        not(target_feature = "avx512f")
    ))]
    f32_operations_equal_scalar_ones::<avx2::F32x16>();
}

#[test]
fn lane_conversions_equal_scalar_ones() {
    for (a, _) in pairs() {
        let x = F32x16::from_array(a);
        for i in 0..16 {
            assert_eq!(x.is_nan().get(i), a[i].is_nan());
        }
        assert_eq!(x.to_u32().to_array(), a.map(|v| v as u32), "to_u32");
        assert_eq!(
            portable::F32x16(a).to_u32().0,
            a.map(|v| v as u32),
            "to_u32 (portable)"
        );
        let (lo, hi) = x.to_f64_halves();
        let (lo, hi) = (lo.to_array(), hi.to_array());
        for i in 0..16 {
            let w = if i < 8 { lo[i] } else { hi[i - 8] };
            assert!(w.to_bits() == (a[i] as f64).to_bits() || a[i].is_nan());
        }
        let wide_a: [f64; 16] = std::array::from_fn(|i| a[i] as f64 * 1.000_000_1);
        let lo = portable::F64x8(std::array::from_fn(|i| wide_a[i]));
        let hi = portable::F64x8(std::array::from_fn(|i| wide_a[8 + i]));
        let narrowed = portable::F32x16::from_f64_halves(lo, hi).0;
        same_bits(narrowed, |i| wide_a[i] as f32, "from_f64_halves (portable)");
        let native = F32x16::from_f64_halves(to_native_f64(lo), to_native_f64(hi));
        same_bits(native.to_array(), |i| wide_a[i] as f32, "from_f64_halves");
    }
}

/// A portable f64 vector in the build's backend.
fn to_native_f64(v: portable::F64x8) -> F64x8 {
    let a = v.0;
    let (lo, _) = F32x16::splat(0.0).to_f64_halves();
    // Build through arithmetic the backend has: 0 + a_i per lane via select on a mask.
    let mut out = lo;
    for (i, &x) in a.iter().enumerate() {
        out = F64x8::select(Mask8(1 << i), F64x8::splat(x), out);
    }
    out
}

#[test]
fn f64_lane_operations_equal_scalar_ones() {
    for (a, b) in pairs() {
        let (xa, _) = F32x16::from_array(a).to_f64_halves();
        let (xb, _) = F32x16::from_array(b).to_f64_halves();
        let (pa, pb) = (xa.to_array(), xb.to_array());
        let check = |got: [f64; 8], f: &dyn Fn(f64, f64) -> f64, what: &str| {
            for i in 0..8 {
                let w = f(pa[i], pb[i]);
                assert!(
                    got[i].to_bits() == w.to_bits() || (got[i].is_nan() && w.is_nan()),
                    "{what} lane {i}"
                );
            }
        };
        check((xa + xb).to_array(), &|p, q| p + q, "add");
        check((xa - xb).to_array(), &|p, q| p - q, "sub");
        check((xa * xb).to_array(), &|p, q| p * q, "mul");
        check((xa / xb).to_array(), &|p, q| p / q, "div");
        check(xa.sqrt().to_array(), &|p, _| p.sqrt(), "sqrt");
        check(
            xa.copysign(xb).to_array(),
            &|p, q| p.copysign(q),
            "copysign",
        );
        check((-xa).to_array(), &|p, _| -p, "neg");
        for i in 0..8 {
            assert_eq!(xa.eq(xb).get(i), pa[i] == pb[i]);
            assert_eq!(xa.lt(xb).get(i), pa[i] < pb[i]);
            assert_eq!(xa.le(xb).get(i), pa[i] <= pb[i]);
            assert_eq!(xa.gt(xb).get(i), pa[i] > pb[i]);
        }
    }
}

#[test]
fn integer_lane_operations_equal_scalar_ones() {
    let words = inputs(3);
    for k in 0..words.len() / 16 {
        let a: [u32; 16] = std::array::from_fn(|i| words[k * 16 + i].to_bits());
        let b: [u32; 16] = std::array::from_fn(|i| words[(k * 16 + i + 3) % words.len()].to_bits());
        let (x, y) = (U32x16::from_array(a), U32x16::from_array(b));
        assert_eq!(
            (x + y).to_array(),
            std::array::from_fn(|i| a[i].wrapping_add(b[i]))
        );
        assert_eq!(
            (x - y).to_array(),
            std::array::from_fn(|i| a[i].wrapping_sub(b[i]))
        );
        assert_eq!((x ^ y).to_array(), std::array::from_fn(|i| a[i] ^ b[i]));
        assert_eq!((x & y).to_array(), std::array::from_fn(|i| a[i] & b[i]));
        assert_eq!((x | y).to_array(), std::array::from_fn(|i| a[i] | b[i]));
        assert_eq!(x.shl::<3>().to_array(), a.map(|v| v << 3));
        assert_eq!(x.shr::<5>().to_array(), a.map(|v| v >> 5));
        assert_eq!(x.to_f32().to_array(), a.map(|v| v as f32));
        assert_eq!(
            (x * y).to_array(),
            std::array::from_fn(|i| a[i].wrapping_mul(b[i]))
        );
        assert_eq!(x.min(y).to_array(), std::array::from_fn(|i| a[i].min(b[i])));
        let (lo, hi) = x.to_u64_halves();
        let wide: Vec<u64> = lo.to_array().into_iter().chain(hi.to_array()).collect();
        assert_eq!(wide, a.map(|v| v as u64).to_vec());
        assert_eq!(x.max(y).to_array(), std::array::from_fn(|i| a[i].max(b[i])));
        let m = Mask16(a[0] as u16);
        let (mut packed, mut packed_int) = ([f32::NAN; 20], [7u32; 20]);
        F32x16::from_array(std::array::from_fn(|i| i as f32)).compress_store(m, &mut packed);
        x.compress_store(m, &mut packed_int);
        for (k, i) in m.lanes().enumerate() {
            assert_eq!((packed[k], packed_int[k]), (i as f32, a[i]));
        }
        // Sixteen places at most are written.
        assert!(packed[16..].iter().all(|p| p.is_nan()) && packed_int[16..] == [7; 4]);
        let f = F32x16::from_array(std::array::from_fn(|i| i as f32 * 0.5));
        let p = f.permute(x).to_array();
        for i in 0..16 {
            assert_eq!(p[i], (a[i] % 16) as f32 * 0.5);
        }
        let p8 = f.permute_low8(x).to_array();
        let p8_portable = portable::F32x16(f.to_array())
            .permute_low8(portable::U32x16(a))
            .0;
        for i in 0..16 {
            assert_eq!(
                (p8[i], p8_portable[i]),
                ((a[i] % 8) as f32 * 0.5, (a[i] % 8) as f32 * 0.5)
            );
        }
        for i in 0..16 {
            assert_eq!(x.lt(y).get(i), a[i] < b[i]);
            assert_eq!(x.eq(y).get(i), a[i] == b[i]);
        }
        let wa: [u64; 8] = std::array::from_fn(|i| (a[i] as u64) << 32 | b[i + 8] as u64);
        let wb: [u64; 8] = std::array::from_fn(|i| (b[i] as u64) << 29 ^ a[i + 8] as u64);
        let (p, q) = (U64x8::from_array(wa), U64x8::from_array(wb));
        assert_eq!(
            (p + q).to_array(),
            std::array::from_fn(|i| wa[i].wrapping_add(wb[i]))
        );
        assert_eq!((p ^ q).to_array(), std::array::from_fn(|i| wa[i] ^ wb[i]));
        assert_eq!(
            (p * q).to_array(),
            std::array::from_fn(|i| wa[i].wrapping_mul(wb[i]))
        );
        assert_eq!(p.shl::<17>().to_array(), wa.map(|v| v << 17));
        assert_eq!(p.shr::<11>().to_array(), wa.map(|v| v >> 11));
        assert_eq!(p.rotl::<45>().to_array(), wa.map(|v| v.rotate_left(45)));
        let m = Mask8(0b1010_0110);
        let sel = U64x8::select(m, p, q).to_array();
        for i in 0..8 {
            assert_eq!(sel[i], if m.get(i) { wa[i] } else { wb[i] });
        }
    }
}

#[test]
fn gathers_read_their_lanes_and_clamp_indices() {
    let idx = U32x16::from_array(std::array::from_fn(|i| (i as u32 * 3) % 13));
    let m = Mask16(0b1011_0111_1101_1110);
    // Tables permuted in one register (at most sixteen entries) and gathered (more).
    for n in [1usize, 10, 16, 17, 40] {
        let table: Vec<f32> = (0..n).map(|i| i as f32 * 1.5).collect();
        let ints: Vec<u32> = (0..n as u32).map(|i| i * 7).collect();
        let got = F32x16::gather(&table, idx, m).to_array();
        let got_int = U32x16::gather(&ints, idx, m).to_array();
        for i in 0..16 {
            let j = ((i * 3) % 13).min(n - 1);
            let (want, want_int) = if m.get(i) {
                (table[j], ints[j])
            } else {
                (0.0, 0)
            };
            assert_eq!(
                (got[i], got_int[i]),
                (want, want_int),
                "{n} entries, lane {i}"
            );
        }
    }
    let wide: Vec<f64> = (0..10).map(|i| i as f64 * 0.25 - 1.0).collect();
    let (idx_lo, _) = idx.to_u64_halves();
    let (m_lo, _) = m.halves();
    let got = F64x8::gather(&wide, idx_lo, m_lo).to_array();
    let portable = portable::F64x8::gather(&wide, portable::U64x8(idx_lo.to_array()), m_lo);
    for i in 0..8 {
        let want = if m.get(i) {
            wide[((i * 3) % 13).min(9)]
        } else {
            0.0
        };
        assert_eq!(got[i], want, "f64 lane {i}");
        assert_eq!(portable.0[i], want, "f64 lane {i} (portable)");
    }
}

#[test]
fn masks_count_iterate_and_split() {
    let m = Mask16(0b1000_0000_0010_0101);
    assert_eq!(m.lanes().collect::<Vec<_>>(), vec![0, 2, 5, 15]);
    assert_eq!(m.count(), 4);
    assert!(m.any() && !m.all() && !m.none());
    assert_eq!(Mask16::first(3), Mask16(0b111));
    assert_eq!(Mask16::first(16), Mask16::ALL);
    let (lo, hi) = m.halves();
    assert_eq!(Mask16::from_halves(lo, hi), m);
    let mut n = Mask16::NONE;
    n.set(4, true);
    n.set(4, false);
    n.set(9, true);
    assert_eq!(n, Mask16(1 << 9));
}

#[test]
fn vectors_equal_glam_bit_for_bit() {
    let vals = inputs(11);
    for k in 0..vals.len() / 6 {
        let a = glam::Vec3::new(vals[6 * k], vals[6 * k + 1], vals[6 * k + 2]);
        let b = glam::Vec3::new(vals[6 * k + 3], vals[6 * k + 4], vals[6 * k + 5]);
        let (va, vb) = (V3::from(a), V3::from(b));
        let eq = |x: f32, y: f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
        let eqv = |x: V3<f32>, y: glam::Vec3| eq(x.x, y.x) && eq(x.y, y.y) && eq(x.z, y.z);
        assert!(eq(va.dot(vb), a.dot(b)));
        assert!(eqv(va.cross(vb), a.cross(b)));
        assert!(eq(va.length(), a.length()));
        if a.length() > 0.0 && a.length().is_finite() {
            assert!(eqv(va.normalize(), a.normalize()));
        }
        assert!(eqv(va.div_scalar(vb.x), a / b.x));
    }
}
