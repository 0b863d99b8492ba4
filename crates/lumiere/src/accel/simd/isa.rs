//! The instruction set, detected once (by `World::new`, which keeps it and picks the accel from it).

/// The widest SIMD instruction set this CPU offers that a kernel could use, in increasing order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// No x86-64 SIMD: the portable kernel.
    Portable,
    /// SSE2, the x86-64 baseline: the 4-wide SSE kernel.
    Sse2,
    /// AVX2 (8 lanes).
    Avx2,
    /// AVX-512 Foundation (16 lanes).
    Avx512,
}

impl Isa {
    /// Asks the CPU (through `cpuid`, behind `is_x86_feature_detected!`). Call it once and keep the
    /// answer: everything that dispatches on the ISA should agree on one value.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") {
                Isa::Avx512
            } else if is_x86_feature_detected!("avx2") {
                Isa::Avx2
            } else {
                Isa::Sse2
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Isa::Portable
        }
    }
}
