//! Sixteen independent random streams side by side: lane i continues the Xoshiro256++
//! stream of one `IndependentSampler` (its `state`), drawing the same numbers in the same
//! order, so a path traced in a lane sees exactly the random numbers it would see alone.
//!
//! Xoshiro256++ (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
//! ACM TOMS 2021): output rotl(s0 + s3, 23) + s0, then the xoshiro256 state transition. A
//! draw advances only the lanes of its mask; the others keep their state, as a path that
//! draws nothing at that step would.

use crate::math::lanes::{F32x16, Mask16, U32x16, U64x8};

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
    /// Lane `lane` continues the stream with state `state` (`IndependentSampler::state`).
    pub fn set_lane(&mut self, lane: usize, state: [u64; 4]) {
        let (half, i) = (lane / 8, lane % 8);
        for (k, &word) in state.iter().enumerate() {
            let mut words = self.s[k][half].to_array();
            words[i] = word;
            self.s[k][half] = U64x8::from_array(words);
        }
    }

    /// The state of lane `lane`'s stream.
    pub fn lane(&self, lane: usize) -> [u64; 4] {
        let (half, i) = (lane / 8, lane % 8);
        std::array::from_fn(|k| self.s[k][half].to_array()[i])
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
            // A sampler continued from the lane's state draws on identically.
            let mut a = IndependentSampler::with_state(17, lanes.lane(i));
            let mut b = IndependentSampler::with_state(17, s.state());
            assert_eq!(a.next_1d(), b.next_1d());
        }
    }
}
