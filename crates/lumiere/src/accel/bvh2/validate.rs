//! Structural invariants of a built BVH, checked in debug builds and by the tests.

use super::Bvh;
use crate::geometry::triangle::is_degenerate;

/// Every slot reachable exactly once, every triangle in at least one slot, children inside their
/// parent, leaves within size limits and bounding their triangles (a triangle in several leaves, cut
/// by spatial splits: each of its corners in one of them), no cycles.
pub fn validate(bvh: &Bvh) -> Result<(), String> {
    let n = bvh.triangle_ids.len();
    if bvh.vertices.len() != n || bvh.triangles > bvh.input_triangles || bvh.triangles > n {
        return Err(format!(
            "{n} slots / {} vertices for {} triangles of {} input triangles",
            bvh.vertices.len(),
            bvh.triangles,
            bvh.input_triangles
        ));
    }
    let mut slots_of_triangle = vec![0u32; bvh.input_triangles];
    for &id in &bvh.triangle_ids {
        match slots_of_triangle.get_mut(id as usize) {
            Some(slots) => *slots += 1,
            None => return Err(format!("triangle id {id} exceeds the input")),
        }
    }
    if slots_of_triangle.iter().filter(|&&s| s > 0).count() != bvh.triangles {
        return Err(format!("the slots hold other than {} distinct triangles", bvh.triangles));
    }
    // Corners of the triangles in several leaves found inside one of them.
    let mut corners_bounded = vec![[false; 3]; bvh.input_triangles];
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
                let id = bvh.triangle_ids[slot] as usize;
                if slots_of_triangle[id] == 1 && !node.bounds().contains(&tri) {
                    return Err(format!("leaf {index} does not bound triangle slot {slot}"));
                }
                if !node.bounds().overlaps(&tri) {
                    return Err(format!("leaf {index} holds triangle slot {slot} outside its box"));
                }
                for (bounded, &corner) in corners_bounded[id].iter_mut().zip(&bvh.vertices[slot]) {
                    *bounded |= node.bounds().contains(&crate::math::Aabb::from_points(&[corner]));
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
    if let Some(id) = (0..bvh.input_triangles).find(|&id| slots_of_triangle[id] > 1 && corners_bounded[id] != [true; 3])
    {
        return Err(format!("a corner of triangle {id} is in none of its leaves"));
    }
    Ok(())
}
