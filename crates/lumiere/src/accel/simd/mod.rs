//! SIMD lanes for the wide BVH: a lane trait, its kernels, and the one place the instruction set is
//! detected.
//!
//! The wide traversal and the batches are written once against [`Lanes`]; a kernel is a type
//! implementing it for one width:
//! - [`sse::F32x4`]: four lanes, SSE, part of the x86-64 baseline, so it needs no detection;
//! - `avx::F32x8<Avx2>`: eight lanes, entered through [`Lanes::dispatch`], which runs the
//!   traversal inside a `#[target_feature]` function; it exists only inside an
//!   [`crate::accel::Accel`] built after checking [`Isa::is_supported`] (both AVX ISAs walk the tree
//!   with it; the AVX-512 level compiles the lane loops of `Accel::simd`);
//! - [`portable::F32xN`]: plain arrays of any width, the fallback on other architectures and a
//!   second implementation the tests check the others against.
//!
//! Kernels must not contract multiplies and adds into FMAs (Rust never does so implicitly): the wide
//! triangle test must round exactly like the scalar one, so every ISA gives the same image bytes.

#[cfg(target_arch = "x86_64")]
pub(in crate::accel) mod avx;
mod isa;
pub mod portable;
#[cfg(target_arch = "x86_64")]
pub mod sse;

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

pub use isa::Isa;

/// The four-lane kernel every build has: SSE on x86-64, plain arrays elsewhere.
#[cfg(target_arch = "x86_64")]
pub type F32x4 = sse::F32x4;
/// The four-lane kernel every build has: SSE on x86-64, plain arrays elsewhere.
#[cfg(not(target_arch = "x86_64"))]
pub type F32x4 = portable::F32xN<4>;

/// `W` f32 lanes: only the operations the wide BVH needs, each one instruction in a SIMD kernel.
///
/// Min and max follow SSE: where either lane is NaN they return `b`'s lane. The wide box test relies
/// on it (an empty child's NaN box never admits a ray), so every kernel must do the same.
pub trait Lanes<const W: usize>:
    Copy + Debug + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// One boolean per lane, as comparisons return it.
    type Mask: LaneMask;

    /// Whether this CPU can run the kernel. Kernels outside the x86-64 baseline must not be used
    /// (not even built into a BVH) where this is false.
    fn supported() -> bool {
        true
    }

    /// Runs `f`, the traversal written against this kernel, with the kernel's instruction set
    /// enabled. Every entry point of the wide BVH goes through it, except the walks inlined into
    /// a caller that runs in `Accel::simd` already (`WideBvh::occluded_from_origin`).
    #[inline(always)]
    fn dispatch<R>(f: impl FnOnce() -> R) -> R {
        f()
    }

    fn splat(v: f32) -> Self;
    fn load(a: &[f32; W]) -> Self;
    fn to_array(self) -> [f32; W];
    /// Lane-wise minimum; `b`'s lane where either lane is NaN.
    fn min(self, b: Self) -> Self;
    /// Lane-wise maximum; `b`'s lane where either lane is NaN.
    fn max(self, b: Self) -> Self;
    fn lt(self, b: Self) -> Self::Mask;
    fn le(self, b: Self) -> Self::Mask;
    fn gt(self, b: Self) -> Self::Mask;
    fn eq(self, b: Self) -> Self::Mask;
    fn ne(self, b: Self) -> Self::Mask;
    /// Lane-wise absolute value (clears the sign bit).
    fn abs(self) -> Self;
    /// `if_negative`'s lane where `sign`'s lane has its sign bit set (-0.0 and negative NaNs
    /// included), `otherwise`'s elsewhere: a choice by a direction's sign read off its reciprocal.
    fn select_by_sign(sign: Self, if_negative: Self, otherwise: Self) -> Self;

    /// Lanes that are neither infinite nor NaN.
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        // Both comparisons are false for NaN, one of them for an infinity.
        Self::splat(-f32::MAX).le(self) & self.le(Self::splat(f32::MAX))
    }
}

/// The result of a lane comparison.
pub trait LaneMask: Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> {
    /// Bit `i` set where lane `i` is true; no bits above the width.
    fn bits(self) -> u32;
}

/// `_mm_min_ps(a, b)` on one lane: `b` where either is NaN, as every kernel's `min`. Loops over
/// lanes that must round like the kernels (packets, ray-major batches) use it.
#[inline(always)]
pub fn min_ps(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// `_mm_max_ps(a, b)` on one lane: `b` where either is NaN, as every kernel's `max`.
#[inline(always)]
pub fn max_ps(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The lanes whose bits are set in `mask`, in increasing order.
#[inline(always)]
pub fn lanes_of(mask: u32) -> impl Iterator<Item = usize> {
    let mut rest = mask;
    std::iter::from_fn(move || {
        (rest != 0).then(|| {
            let lane = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            lane
        })
    })
}

/// Bits `0..width` set: the mask of all lanes, for complementing [`LaneMask::bits`].
pub const fn all_lanes(width: usize) -> u32 {
    assert!(width != 0 && width <= 32, "a lane mask is a u32");
    u32::MAX >> (32 - width)
}
