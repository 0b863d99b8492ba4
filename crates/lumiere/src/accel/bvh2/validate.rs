//! Structural invariants of a built BVH, checked in debug builds and by the tests.

use super::Bvh;
use crate::geometry::triangle::is_degenerate;

/// Every non-degenerate input triangle reachable exactly once, children inside their parent, leaves
/// within size limits, leaf-ordered vertices matching the ids, no cycles.
pub fn validate(bvh: &Bvh) -> Result<(), String> {
    let n = bvh.triangle_ids.len();
    if bvh.vertices.len() != n || n > bvh.input_triangles {
        return Err(format!("{n} ids / {} vertices for {} input triangles", bvh.vertices.len(), bvh.input_triangles));
    }
    if let Some(slot) = (0..n).find(|&i| {
        let [p0, p1, p2] = bvh.vertices[i];
        is_degenerate(p0, p1, p2)
    }) {
        return Err(format!("degenerate triangle in slot {slot}"));
    }
    if bvh.nodes.is_empty() {
        return Err("no root node".into());
    }
    if n == 0 {
        return if bvh.nodes.len() == 1 { Ok(()) } else { Err("empty BVH with several nodes".into()) };
    }
    let mut seen_triangle = vec![false; n];
    let mut seen_node = vec![false; bvh.nodes.len()];
    let mut stack = vec![(0usize, 0usize)];
    while let Some((index, depth)) = stack.pop() {
        if std::mem::replace(&mut seen_node[index], true) {
            return Err(format!("node {index} reached twice"));
        }
        if depth > super::build::MAX_DEPTH {
            return Err(format!("node {index} at depth {depth}"));
        }
        let node = &bvh.nodes[index];
        if node.is_leaf() {
            let (first, count) = (node.first as usize, node.count as usize);
            if count > super::build::MAX_LEAF_SIZE || first + count > n {
                return Err(format!("leaf {index} holds {first}..{}", first + count));
            }
            for (slot, seen) in seen_triangle.iter_mut().enumerate().skip(first).take(count) {
                if std::mem::replace(seen, true) {
                    return Err(format!("triangle slot {slot} in two leaves"));
                }
                let tri = crate::math::Aabb::from_points(&bvh.vertices[slot]);
                if !node.bounds().contains(&tri) {
                    return Err(format!("leaf {index} does not bound triangle slot {slot}"));
                }
            }
        } else {
            let first = node.first as usize;
            if first == 0 || first + 1 >= bvh.nodes.len() {
                return Err(format!("node {index} has children at {first}"));
            }
            for child in [first, first + 1] {
                if !node.bounds().contains(&bvh.nodes[child].bounds()) {
                    return Err(format!("child {child} outside its parent {index}"));
                }
                stack.push((child, depth + 1));
            }
        }
    }
    if let Some(slot) = seen_triangle.iter().position(|s| !s) {
        return Err(format!("triangle slot {slot} unreachable"));
    }
    let mut ids = bvh.triangle_ids.clone();
    ids.sort_unstable();
    if ids.windows(2).any(|w| w[0] == w[1]) || ids.last().is_some_and(|&id| id as usize >= bvh.input_triangles) {
        return Err("triangle ids repeat or exceed the input".into());
    }
    Ok(())
}
