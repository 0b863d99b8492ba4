//! The surface points of many hits at once: their corners gathered SoA by `World::surfaces`, then
//! one loop over the lanes that the compiler vectorises. Each lane does `World::surface`'s
//! operations in its order (glam's `cross`, `dot`, `normalize_or_zero` and `try_normalize`, which
//! work component by component), so the points have its bits. One point at a time, its two square
//! roots and divisions were a seventh of a hard-shadow render.

use glam::{Vec2, Vec3};

use super::surface::SurfacePoint;
use crate::math::rows::{Rows, row, set_row};

/// What the surface points of `N` hits are made from, one lane per hit, rows by axis.
pub struct HitCorners<const N: usize> {
    /// The corners' positions: `positions[corner][axis][lane]`.
    pub positions: [Rows<N>; 3],
    /// The corners' vertex normals, where `normals_given` is set.
    pub normals: [Rows<N>; 3],
    pub normals_given: [bool; N],
    /// The corners' texture coordinates, where `texcoords_given` is set.
    pub texcoords: [[[f32; N]; 2]; 3],
    pub texcoords_given: [bool; N],
    /// The hits' barycentrics of the second and third corners.
    pub u: [f32; N],
    pub v: [f32; N],
    /// The rays' directions.
    pub dir: Rows<N>,
}

/// The surface points' vectors, one lane per hit, rows by axis.
pub struct SurfaceRows<const N: usize> {
    pub p: Rows<N>,
    pub ng: Rows<N>,
    pub ns: Rows<N>,
    pub uv: [[f32; N]; 2],
    /// Bit `i` set where lane `i`'s ray arrived on the front of its triangle.
    pub front_faces: u32,
}

impl<const N: usize> Default for HitCorners<N> {
    fn default() -> Self {
        HitCorners {
            positions: [[[0.0; N]; 3]; 3],
            normals: [[[0.0; N]; 3]; 3],
            normals_given: [false; N],
            texcoords: [[[0.0; N]; 2]; 3],
            texcoords_given: [false; N],
            u: [0.0; N],
            v: [0.0; N],
            dir: [[0.0; N]; 3],
        }
    }
}

impl<const N: usize> HitCorners<N> {
    /// Every lane's surface vectors (lanes without a hit compute garbage, unused). Inline into
    /// `World::simd_256` so that the loop gets the ISA's width.
    #[inline(always)]
    pub fn surface_rows(&self) -> SurfaceRows<N> {
        const { assert!(N <= 32, "the front-face mask is a u32") };
        // Locals, not the fields of the result: the compiler does not vectorise the loop when its
        // mask shares memory with its rows.
        let rows = [[0.0; N]; 3];
        let (mut ps, mut ngs, mut nss, mut uvs, mut front_faces) = (rows, rows, rows, [[0.0; N]; 2], 0u32);
        let [p0, p1, p2] = &self.positions;
        let [n0, n1, n2] = &self.normals;
        let [t0, t1, t2] = &self.texcoords;
        for lane in 0..N {
            let (u, v) = (self.u[lane], self.v[lane]);
            let w = 1.0 - u - v;
            let (a, b, c) = (row(p0, lane), row(p1, lane), row(p2, lane));
            let p = w * a + u * b + v * c;
            let geometric = (b - a).cross(c - a);
            let (unit, normalized) = normalize(geometric);
            let geometric = if normalized { unit } else { Vec3::ZERO };
            let front_face = geometric.dot(row(&self.dir, lane)) <= 0.0;
            let ng = if front_face { geometric } else { -geometric };
            // The interpolated vertex normal (`try_normalize`), turned to `ng`'s side, or `ng`.
            let (n, normalized) = normalize(w * row(n0, lane) + u * row(n1, lane) + v * row(n2, lane));
            let turned = if n.dot(ng) < 0.0 { -n } else { n };
            let ns = if self.normals_given[lane] & normalized { turned } else { ng };
            let texcoord = |rows: &[[f32; N]; 2]| Vec2::new(rows[0][lane], rows[1][lane]);
            let uv = w * texcoord(t0) + u * texcoord(t1) + v * texcoord(t2);
            let uv = if self.texcoords_given[lane] { uv } else { Vec2::ZERO };
            set_row(&mut ps, lane, p);
            set_row(&mut ngs, lane, ng);
            set_row(&mut nss, lane, ns);
            [uvs[0][lane], uvs[1][lane]] = uv.to_array();
            front_faces |= u32::from(front_face) << lane;
        }
        SurfaceRows { p: ps, ng: ngs, ns: nss, uv: uvs, front_faces }
    }
}

impl<const N: usize> SurfaceRows<N> {
    /// Lane `lane`'s point, on triangle `triangle` of material `material`.
    #[inline(always)]
    pub fn point(&self, lane: usize, triangle: u32, material: u32) -> SurfacePoint {
        SurfacePoint {
            p: row(&self.p, lane),
            ng: row(&self.ng, lane),
            ns: row(&self.ns, lane),
            uv: Vec2::new(self.uv[0][lane], self.uv[1][lane]),
            triangle,
            material,
            front_face: self.front_faces >> lane & 1 != 0,
        }
    }
}

/// glam's `try_normalize` without its branch: `v · (1 / |v|)`, and whether that reciprocal is
/// finite and positive (where glam returns `None`).
#[inline(always)]
fn normalize(v: Vec3) -> (Vec3, bool) {
    let rcp = v.length_recip();
    (v * rcp, rcp.is_finite() & (rcp > 0.0))
}
