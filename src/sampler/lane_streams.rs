//! Sixteen independent random streams side by side: lane i continues the Xoshiro256++
//! stream of one `IndependentSampler` (its `state`), drawing the same numbers in the same
//! order, so a path traced in a lane sees exactly the random numbers it would see alone.
//!
//! Xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
//! ACM TOMS 2021): output rotl(s0 + s3, 23) + s0, then the xoshiro256 state transition. A
//! draw advances only the lanes of its mask; the others keep their state, as a path that
//! draws nothing at that step would.

use super::independent::HASH_START;
use crate::math::lanes::{F32x16, Mask16, U32x16, U64x8};

const _: () = assert!(std::mem::size_of::<[[U64x8; 2]; 4]>() == 64 * 8);

/// The states of sixteen Xoshiro256++ generators: word k of lanes 0–7 in `s[k][0]`, of
/// lanes 8–15 in `s[k][1]`.
#[derive(Clone, Copy)]
pub struct LaneStreams {
    s: [[U64x8; 2]; 4],
}

impl Default for LaneStreams {
    fn default() -> Self {
        LaneStreams {
            s: [[U64x8::splat(0); 2]; 4],
        }
    }
}

impl LaneStreams {
    /// The states as plain words: word k of lane i at 16k + i (lanes 0–7 are `s[k][0]`,
    /// 8–15 `s[k][1]`). A lane leaving for scalar code (and coming back) touches four words
    /// in memory this way, instead of four whole vectors taken apart and rebuilt.
    #[inline(always)]
    fn words(&self) -> &[u64; 64] {
        // SAFETY: `s` is 4·2 `U64x8`s of eight u64 each, without padding (checked below in
        // both backends), so it has the size of [u64; 64] and at least its alignment.
        unsafe { &*(&self.s as *const [[U64x8; 2]; 4] as *const [u64; 64]) }
    }

    #[inline(always)]
    fn words_mut(&mut self) -> &mut [u64; 64] {
        // SAFETY: as `words`; every bit pattern is a valid u64 and a valid `U64x8`.
        unsafe { &mut *(&mut self.s as *mut [[U64x8; 2]; 4] as *mut [u64; 64]) }
    }

    /// Lane `lane` continues the stream with state `state` (`IndependentSampler::state`).
    #[inline]
    pub fn set_lane(&mut self, lane: usize, state: [u64; 4]) {
        let words = self.words_mut();
        for (k, &word) in state.iter().enumerate() {
            words[16 * k + lane] = word;
        }
    }

    /// Lanes `m` start the streams of samples `index` of pixels (x, y) (all per lane), as
    /// `IndependentSampler::start_pixel_sample` seeds them: the hash of (seed, x, y, index)
    /// expanded by SplitMix64 into the four state words.
    pub fn start_pixel_samples(
        &mut self,
        m: Mask16,
        seed: u64,
        x: U32x16,
        y: U32x16,
        index: U32x16,
    ) {
        let (x_lo, x_hi) = x.to_u64_halves();
        let (y_lo, y_hi) = y.to_u64_halves();
        let (i_lo, i_hi) = index.to_u64_halves();
        let (m_lo, m_hi) = m.halves();
        let halves = [(x_lo, y_lo, i_lo, m_lo), (x_hi, y_hi, i_hi, m_hi)];
        for (h, (px, py, pi, keep)) in halves.into_iter().enumerate() {
            let key = hash_words_lanes(&[U64x8::splat(seed), px, py, pi]);
            // SplitMix64 seeded with `key` (rand_xoshiro's `seed_from_u64`): word k is the
            // finaliser of key + (k + 1)·φ, which `mix64` of key + k·φ is.
            let mut x = key;
            for k in 0..4 {
                self.s[k][h] = U64x8::select(keep, mix64_lanes(x), self.s[k][h]);
                x = x + U64x8::splat(GOLDEN_GAMMA);
            }
        }
    }

    /// The state of lane `lane`'s stream.
    #[inline]
    pub fn lane(&self, lane: usize) -> [u64; 4] {
        let words = self.words();
        std::array::from_fn(|k| words[16 * k + lane])
    }

    #[cfg(test)]
    fn clone_states(&self) -> [[u64; 4]; 16] {
        std::array::from_fn(|i| self.lane(i))
    }

    /// The next 64-bit output of the lanes of `m` (other lanes: unspecified), advancing
    /// only them.
    #[inline(always)]
    pub fn next_u64(&mut self, m: Mask16) -> [U64x8; 2] {
        let (m_lo, m_hi) = m.halves();
        [self.step(0, m_lo.0), self.step(1, m_hi.0)]
    }

    /// One Xoshiro256++ step of half `h`, kept in the lanes of `m`.
    #[inline(always)]
    fn step(&mut self, h: usize, m: u8) -> U64x8 {
        let [s0, s1, s2, s3] = [self.s[0][h], self.s[1][h], self.s[2][h], self.s[3][h]];
        let result = (s0 + s3).rotl::<23>() + s0;
        let t = s1.shl::<17>();
        let s2 = s2 ^ s0;
        let s3 = s3 ^ s1;
        let s1 = s1 ^ s2;
        let s0 = s0 ^ s3;
        let s2 = s2 ^ t;
        let s3 = s3.rotl::<45>();
        let keep = crate::math::lanes::Mask8(m);
        self.s[0][h] = U64x8::select(keep, s0, self.s[0][h]);
        self.s[1][h] = U64x8::select(keep, s1, self.s[1][h]);
        self.s[2][h] = U64x8::select(keep, s2, self.s[2][h]);
        self.s[3][h] = U64x8::select(keep, s3, self.s[3][h]);
        result
    }

    /// A uniform number in [0, 1) for each lane of `m` (0 elsewhere), as
    /// `IndependentSampler::next_1d` makes it: the top 24 bits of a draw times 2⁻²⁴.
    #[inline(always)]
    pub fn next_1d(&mut self, m: Mask16) -> F32x16 {
        let [lo, hi] = self.next_u64(m);
        let top = U32x16::from_u64_halves(lo.shr::<40>(), hi.shr::<40>());
        let u = top.to_f32() * F32x16::splat(1.0 / (1u64 << 24) as f32);
        F32x16::select(m, u, F32x16::splat(0.0))
    }

    /// Two uniform numbers per lane of `m`, drawn one after the other (as `next_2d`).
    #[inline(always)]
    pub fn next_2d(&mut self, m: Mask16) -> (F32x16, F32x16) {
        let x = self.next_1d(m);
        let y = self.next_1d(m);
        (x, y)
    }
}

/// SplitMix64's increment φ (the golden ratio times 2⁶⁴).
const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// `independent::mix64` per lane.
#[inline(always)]
fn mix64_lanes(z: U64x8) -> U64x8 {
    let z = z + U64x8::splat(GOLDEN_GAMMA);
    let z = (z ^ z.shr::<30>()) * U64x8::splat(0xBF58_476D_1CE4_E5B9);
    let z = (z ^ z.shr::<27>()) * U64x8::splat(0x94D0_49BB_1331_11EB);
    z ^ z.shr::<31>()
}

/// `independent::hash_words` per lane.
#[inline(always)]
fn hash_words_lanes(words: &[U64x8]) -> U64x8 {
    words.iter().fold(U64x8::splat(HASH_START), |h, &w| {
        mix64_lanes(h ^ mix64_lanes(w))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{IndependentSampler, Sampler};

    #[test]
    fn each_lane_draws_what_its_sampler_draws() {
        let mut samplers: Vec<IndependentSampler> = (0..16)
            .map(|i| {
                let mut s = IndependentSampler::new(17);
                s.start_pixel_sample((i, 3 * i), 5);
                s
            })
            .collect();
        let mut lanes = LaneStreams::default();
        for (i, s) in samplers.iter().enumerate() {
            lanes.set_lane(i, s.state());
        }
        // Masks that skip lanes at some draws: skipped lanes must not advance.
        for step in 0..200u32 {
            let m = Mask16((step.wrapping_mul(0x9E37) ^ (step >> 3)) as u16 | 1);
            let got = lanes.next_1d(m).to_array();
            for (i, s) in samplers.iter_mut().enumerate() {
                if m.get(i) {
                    assert_eq!(
                        got[i].to_bits(),
                        s.next_1d().to_bits(),
                        "step {step} lane {i}"
                    );
                } else {
                    assert_eq!(got[i], 0.0);
                }
            }
        }
        for (i, s) in samplers.iter().enumerate() {
            assert_eq!(lanes.lane(i), s.state());
        }
        for (i, s) in samplers.iter().enumerate() {
            // A sampler continued from the lane's state draws on identically.
            let mut a = IndependentSampler::with_state(17, lanes.lane(i));
            let mut b = IndependentSampler::with_state(17, s.state());
            assert_eq!(a.next_1d(), b.next_1d());
        }
    }

    #[test]
    fn lanes_start_pixel_samples_as_the_sampler_does() {
        let mut lanes = LaneStreams::default();
        for i in 0..16 {
            lanes.set_lane(i, [i as u64, 7, 9, 11]);
        }
        let m = Mask16(0b1011_1111_0111_1101);
        let xs = U32x16::from_array(std::array::from_fn(|i| 3 * i as u32 + 1));
        let ys = U32x16::from_array(std::array::from_fn(|i| 1000 - i as u32));
        let before = lanes.clone_states();
        let index = U32x16::from_array(std::array::from_fn(|i| 4_000_000_000 - 7 * i as u32));
        lanes.start_pixel_samples(m, 17, xs, ys, index);
        for (i, &old) in before.iter().enumerate() {
            let want = if m.get(i) {
                let mut s = IndependentSampler::new(17);
                let index = 4_000_000_000 - 7 * i as u64;
                s.start_pixel_sample((3 * i as u32 + 1, 1000 - i as u32), index);
                s.state()
            } else {
                old
            };
            assert_eq!(lanes.lane(i), want, "lane {i}");
        }
    }
}
