//! Lane masks: one bit per lane, lane i in bit i (the layout of AVX-512's mask registers).

use std::ops::{BitAnd, BitAndAssign, BitOr, BitOrAssign, BitXor, Not};

macro_rules! mask_type {
    ($name:ident, $bits:ty, $lanes:expr) => {
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct $name(pub $bits);

        impl $name {
            pub const NONE: $name = $name(0);
            pub const ALL: $name = $name(<$bits>::MAX);

            /// Lane i set where `f(i)`.
            #[inline(always)]
            pub fn from_fn(f: impl Fn(usize) -> bool) -> $name {
                let mut bits: $bits = 0;
                for i in 0..$lanes {
                    bits |= (f(i) as $bits) << i;
                }
                $name(bits)
            }

            /// The first `n` lanes set.
            #[inline(always)]
            pub fn first(n: usize) -> $name {
                if n >= $lanes {
                    $name::ALL
                } else {
                    $name(((1u32 << n) - 1) as $bits)
                }
            }

            #[inline(always)]
            pub fn get(self, lane: usize) -> bool {
                (self.0 >> lane) & 1 != 0
            }

            #[inline(always)]
            pub fn set(&mut self, lane: usize, on: bool) {
                let bit: $bits = 1 << lane;
                if on {
                    self.0 |= bit;
                } else {
                    self.0 &= !bit;
                }
            }

            #[inline(always)]
            pub fn any(self) -> bool {
                self.0 != 0
            }

            #[inline(always)]
            pub fn none(self) -> bool {
                self.0 == 0
            }

            #[inline(always)]
            pub fn all(self) -> bool {
                self.0 == <$bits>::MAX
            }

            #[inline(always)]
            pub fn count(self) -> u32 {
                self.0.count_ones()
            }

            /// The set lanes, lowest first.
            #[inline(always)]
            pub fn lanes(self) -> impl Iterator<Item = usize> {
                let mut bits = self.0;
                std::iter::from_fn(move || {
                    if bits == 0 {
                        return None;
                    }
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    Some(lane)
                })
            }
        }

        impl BitAnd for $name {
            type Output = $name;
            #[inline(always)]
            fn bitand(self, o: $name) -> $name {
                $name(self.0 & o.0)
            }
        }

        impl BitOr for $name {
            type Output = $name;
            #[inline(always)]
            fn bitor(self, o: $name) -> $name {
                $name(self.0 | o.0)
            }
        }

        impl BitXor for $name {
            type Output = $name;
            #[inline(always)]
            fn bitxor(self, o: $name) -> $name {
                $name(self.0 ^ o.0)
            }
        }

        impl Not for $name {
            type Output = $name;
            #[inline(always)]
            fn not(self) -> $name {
                $name(!self.0)
            }
        }

        impl BitAndAssign for $name {
            #[inline(always)]
            fn bitand_assign(&mut self, o: $name) {
                self.0 &= o.0;
            }
        }

        impl BitOrAssign for $name {
            #[inline(always)]
            fn bitor_assign(&mut self, o: $name) {
                self.0 |= o.0;
            }
        }
    };
}

mask_type!(Mask16, u16, 16);
mask_type!(Mask8, u8, 8);

impl Mask16 {
    /// Lanes 0–7 and 8–15 as two eight-lane masks (for `F64x8` halves).
    #[inline(always)]
    pub fn halves(self) -> (Mask8, Mask8) {
        (Mask8(self.0 as u8), Mask8((self.0 >> 8) as u8))
    }

    /// The sixteen-lane mask of two halves.
    #[inline(always)]
    pub fn from_halves(lo: Mask8, hi: Mask8) -> Mask16 {
        Mask16(lo.0 as u16 | (hi.0 as u16) << 8)
    }
}
