//! `W` f32 lanes as a plain array: the kernel on architectures without one of their own, and, on
//! x86-64, a second implementation of [`Lanes`] that the tests run the wide BVH with (at width 4 to
//! check the SSE kernel lane for lane, at width 8 to check that the layout really is generic).
//! Each operation is the scalar IEEE operation per lane, so results equal the SIMD kernels' bit for
//! bit.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

use super::{LaneMask, Lanes};

#[derive(Clone, Copy, Debug)]
pub struct F32xN<const W: usize>([f32; W]);

#[derive(Clone, Copy, Debug)]
pub struct MaskN<const W: usize>([bool; W]);

impl<const W: usize> F32xN<W> {
    #[inline(always)]
    fn map(self, b: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        F32xN(std::array::from_fn(|i| f(self.0[i], b.0[i])))
    }
    #[inline(always)]
    fn compare(self, b: Self, f: impl Fn(f32, f32) -> bool) -> MaskN<W> {
        MaskN(std::array::from_fn(|i| f(self.0[i], b.0[i])))
    }
}

impl<const W: usize> Lanes<W> for F32xN<W> {
    type Mask = MaskN<W>;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        F32xN([v; W])
    }
    #[inline(always)]
    fn load(a: &[f32; W]) -> Self {
        F32xN(*a)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; W] {
        self.0
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        // `b` unless `a < b`: `b` when either is NaN, as SSE's `minps`.
        self.map(b, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        self.map(b, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn lt(self, b: Self) -> MaskN<W> {
        self.compare(b, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, b: Self) -> MaskN<W> {
        self.compare(b, |a, b| a <= b)
    }
    #[inline(always)]
    fn gt(self, b: Self) -> MaskN<W> {
        self.compare(b, |a, b| a > b)
    }
    #[inline(always)]
    fn eq(self, b: Self) -> MaskN<W> {
        self.compare(b, |a, b| a == b)
    }
    #[inline(always)]
    fn ne(self, b: Self) -> MaskN<W> {
        self.compare(b, |a, b| a != b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F32xN(self.0.map(f32::abs))
    }
    #[inline(always)]
    fn select_by_sign(sign: Self, if_negative: Self, otherwise: Self) -> Self {
        F32xN(std::array::from_fn(|i| if sign.0[i].is_sign_negative() { if_negative.0[i] } else { otherwise.0[i] }))
    }
}

impl<const W: usize> Add for F32xN<W> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        self.map(b, |a, b| a + b)
    }
}
impl<const W: usize> Sub for F32xN<W> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        self.map(b, |a, b| a - b)
    }
}
impl<const W: usize> Mul for F32xN<W> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        self.map(b, |a, b| a * b)
    }
}
impl<const W: usize> Div for F32xN<W> {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self.map(b, |a, b| a / b)
    }
}

impl<const W: usize> LaneMask for MaskN<W> {
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0.iter().enumerate().fold(0, |bits, (i, &lane)| bits | u32::from(lane) << i)
    }
}
impl<const W: usize> BitAnd for MaskN<W> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, b: Self) -> Self {
        MaskN(std::array::from_fn(|i| self.0[i] & b.0[i]))
    }
}
impl<const W: usize> BitOr for MaskN<W> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, b: Self) -> Self {
        MaskN(std::array::from_fn(|i| self.0[i] | b.0[i]))
    }
}
