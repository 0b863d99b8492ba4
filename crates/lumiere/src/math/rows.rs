//! Vectors of `N` lanes stored SoA, as the lane loops that the compiler vectorises keep them: a
//! row of x, one of y, one of z.

use glam::Vec3;

/// `N` vectors, SoA: `rows[axis][lane]`.
pub type Rows<const N: usize> = [[f32; N]; 3];

/// The vector of lane `lane`.
#[inline(always)]
pub fn row<const N: usize>(rows: &Rows<N>, lane: usize) -> Vec3 {
    Vec3::new(rows[0][lane], rows[1][lane], rows[2][lane])
}

/// Sets the vector of lane `lane` to `v`.
#[inline(always)]
pub fn set_row<const N: usize>(rows: &mut Rows<N>, lane: usize, v: Vec3) {
    [rows[0][lane], rows[1][lane], rows[2][lane]] = v.to_array();
}
