//! Quad lights: two light triangles that share an edge, lie in one plane and together form a convex
//! quadrilateral, which is how OBJ files write a rectangular area light (the Cornell boxes' lights).
//!
//! Every shadow segment towards a point of either triangle stays inside the shaft from the receiver
//! to the quad, so direct lighting gathers the segments' candidate blockers once for both triangles
//! instead of once each (see `integrators/direct.rs`). The quad is given by the triangles' shadow
//! targets, where those segments end.

use std::collections::HashMap;

use glam::{Vec3, Vec4};

use super::AreaLight;

/// The shadow targets of a pair of light triangles as one convex quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadLight {
    /// The corners in order around the quad (the first triangle's unshared corner, a shared one,
    /// the second triangle's unshared corner, the other shared one).
    pub corners: [Vec3; 4],
    /// The plane the segments end on, `n . x + w`, its normal towards the emitting side, placed so
    /// that every shadow target of both triangles lies on it or in front of it: nothing on or
    /// behind it can block a segment.
    pub plane: Vec4,
}

/// The normals of two triangles of one quad agree to this cosine (a quad split along a diagonal
/// gives two normals equal to a few ulps).
const COPLANAR_COSINE: f32 = 1.0 - 1e-5;

/// The quads of a light list, and each light's quad.
#[derive(Clone, Debug)]
pub(super) struct Quads {
    pub quads: Vec<QuadLight>,
    /// Per light, the index of its quad in `quads`, or `NO_QUAD`.
    pub quad_of_light: Vec<u32>,
}

pub(super) const NO_QUAD: u32 = u32::MAX;

/// Pairs the lights into quads where they can be: each light belongs to at most one quad; two
/// lights pair when they share an edge (its two vertices, bit for bit), their normals agree and
/// the four corners turn the same way at each corner (a strictly convex quad). Linear in the
/// number of lights (edges are matched through a hash map).
pub(super) fn pair_lights(lights: &[AreaLight]) -> Quads {
    // Edge `k` of a light (corners `k` and `k + 1`), whichever way it runs.
    let edge = |light: &AreaLight, k: usize| {
        let key = |v: Vec3| v.to_array().map(f32::to_bits);
        let (a, b) = (key(light.vertices[k]), key(light.vertices[(k + 1) % 3]));
        if a < b { (a, b) } else { (b, a) }
    };
    let mut by_edge: HashMap<([u32; 3], [u32; 3]), Vec<u32>> = HashMap::new();
    for (index, light) in lights.iter().enumerate() {
        for k in 0..3 {
            by_edge.entry(edge(light, k)).or_default().push(index as u32);
        }
    }
    let mut quads = Vec::new();
    let mut quad_of_light = vec![NO_QUAD; lights.len()];
    // Visited in light order, so that the pairing does not depend on the map's iteration order.
    for (index, light) in lights.iter().enumerate() {
        for k in 0..3 {
            if quad_of_light[index] != NO_QUAD {
                break;
            }
            // An edge of exactly two lights (a fan of three or more around one edge is no quad).
            let sharing = &by_edge[&edge(light, k)];
            if sharing.len() != 2 {
                continue;
            }
            let other = if sharing[0] as usize == index { sharing[1] } else { sharing[0] };
            if quad_of_light[other as usize] != NO_QUAD {
                continue;
            }
            if let Some(quad) = quad_of(lights, index as u32, other, k) {
                quad_of_light[index] = quads.len() as u32;
                quad_of_light[other as usize] = quads.len() as u32;
                quads.push(quad);
            }
        }
    }
    Quads { quads, quad_of_light }
}

/// The quad of lights `first` and `second`, which share `first`'s edge `edge` (vertices `edge` and
/// `edge + 1`), if they are coplanar and strictly convex together.
fn quad_of(lights: &[AreaLight], first: u32, second: u32, edge: usize) -> Option<QuadLight> {
    let (l1, l2) = (&lights[first as usize], &lights[second as usize]);
    if l1.normal.dot(l2.normal) < COPLANAR_COSINE {
        return None;
    }
    let (u, v) = (edge, (edge + 1) % 3);
    let a = (edge + 2) % 3;
    // The second triangle's corner off the shared edge: the one equal to neither shared vertex.
    let b = (0..3).find(|&k| l2.vertices[k] != l1.vertices[u] && l2.vertices[k] != l1.vertices[v])?;
    // Around the quad: a, v, b, u (a and b are opposite corners, as are the shared u and v). Were
    // a and b on one side of the shared edge, this would cross itself and fail the convexity test.
    // The walk goes from a to v, against the first triangle's winding (u, v, a), so it turns
    // clockwise about the normal: a strictly convex quad turns the negative way at every corner.
    let positions = [l1.vertices[a], l1.vertices[v], l2.vertices[b], l1.vertices[u]];
    let strictly_convex = (0..4).all(|k| {
        let (p, q, r) = (positions[k], positions[(k + 1) % 4], positions[(k + 2) % 4]);
        (q - p).cross(r - q).dot(l1.normal) < 0.0
    });
    if !strictly_convex {
        return None;
    }
    let corners = [l1.shadow_targets[a], l1.shadow_targets[v], l2.shadow_targets[b], l1.shadow_targets[u]];
    // Through the first triangle's targets, then moved back behind any target of the second that
    // lies behind it (by a few ulps at most; twice that, so that rounding cannot undo it).
    let n = l1.normal;
    let w = -n.dot(l1.shadow_targets[0]);
    let lowest = l1.shadow_targets.iter().chain(&l2.shadow_targets).map(|t| n.dot(*t) + w).fold(0.0f32, f32::min);
    Some(QuadLight { corners, plane: n.extend(w - 2.0 * lowest) })
}
