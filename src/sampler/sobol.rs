//! The first four dimensions of Sobol's sequence, Owen-scrambled.
//!
//! Sobol' (1967): coordinate d of point i is the XOR of the direction numbers v_{d,k} over
//! the set bits k of i. Dimension 0 has v_k = 2^-(k+1) (the van der Corput sequence, i.e.
//! the bit-reversed index); dimension 1 uses the primitive polynomial x + 1, whose
//! recurrence m_k = 2·m_{k-1} ⊕ m_{k-1} with m_1 = 1 gives v_k = v_{k-1} ⊕ (v_{k-1} >> 1).
//! Together they form a (0,2)-sequence in base 2: every aligned block of 2^m points is a
//! (0,m,2)-net, one point in each elementary interval of area 2^-m.
//!
//! Owen (1995) nested uniform scrambling flips each binary digit of a coordinate by a
//! random bit chosen per node of the digit tree, i.e. per prefix of the digits above it.
//! As in Burley (2020, "Practical hash-based Owen scrambling", JCGT 9(4)) the random bits
//! come from a hash instead of a stored tree; here the hash is evaluated per node (one per
//! digit), which is the exact scramble rather than Laine–Karras' one-multiply
//! approximation. A scramble permutes the elementary intervals of every level among
//! themselves, so the net property survives.
//!
//! Dimensions 2 and 3 (the lens samples of camera estimators, `pixel_samples`) use the next
//! primitive polynomials in Joe & Kuo's (2008) ordering, x² + x + 1 and x³ + x + 1, with
//! their initial direction numbers m = (1, 3) and m = (1, 3, 1); the remaining numbers follow
//! Bratley & Fox's (1988) recurrence. On their own, an aligned block of 2^m points of these
//! two dimensions is a (t,m,2)-net with t = 0 for m = 1 and 4, t = 1 for m = 2 and
//! 5 ≤ m ≤ 10 (two points in each elementary interval of area 2^(1−m)), t = 2 for m = 3 and
//! m = 11, 12 (tests/lens_samples.rs checks m ≤ 12). Dimensions 0–3 of one point are a 4D Sobol' point,
//! so pixel and lens samples taken from the same index are stratified jointly (a (t,m,4)-net
//! with t ≤ 3, the sum of the polynomials' degrees minus one).

use glam::Vec2;

use super::independent::{hash_words, mix64};
use super::pattern::Pattern;

/// The unscrambled first two coordinates of Sobol point `index`, as 32-bit fixed point.
pub fn sobol_2d(index: u32) -> [u32; 2] {
    let mut y = 0u32;
    let mut v = 1u32 << 31;
    let mut bits = index;
    while bits != 0 {
        if bits & 1 == 1 {
            y ^= v;
        }
        v ^= v >> 1;
        bits >>= 1;
    }
    [index.reverse_bits(), y]
}

/// Direction numbers v_k = m_k / 2^(k+1) (32-bit fixed point, k = 0..31) of the primitive
/// polynomial of degree `s` with inner coefficients `a` (most significant = x^(s−1)) and
/// initial numbers `m` (the first `s` used), by Bratley & Fox's recurrence
/// m_k = 2 a_1 m_{k−1} ⊕ 4 a_2 m_{k−2} ⊕ … ⊕ 2^s m_{k−s} ⊕ m_{k−s}.
const fn direction_numbers(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut mk = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        mk[k] = if k < s {
            m[k]
        } else {
            let mut new = mk[k - s] ^ (mk[k - s] << s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    new ^= mk[k - j] << j;
                }
                j += 1;
            }
            new
        };
        k += 1;
    }
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = mk[k] << (31 - k);
        k += 1;
    }
    v
}

/// Dimension 2: x² + x + 1.
const DIRECTIONS_2: [u32; 32] = direction_numbers(2, 1, [1, 3, 0]);
/// Dimension 3: x³ + x + 1.
const DIRECTIONS_3: [u32; 32] = direction_numbers(3, 1, [1, 3, 1]);

/// The unscrambled coordinates 2 and 3 of Sobol point `index`, as 32-bit fixed point.
pub fn sobol_dims_2_3(index: u32) -> [u32; 2] {
    let mut out = [0u32; 2];
    let mut bits = index;
    let mut k = 0;
    while bits != 0 {
        if bits & 1 == 1 {
            out[0] ^= DIRECTIONS_2[k];
            out[1] ^= DIRECTIONS_3[k];
        }
        bits >>= 1;
        k += 1;
    }
    out
}

/// Owen's nested uniform scramble of a 32-digit binary fraction: digit k (counted from
/// the most significant) is flipped by a hashed bit of (seed, the k digits above it).
pub fn owen_scramble(x: u32, seed: u64) -> u32 {
    let mut out = x;
    for k in 0..32u32 {
        // The node of the digit tree: the k-digit prefix with a leading 1 marking its
        // length, so prefixes of different lengths never collide.
        let prefix = x.checked_shr(32 - k).unwrap_or(0) as u64;
        let node = (1u64 << k) | prefix;
        let flip = (mix64(seed ^ mix64(node)) >> 63) as u32;
        out ^= flip << (31 - k);
    }
    out
}

/// A 32-bit fixed-point fraction as an f32 in [0, 1) (its top 24 bits, exactly).
pub fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The first `n` Sobol points, unscrambled (a (0,m,2)-net when n = 2^m).
pub fn unscrambled_points(n: usize) -> Vec<Vec2> {
    (0..n as u32)
        .map(|i| {
            let [x, y] = sobol_2d(i);
            Vec2::new(to_unit(x), to_unit(y))
        })
        .collect()
}

/// The first `n` Sobol points, each dimension Owen-scrambled with its own seed.
pub fn points(n: usize, seed: u64) -> Vec<Vec2> {
    let sx = hash_words(&[seed, Pattern::Sobol as u64, 0]);
    let sy = hash_words(&[seed, Pattern::Sobol as u64, 1]);
    (0..n as u32)
        .map(|i| {
            let [x, y] = sobol_2d(i);
            Vec2::new(to_unit(owen_scramble(x, sx)), to_unit(owen_scramble(y, sy)))
        })
        .collect()
}
