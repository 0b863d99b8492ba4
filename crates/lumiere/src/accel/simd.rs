//! Four f32 lanes: SSE on x86-64 (part of the baseline, so no runtime detection is needed), plain
//! arrays elsewhere. Only the operations the wide BVH needs, each mapping to one instruction.

#[cfg(target_arch = "x86_64")]
mod imp {
    use std::arch::x86_64::*;

    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct F32x4(__m128);

    // SAFETY (all blocks below): SSE and SSE2 are part of the x86-64 baseline, so these intrinsics
    // are always available; loads take references to properly sized arrays.
    impl F32x4 {
        #[inline(always)]
        pub fn splat(v: f32) -> Self {
            unsafe { F32x4(_mm_set1_ps(v)) }
        }
        #[inline(always)]
        pub fn load(a: &[f32; 4]) -> Self {
            unsafe { F32x4(_mm_loadu_ps(a.as_ptr())) }
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 4] {
            let mut out = [0.0; 4];
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
        /// Lane-wise minimum; returns `b`'s lane where either lane is NaN (SSE semantics).
        #[inline(always)]
        pub fn min(self, b: Self) -> Self {
            unsafe { F32x4(_mm_min_ps(self.0, b.0)) }
        }
        /// Lane-wise maximum; returns `b`'s lane where either lane is NaN (SSE semantics).
        #[inline(always)]
        pub fn max(self, b: Self) -> Self {
            unsafe { F32x4(_mm_max_ps(self.0, b.0)) }
        }
        #[inline(always)]
        pub fn le(self, b: Self) -> Mask4 {
            unsafe { Mask4(_mm_cmple_ps(self.0, b.0)) }
        }
        #[inline(always)]
        pub fn lt(self, b: Self) -> Mask4 {
            unsafe { Mask4(_mm_cmplt_ps(self.0, b.0)) }
        }
        #[inline(always)]
        pub fn gt(self, b: Self) -> Mask4 {
            unsafe { Mask4(_mm_cmpgt_ps(self.0, b.0)) }
        }
        #[inline(always)]
        pub fn eq(self, b: Self) -> Mask4 {
            unsafe { Mask4(_mm_cmpeq_ps(self.0, b.0)) }
        }
        #[inline(always)]
        pub fn ne(self, b: Self) -> Mask4 {
            unsafe { Mask4(_mm_cmpneq_ps(self.0, b.0)) }
        }
        /// Lane-wise absolute value (clears the sign bit).
        #[inline(always)]
        pub fn abs(self) -> Self {
            unsafe { F32x4(_mm_andnot_ps(_mm_set1_ps(-0.0), self.0)) }
        }
        /// Lanes that are neither infinite nor NaN.
        #[inline(always)]
        pub fn is_finite(self) -> Mask4 {
            // Both comparisons are false for NaN, one of them for an infinity.
            F32x4::splat(-f32::MAX).le(self) & self.le(F32x4::splat(f32::MAX))
        }
    }

    impl std::ops::Add for F32x4 {
        type Output = Self;
        #[inline(always)]
        fn add(self, b: Self) -> Self {
            unsafe { F32x4(_mm_add_ps(self.0, b.0)) }
        }
    }
    impl std::ops::Sub for F32x4 {
        type Output = Self;
        #[inline(always)]
        fn sub(self, b: Self) -> Self {
            unsafe { F32x4(_mm_sub_ps(self.0, b.0)) }
        }
    }
    impl std::ops::Mul for F32x4 {
        type Output = Self;
        #[inline(always)]
        fn mul(self, b: Self) -> Self {
            unsafe { F32x4(_mm_mul_ps(self.0, b.0)) }
        }
    }
    impl std::ops::Div for F32x4 {
        type Output = Self;
        #[inline(always)]
        fn div(self, b: Self) -> Self {
            unsafe { F32x4(_mm_div_ps(self.0, b.0)) }
        }
    }

    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct Mask4(__m128);

    impl Mask4 {
        /// Bit `i` set where lane `i` is true.
        #[inline(always)]
        pub fn bits(self) -> u32 {
            unsafe { _mm_movemask_ps(self.0) as u32 }
        }
    }
    impl std::ops::BitAnd for Mask4 {
        type Output = Self;
        #[inline(always)]
        fn bitand(self, b: Self) -> Self {
            unsafe { Mask4(_mm_and_ps(self.0, b.0)) }
        }
    }
    impl std::ops::BitOr for Mask4 {
        type Output = Self;
        #[inline(always)]
        fn bitor(self, b: Self) -> Self {
            unsafe { Mask4(_mm_or_ps(self.0, b.0)) }
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    #[derive(Clone, Copy, Debug)]
    pub struct F32x4([f32; 4]);

    fn map(a: [f32; 4], b: [f32; 4], f: impl Fn(f32, f32) -> f32) -> [f32; 4] {
        [f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])]
    }
    fn cmp(a: [f32; 4], b: [f32; 4], f: impl Fn(f32, f32) -> bool) -> Mask4 {
        Mask4([f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])])
    }

    impl F32x4 {
        pub fn splat(v: f32) -> Self {
            F32x4([v; 4])
        }
        pub fn load(a: &[f32; 4]) -> Self {
            F32x4(*a)
        }
        pub fn to_array(self) -> [f32; 4] {
            self.0
        }
        pub fn min(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| if x < y { x } else { y }))
        }
        pub fn max(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| if x > y { x } else { y }))
        }
        pub fn le(self, b: Self) -> Mask4 {
            cmp(self.0, b.0, |x, y| x <= y)
        }
        pub fn lt(self, b: Self) -> Mask4 {
            cmp(self.0, b.0, |x, y| x < y)
        }
        pub fn gt(self, b: Self) -> Mask4 {
            cmp(self.0, b.0, |x, y| x > y)
        }
        pub fn eq(self, b: Self) -> Mask4 {
            cmp(self.0, b.0, |x, y| x == y)
        }
        pub fn ne(self, b: Self) -> Mask4 {
            cmp(self.0, b.0, |x, y| x != y)
        }
        pub fn abs(self) -> Self {
            F32x4(self.0.map(f32::abs))
        }
        pub fn is_finite(self) -> Mask4 {
            Mask4(self.0.map(f32::is_finite))
        }
    }
    impl std::ops::Add for F32x4 {
        type Output = Self;
        fn add(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| x + y))
        }
    }
    impl std::ops::Sub for F32x4 {
        type Output = Self;
        fn sub(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| x - y))
        }
    }
    impl std::ops::Mul for F32x4 {
        type Output = Self;
        fn mul(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| x * y))
        }
    }
    impl std::ops::Div for F32x4 {
        type Output = Self;
        fn div(self, b: Self) -> Self {
            F32x4(map(self.0, b.0, |x, y| x / y))
        }
    }

    #[derive(Clone, Copy, Debug)]
    pub struct Mask4([bool; 4]);

    impl Mask4 {
        pub fn bits(self) -> u32 {
            self.0.iter().enumerate().map(|(i, &b)| u32::from(b) << i).sum()
        }
    }
    impl std::ops::BitAnd for Mask4 {
        type Output = Self;
        fn bitand(self, b: Self) -> Self {
            Mask4([self.0[0] & b.0[0], self.0[1] & b.0[1], self.0[2] & b.0[2], self.0[3] & b.0[3]])
        }
    }
    impl std::ops::BitOr for Mask4 {
        type Output = Self;
        fn bitor(self, b: Self) -> Self {
            Mask4([self.0[0] | b.0[0], self.0[1] | b.0[1], self.0[2] | b.0[2], self.0[3] | b.0[3]])
        }
    }
}

pub use imp::F32x4;
