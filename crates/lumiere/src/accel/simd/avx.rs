//! Eight f32 lanes in one 256-bit register, for the 8-wide BVH on CPUs with AVX2 or AVX-512.
//!
//! One kernel, generic in the level it is compiled for: AVX2, or AVX-512 (F, VL, DQ), where the
//! compiler gets 32 vector registers and mask registers. Every level rounds exactly alike (Rust
//! never fuses a multiply and an add on its own), so they return the same bits as the SSE and
//! scalar paths. The BVH traversal runs at the AVX2 level on both AVX ISAs (see `Accel`); the
//! AVX-512 level runs the 16-lane loops of `Accel::simd`.
//!
//! Unlike SSE, neither is part of the x86-64 baseline: these intrinsics may only run on a CPU that
//! has the level's features. The kernel's operations run only on a [`crate::accel::WideBvh`] built
//! for it, which `WideBvh::from_tree` creates only when [`Lanes::supported`] holds (and `Accel`
//! only when its ISA is supported): through [`Lanes::dispatch`], or inlined into a caller that
//! runs in `Accel::simd` already. `dispatch` also enters the one `#[target_feature]` function the
//! kernel code is inlined into, so that each intrinsic below compiles to one instruction there.

use std::arch::x86_64::*;
use std::fmt::Debug;
use std::marker::PhantomData;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

use super::{LaneMask, Lanes};

/// An instruction set level the 8-lane kernel is compiled for.
pub trait AvxLevel: Copy + Debug {
    fn supported() -> bool;
    /// Runs `f` with the level's features enabled.
    ///
    /// # Safety
    /// The CPU must support the level (`supported()`).
    unsafe fn run<R>(f: impl FnOnce() -> R) -> R;
}

/// AVX2 (with AVX): Haswell and later, Zen and later.
#[derive(Clone, Copy, Debug)]
pub struct Avx2;

/// AVX-512 Foundation with the 256-bit (VL) encodings and 64-bit integer multiplies (DQ, which
/// the samplers' hashes use): Skylake-X and later, Zen 4 and later.
#[derive(Clone, Copy, Debug)]
pub struct Avx512;

impl AvxLevel for Avx2 {
    fn supported() -> bool {
        is_x86_feature_detected!("avx2")
    }
    #[inline(always)]
    unsafe fn run<R>(f: impl FnOnce() -> R) -> R {
        #[target_feature(enable = "avx,avx2")]
        unsafe fn with_avx2<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        // SAFETY: the caller guarantees AVX2.
        unsafe { with_avx2(f) }
    }
}

impl AvxLevel for Avx512 {
    fn supported() -> bool {
        is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512vl")
            && is_x86_feature_detected!("avx512dq")
    }
    #[inline(always)]
    unsafe fn run<R>(f: impl FnOnce() -> R) -> R {
        #[target_feature(enable = "avx,avx2,avx512f,avx512vl,avx512dq")]
        unsafe fn with_avx512<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        // SAFETY: the caller guarantees AVX-512 F, VL and DQ (and AVX2).
        unsafe { with_avx512(f) }
    }
}

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8<V>(__m256, PhantomData<V>);

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct Mask8(__m256);

impl<V> F32x8<V> {
    #[inline(always)]
    fn new(v: __m256) -> Self {
        F32x8(v, PhantomData)
    }
}

impl<V: AvxLevel> Lanes<8> for F32x8<V> {
    type Mask = Mask8;

    fn supported() -> bool {
        V::supported()
    }

    #[inline(always)]
    fn dispatch<R>(f: impl FnOnce() -> R) -> R {
        debug_assert!(Self::supported());
        // SAFETY: values of this kernel exist only inside a BVH built for it, which `Accel::build`
        // creates only when `supported()` holds (see the module note).
        unsafe { V::run(f) }
    }

    #[inline(always)]
    fn splat(v: f32) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_set1_ps(v)) }
    }
    #[inline(always)]
    fn load(a: &[f32; 8]) -> Self {
        // SAFETY: the level's features are present (see `dispatch`); `a` is eight readable f32 (unaligned load).
        unsafe { F32x8::new(_mm256_loadu_ps(a.as_ptr())) }
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        // SAFETY: the level's features are present (see `dispatch`); `out` is eight writable f32 (unaligned store).
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`); `vminps` returns the second operand on NaN, as SSE's `minps`.
        unsafe { F32x8::new(_mm256_min_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_max_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn lt(self, b: Self) -> Mask8 {
        // SAFETY: the level's features are present (see `dispatch`); ordered, quiet comparisons: false on NaN, as SSE's `cmpltps`.
        unsafe { Mask8(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, b.0)) }
    }
    #[inline(always)]
    fn le(self, b: Self) -> Mask8 {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { Mask8(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, b.0)) }
    }
    #[inline(always)]
    fn gt(self, b: Self) -> Mask8 {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { Mask8(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, b.0)) }
    }
    #[inline(always)]
    fn eq(self, b: Self) -> Mask8 {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { Mask8(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, b.0)) }
    }
    #[inline(always)]
    fn ne(self, b: Self) -> Mask8 {
        // SAFETY: the level's features are present (see `dispatch`); unordered: true on NaN, as SSE's `cmpneqps` and IEEE `!=`.
        unsafe { Mask8(_mm256_cmp_ps::<_CMP_NEQ_UQ>(self.0, b.0)) }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
    }
    #[inline(always)]
    fn select_by_sign(sign: Self, if_negative: Self, otherwise: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`); `vblendvps` reads each lane's sign bit.
        unsafe { F32x8::new(_mm256_blendv_ps(otherwise.0, if_negative.0, sign.0)) }
    }
}

impl<V> Add for F32x8<V> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_add_ps(self.0, b.0)) }
    }
}
impl<V> Sub for F32x8<V> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_sub_ps(self.0, b.0)) }
    }
}
impl<V> Mul for F32x8<V> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_mul_ps(self.0, b.0)) }
    }
}
impl<V> Div for F32x8<V> {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { F32x8::new(_mm256_div_ps(self.0, b.0)) }
    }
}

impl LaneMask for Mask8 {
    #[inline(always)]
    fn bits(self) -> u32 {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
}
impl BitAnd for Mask8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { Mask8(_mm256_and_ps(self.0, b.0)) }
    }
}
impl BitOr for Mask8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, b: Self) -> Self {
        // SAFETY: the level's features are present (see `dispatch`).
        unsafe { Mask8(_mm256_or_ps(self.0, b.0)) }
    }
}
