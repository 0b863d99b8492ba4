//! Four f32 lanes in one SSE register. SSE and SSE2 are part of the x86-64 baseline, so this kernel
//! runs on every x86-64 CPU with no runtime detection and no `#[target_feature]` entry point.

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

use super::{LaneMask, Lanes};

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x4(__m128);

#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct Mask4(__m128);

impl Lanes<4> for F32x4 {
    type Mask = Mask4;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_set1_ps(v)) }
    }
    #[inline(always)]
    fn load(a: &[f32; 4]) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline; `a` is four readable f32 (unaligned load).
        unsafe { F32x4(_mm_loadu_ps(a.as_ptr())) }
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        let mut out = [0.0; 4];
        // SAFETY: SSE is part of the x86-64 baseline; `out` is four writable f32 (unaligned store).
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline. `minps` returns the second operand on NaN.
        unsafe { F32x4(_mm_min_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline. `maxps` returns the second operand on NaN.
        unsafe { F32x4(_mm_max_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn lt(self, b: Self) -> Mask4 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_cmplt_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn le(self, b: Self) -> Mask4 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_cmple_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn gt(self, b: Self) -> Mask4 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_cmpgt_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn eq(self, b: Self) -> Mask4 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_cmpeq_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn ne(self, b: Self) -> Mask4 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_cmpneq_ps(self.0, b.0)) }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_andnot_ps(_mm_set1_ps(-0.0), self.0)) }
    }
    #[inline(always)]
    fn select_by_sign(sign: Self, if_negative: Self, otherwise: Self) -> Self {
        // SAFETY: SSE2 is part of the x86-64 baseline. The arithmetic shift spreads each sign bit
        // over its lane (SSE4.1's `blendvps` is not in the baseline).
        unsafe {
            let negative = _mm_castsi128_ps(_mm_srai_epi32::<31>(_mm_castps_si128(sign.0)));
            F32x4(_mm_or_ps(_mm_and_ps(negative, if_negative.0), _mm_andnot_ps(negative, otherwise.0)))
        }
    }
}

impl Add for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_add_ps(self.0, b.0)) }
    }
}
impl Sub for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_sub_ps(self.0, b.0)) }
    }
}
impl Mul for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_mul_ps(self.0, b.0)) }
    }
}
impl Div for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { F32x4(_mm_div_ps(self.0, b.0)) }
    }
}

impl LaneMask for Mask4 {
    #[inline(always)]
    fn bits(self) -> u32 {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { _mm_movemask_ps(self.0) as u32 }
    }
}
impl BitAnd for Mask4 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_and_ps(self.0, b.0)) }
    }
}
impl BitOr for Mask4 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, b: Self) -> Self {
        // SAFETY: SSE is part of the x86-64 baseline.
        unsafe { Mask4(_mm_or_ps(self.0, b.0)) }
    }
}
