//! The instruction set: detected once (by `Accel::build`'s callers through [`Isa::detect`]), or
//! forced by `--isa` for tests and benchmarks.

use std::fmt;

/// A SIMD instruction set the BVH kernels can use, in increasing order of width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// No x86-64 SIMD: the portable 4-wide kernel (architectures other than x86-64).
    Portable,
    /// SSE2, the x86-64 baseline: the 4-wide BVH with the SSE kernel.
    Sse2,
    /// AVX2: the 8-wide BVH with 256-bit kernels.
    Avx2,
    /// AVX-512 F, VL and DQ: the 8-wide BVH (traversed with the AVX2 kernel) and 16-lane loops.
    Avx512,
}

impl Isa {
    /// Every ISA, narrowest first.
    pub const ALL: [Isa; 4] = [Isa::Portable, Isa::Sse2, Isa::Avx2, Isa::Avx512];

    /// The widest ISA this CPU runs. `is_x86_feature_detected!` caches its `cpuid` answer, but call
    /// this once and keep the answer all the same: everything that dispatches should agree on one.
    pub fn detect() -> Isa {
        Isa::ALL.into_iter().rev().find(|isa| isa.is_supported()).unwrap_or(Isa::Portable)
    }

    /// Whether this CPU (and this build's target architecture) can run the ISA's kernels.
    pub fn is_supported(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use super::avx::{Avx2, Avx512, AvxLevel};
            match self {
                // The portable kernel runs anywhere; on x86-64 it is for tests, as SSE2 is always there.
                Isa::Portable | Isa::Sse2 => true,
                Isa::Avx2 => Avx2::supported(),
                Isa::Avx512 => Avx512::supported(),
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self == Isa::Portable
        }
    }

    /// The ISAs this CPU can run, narrowest first.
    pub fn supported() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|isa| isa.is_supported()).collect()
    }

    /// The name `--isa` takes and reports print.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Sse2 => "sse2",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The ISA called `name` (as [`Isa::name`] writes it).
    pub fn from_name(name: &str) -> Option<Isa> {
        Isa::ALL.into_iter().find(|isa| isa.name() == name)
    }

    /// Children per BVH node (and triangles per leaf block) of this ISA's accel.
    pub fn width(self) -> usize {
        match self {
            Isa::Portable | Isa::Sse2 => 4,
            Isa::Avx2 | Isa::Avx512 => 8,
        }
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
