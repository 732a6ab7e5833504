//! Whether this build runs on this CPU: a binary built with `-C target-cpu=native` (the
//! default, `.cargo/config.toml`) or for a higher x86-64 level may use instructions another
//! machine lacks, and would die there of an illegal instruction. `main` checks first.

/// The x86 features this build was compiled to use that the CPU it runs on lacks (empty on
/// other architectures). Read from CPUID directly: `is_x86_feature_detected!` answers yes
/// for every feature enabled at compile time, whatever the CPU.
pub fn missing_features() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        x86::missing()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::{__cpuid, __cpuid_count};

    /// The CPUID registers where features are reported.
    #[derive(Clone, Copy)]
    enum Reg {
        /// Leaf 1, ECX.
        L1Ecx,
        /// Leaf 7 subleaf 0, EBX, ECX and EDX.
        L7Ebx,
        L7Ecx,
        L7Edx,
        /// Leaf 7 subleaf 1, EAX.
        L7s1Eax,
        /// Leaf 0x8000_0001, ECX.
        Ext1Ecx,
    }

    struct Cpuid {
        l1_ecx: u32,
        l7: [u32; 3],
        l7s1_eax: u32,
        ext1_ecx: u32,
    }

    impl Cpuid {
        fn read() -> Cpuid {
            // CPUID exists on every x86-64 CPU; leaves above the maximum read as zero here.
            let max = __cpuid(0).eax;
            let max_ext = __cpuid(0x8000_0000).eax;
            let (l7, l7s1_eax) = if max >= 7 {
                let r = __cpuid_count(7, 0);
                let sub1 = if r.eax >= 1 {
                    __cpuid_count(7, 1).eax
                } else {
                    0
                };
                ([r.ebx, r.ecx, r.edx], sub1)
            } else {
                ([0; 3], 0)
            };
            Cpuid {
                l1_ecx: __cpuid(1).ecx,
                l7,
                l7s1_eax,
                ext1_ecx: if max_ext >= 0x8000_0001 {
                    __cpuid(0x8000_0001).ecx
                } else {
                    0
                },
            }
        }

        fn has(&self, reg: Reg, bit: u32) -> bool {
            let word = match reg {
                Reg::L1Ecx => self.l1_ecx,
                Reg::L7Ebx => self.l7[0],
                Reg::L7Ecx => self.l7[1],
                Reg::L7Edx => self.l7[2],
                Reg::L7s1Eax => self.l7s1_eax,
                Reg::Ext1Ecx => self.ext1_ecx,
            };
            word & (1 << bit) != 0
        }
    }

    pub(super) fn missing() -> Vec<&'static str> {
        let cpu = Cpuid::read();
        let mut missing = Vec::new();
        // (feature, where CPUID reports it): each one this build enables must be there.
        macro_rules! check {
            ($($feature:tt: $reg:ident $bit:literal),* $(,)?) => {$(
                if cfg!(target_feature = $feature) && !cpu.has(Reg::$reg, $bit) {
                    missing.push($feature);
                }
            )*};
        }
        #[rustfmt::skip]
        check!(
            "sse3": L1Ecx 0, "pclmulqdq": L1Ecx 1, "ssse3": L1Ecx 9, "fma": L1Ecx 12,
            "cmpxchg16b": L1Ecx 13, "sse4.1": L1Ecx 19, "sse4.2": L1Ecx 20, "movbe": L1Ecx 22,
            "popcnt": L1Ecx 23, "aes": L1Ecx 25, "xsave": L1Ecx 26, "avx": L1Ecx 28,
            "f16c": L1Ecx 29, "rdrand": L1Ecx 30,
            "bmi1": L7Ebx 3, "avx2": L7Ebx 5, "bmi2": L7Ebx 8, "avx512f": L7Ebx 16,
            "avx512dq": L7Ebx 17, "rdseed": L7Ebx 18, "adx": L7Ebx 19, "avx512ifma": L7Ebx 21,
            "avx512cd": L7Ebx 28, "sha": L7Ebx 29, "avx512bw": L7Ebx 30, "avx512vl": L7Ebx 31,
            "avx512vbmi": L7Ecx 1, "avx512vbmi2": L7Ecx 6, "gfni": L7Ecx 8, "vaes": L7Ecx 9,
            "vpclmulqdq": L7Ecx 10, "avx512vnni": L7Ecx 11, "avx512bitalg": L7Ecx 12,
            "avx512vpopcntdq": L7Ecx 14,
            "avx512vp2intersect": L7Edx 8, "avx512fp16": L7Edx 23,
            "avxvnni": L7s1Eax 4, "avx512bf16": L7s1Eax 5,
            "lzcnt": Ext1Ecx 5, "sse4a": Ext1Ecx 6,
        );
        missing
    }
}

#[cfg(test)]
mod tests {
    /// The tests run on the machine they were built for (with `target-cpu=native`, every
    /// feature it has): a wrong CPUID bit would report one of them missing.
    #[test]
    fn a_build_for_this_machine_misses_nothing() {
        assert_eq!(super::missing_features(), Vec::<&str>::new());
    }
}
