//! Faces of more than three corners that are not convex, split again by ear clipping.
//!
//! Faces are split as fans `(a,b,c), (a,c,d), …` while they are parsed: gKit numbers triangles
//! that way, and a chunk may not have the positions its faces name yet. A fan covers a convex
//! polygon exactly, but across a concave one (an L, a star, a floor plan) it lays triangles outside
//! the polygon, over the notch, and leaves parts of it uncovered, where Blender keeps the polygon
//! and tinyobjloader ear-clips it. Once the mesh is whole, each such face's fan is replaced, in
//! place, by an ear clipping of the polygon projected on its plane: as many triangles (n - 2), so
//! no later triangle id moves, and the same winding. Convex faces keep their fan and gKit's ids.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::error::shown_path;
use crate::scene::load::warnings::Warnings;
use crate::scene::mesh::TriangleMesh;
use std::path::Path;

/// A face of more than three corners: its fan's first triangle and its corner count.
#[derive(Clone, Copy, Debug)]
pub(in crate::scene::load) struct Polygon {
    pub(in crate::scene::load) first_triangle: usize,
    pub(in crate::scene::load) corners: usize,
}

/// The most corners a concave face may have to be ear-clipped; larger ones keep their fan (and a
/// warning says how many). Ear clipping tests every corner against every candidate ear, so its
/// work grows as the cube of the corners.
const MAX_CLIPPED_CORNERS: usize = 64;

/// Corner-against-ear tests a whole file may ask for (a few tenths of a second): past them, the
/// concave faces left keep their fans. Real faces find an ear within a few tries, a few thousand
/// tests for 64 corners; a file of hundreds of thousands of faces shaped to find theirs last
/// would otherwise take minutes.
const WORK_BUDGET: u64 = 50_000_000;

/// The concave faces that keep their fan, by reason.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::scene::load) struct Unclipped {
    /// More than [`MAX_CLIPPED_CORNERS`] corners.
    too_large: usize,
    /// Met after the file's [`WORK_BUDGET`] was spent.
    out_of_budget: usize,
}

impl Unclipped {
    /// One warning per reason that left faces of `file` unclipped.
    pub(in crate::scene::load) fn warn(self, warnings: &mut Warnings, file: &Path) {
        let Unclipped { too_large, out_of_budget } = self;
        if too_large > 0 {
            warnings.push(file, "concave faces too large to split", || {
                format!(
                    "{}: {too_large} concave face(s) of more than {MAX_CLIPPED_CORNERS} corners keep their fan of triangles, which covers them wrongly",
                    shown_path(file)
                )
            });
        }
        if out_of_budget > 0 {
            warnings.push(file, "concave faces past the splitting budget", || {
                format!(
                    "{}: {out_of_budget} concave face(s) keep their fan of triangles, which covers them wrongly: splitting the file's concave faces took too long",
                    shown_path(file)
                )
            });
        }
    }
}

/// Replaces the fan of every concave face of `polygons` (whose triangles `mesh` holds as the parser
/// made them) by an ear clipping of it, in file order; returns what was left unclipped.
pub(in crate::scene::load) fn clip_concave_faces(mesh: &mut TriangleMesh, polygons: &[Polygon]) -> Unclipped {
    // Told apart in parallel (a mesh of quads has millions of faces), as one flag per face: an
    // indexed collection into one buffer, where collecting the concave faces themselves went
    // through a list of buffers per task (a third of the pass on a mesh of warped quads). Each
    // thread reuses one buffer of points: most faces are quads, tested once, for which an
    // allocation would cost more than the test.
    let concave: Vec<bool> = polygons
        .par_iter()
        .map_init(Vec::new, |points, polygon| {
            if polygon.corners == 4 {
                return !quad_fan_covers(mesh, polygon);
            }
            project(mesh, polygon, points);
            !is_convex(points)
        })
        .collect();
    let mut unclipped = Unclipped::default();
    let mut budget = WORK_BUDGET;
    let (mut points, mut corners) = (Vec::new(), Vec::new());
    for (polygon, _) in polygons.iter().zip(concave).filter(|&(_, concave)| concave) {
        if polygon.corners > MAX_CLIPPED_CORNERS {
            unclipped.too_large += 1;
            continue;
        }
        let clipped;
        let ears: &[[usize; 3]] = if polygon.corners == 4 {
            // The other diagonal, 1-3, lies inside where 0-2 does not (see `quad_fan_covers`).
            &[[0, 1, 3], [1, 2, 3]]
        } else {
            project(mesh, polygon, &mut points);
            let Some(ears) = ear_clip(&points, &mut budget) else {
                unclipped.out_of_budget += 1;
                continue;
            };
            clipped = ears;
            &clipped
        };
        let first = polygon.first_triangle;
        for list in [&mut mesh.indices, &mut mesh.texcoord_indices, &mut mesh.normal_indices] {
            // Attribute lists are empty when no triangle has the attribute.
            if list.is_empty() {
                continue;
            }
            corners.clear();
            corners.extend((0..polygon.corners).map(|k| fan_corner(list, polygon, k)));
            for (triangle, ear) in list[first..].iter_mut().zip(ears) {
                *triangle = ear.map(|corner| corners[corner]);
            }
        }
    }
    unclipped
}

/// Corner `k` of a face, from its fan `(c0, c1, c2), (c0, c2, c3), …` in `triangles`.
fn fan_corner(triangles: &[[u32; 3]], polygon: &Polygon, k: usize) -> u32 {
    let fan = &triangles[polygon.first_triangle..];
    match k {
        0 | 1 => fan[0][k],
        _ => fan[k - 2][2],
    }
}

/// Whether a quad's fan `(0,1,2), (0,2,3)` covers it: both triangles face the side of the quad's
/// Newell normal (for four corners, the cross product of the diagonals), so the diagonal 0-2 lies
/// inside. A corner that turns back at 1 or 3 turns one of them over; at 0 or 2, the diagonal
/// from it is the one inside, and ear clipping would give the fan too. Products of differences
/// where the general test projects the face: quads are most faces of four corners or more.
fn quad_fan_covers(mesh: &TriangleMesh, polygon: &Polygon) -> bool {
    let fan = &mesh.indices[polygon.first_triangle..];
    let corner = |t: usize, k: usize| mesh.positions[fan[t][k] as usize].as_dvec3();
    let [p0, p1, p2, p3] = [corner(0, 0), corner(0, 1), corner(0, 2), corner(1, 2)];
    let normal = (p2 - p0).cross(p3 - p1);
    // A triangle of no area (three corners on a line) keeps the fan, as `is_convex` keeps it.
    (p1 - p0).cross(p2 - p0).dot(normal) >= 0.0 && (p2 - p0).cross(p3 - p0).dot(normal) >= 0.0
}

/// A face's corners, into `points`, on the plane it faces most (its Newell normal's dominant axis
/// dropped, the other two ordered so that it winds counter-clockwise there), in f64: the tests
/// below compare products of differences.
fn project(mesh: &TriangleMesh, polygon: &Polygon, points: &mut Vec<DVec2>) {
    let position = |k: usize| mesh.positions[fan_corner(&mesh.indices, polygon, k) as usize].as_dvec3();
    let mut normal = DVec3::ZERO;
    let (mut p, first) = (position(0), position(0));
    for k in 1..=polygon.corners {
        let q = if k == polygon.corners { first } else { position(k) };
        normal += DVec3::new((p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y));
        p = q;
    }
    let axis = normal.abs().max_position();
    let (mut u, mut v) = ((axis + 1) % 3, (axis + 2) % 3);
    if normal[axis] < 0.0 {
        std::mem::swap(&mut u, &mut v);
    }
    points.clear();
    points.extend((0..polygon.corners).map(|k| {
        let p = position(k);
        DVec2::new(p[u], p[v])
    }));
}

/// Twice the signed area of `(a, b, c)`: positive when they turn counter-clockwise.
fn orientation(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Whether no corner of the (counter-clockwise) polygon turns clockwise. A polygon whose plane
/// could not be told (every corner on a line) counts as convex: its fan is as good as any.
fn is_convex(points: &[DVec2]) -> bool {
    let n = points.len();
    (0..n).all(|k| orientation(points[(k + n - 1) % n], points[k], points[(k + 1) % n]) >= 0.0)
}

/// Ear clipping: the n - 2 triangles (corner numbers, counter-clockwise as the polygon) of a
/// simple counter-clockwise polygon. An ear is a corner that turns counter-clockwise and whose
/// triangle with its neighbours holds no other corner. If none is left (a polygon that crosses
/// itself, or rounding), the corners that remain are closed as a fan, so that the count holds.
/// `None` if that takes more corner tests than `budget` has left (then spent).
fn ear_clip(points: &[DVec2], budget: &mut u64) -> Option<Vec<[usize; 3]>> {
    let mut remaining: Vec<usize> = (0..points.len()).collect();
    let mut ears = Vec::with_capacity(points.len() - 2);
    while remaining.len() > 3 {
        let Some(at) = find_ear(points, &remaining, budget)? else { break };
        let n = remaining.len();
        ears.push([remaining[(at + n - 1) % n], remaining[at], remaining[(at + 1) % n]]);
        remaining.remove(at);
    }
    ears.extend(remaining.windows(2).skip(1).map(|pair| [remaining[0], pair[0], pair[1]]));
    Some(ears)
}

/// The position in `remaining` of an ear: a strictly convex one, or else a corner on the line of
/// its neighbours (cut as a triangle of no area, which no ray hits), or none; `None` (the outer
/// one) once `budget` cannot pay for the next candidate's tests.
fn find_ear(points: &[DVec2], remaining: &[usize], budget: &mut u64) -> Option<Option<usize>> {
    let n = remaining.len();
    let corner = |k: usize| points[remaining[k % n]];
    let mut is_ear = |at: usize, strictly: bool| {
        *budget = budget.checked_sub(n as u64)?;
        let (a, b, c) = (corner(at + n - 1), corner(at), corner(at + 1));
        let turn = orientation(a, b, c);
        let convex = if strictly { turn > 0.0 } else { turn >= 0.0 };
        Some(
            convex
                && remaining.iter().map(|&i| points[i]).all(|p| {
                    // A corner that repeats one of the ear's lies on it without being inside.
                    let inside =
                        orientation(a, b, p) >= 0.0 && orientation(b, c, p) >= 0.0 && orientation(c, a, p) >= 0.0;
                    !inside || p == a || p == b || p == c
                }),
        )
    };
    for strictly in [true, false] {
        for at in 0..n {
            if is_ear(at, strictly)? {
                return Some(Some(at));
            }
        }
    }
    Some(None)
}
