//! Random permutations of 0..n evaluated one element at a time, in O(1) expected time and no
//! memory: a keyed bijection of the smallest power-of-two range 0..2^b ≥ n, applied again
//! while the result falls outside 0..n ("cycle walking"; the idea of Kensler 2013,
//! "Correlated multi-jittered sampling", §3, with a hash of mltbench's own). Following the
//! cycle of a bijection from an element of 0..n always returns to 0..n, so the result is a
//! permutation of 0..n; since 2^b < 2n, fewer than two steps are needed on average.
//!
//! The bijection on b bits is a few rounds of steps that are each invertible modulo 2^b:
//! XOR with a key, multiplication by an odd key, and x ^ (x >> s).

use super::independent::mix64;

/// Element `index` (< n) of the permutation of 0..n selected by `key`.
pub fn permute(index: u32, n: u32, key: u64) -> u32 {
    debug_assert!(index < n, "index {index} outside 0..{n}");
    if n <= 1 {
        return 0;
    }
    let bits = 32 - (n - 1).leading_zeros();
    let mask = if bits == 32 {
        u32::MAX
    } else {
        (1u32 << bits) - 1
    };
    let keys = [
        mix64(key),
        mix64(key ^ 0x9E37_79B9),
        mix64(key ^ 0x7F4A_7C15),
        mix64(key ^ 0xF39C_C060),
    ];
    let mut x = index;
    loop {
        x = bijection(x, mask, bits, &keys);
        if x < n {
            return x;
        }
    }
}

/// A keyed bijection of 0..=mask (mask = 2^bits − 1).
fn bijection(mut x: u32, mask: u32, bits: u32, keys: &[u64; 4]) -> u32 {
    // Shifts that mix the high bits into the low ones; x ^ (x >> s) is invertible for s ≥ 1.
    let shift = (bits / 2).max(1);
    for &k in keys {
        x ^= k as u32 & mask;
        x = x.wrapping_mul((k >> 32) as u32 | 1) & mask;
        x ^= x >> shift;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_a_permutation_for_every_size() {
        for n in (1..=70).chain([255, 256, 257, 1000, 1024, 4097]) {
            for key in 0..5u64 {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let p = permute(i, n, key);
                    assert!(p < n, "n = {n}: {p}");
                    assert!(!seen[p as usize], "n = {n}, key {key}: {p} twice");
                    seen[p as usize] = true;
                }
            }
        }
    }

    #[test]
    fn where_an_element_goes_is_close_to_uniform_over_keys() {
        // Over 16 000 keys, element 3 of a permutation of 0..16 lands on each position
        // about 1000 times (binomial σ ≈ 31); and keys give different permutations.
        let n = 16u32;
        let keys = 16_000u64;
        let mut counts = [0u32; 16];
        for key in 0..keys {
            counts[permute(3, n, key) as usize] += 1;
        }
        for (slot, &c) in counts.iter().enumerate() {
            assert!((c as f64 - 1000.0).abs() < 5.0 * 31.0, "slot {slot}: {c}");
        }
        let a: Vec<u32> = (0..n).map(|i| permute(i, n, 1)).collect();
        let b: Vec<u32> = (0..n).map(|i| permute(i, n, 2)).collect();
        assert_ne!(a, b);
    }
}
