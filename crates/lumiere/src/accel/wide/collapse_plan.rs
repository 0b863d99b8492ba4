//! Which binary nodes become wide nodes: the collapse that minimises the wide tree's surface area
//! heuristic, by dynamic programming over the binary tree (Ylitie, Karras and Laine, "Efficient
//! Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", 2017, section 4.1, here with the
//! binary tree's leaves kept as they are).
//!
//! Every leaf is one child of one wide node whatever the collapse, so the SAH of the wide tree
//! differs between collapses only in its nodes: the plan minimises the summed surface area of the
//! binary nodes that become wide nodes, in proportion to the wide nodes a random ray visits. Greedily
//! opening the largest child until a node has `W` (the classic collapse) fills every node, but it
//! cannot see that opening a smaller child, or leaving a large one whole to become a node of its
//! own further down, may cost less in all. The plan compares every way of spreading up to `W`
//! slots over a node's two subtrees, bottom-up, in `O(n W²)`.

use crate::accel::bvh2::{Bvh, Node};

/// How a binary subtree is best represented by at most `i` roots (`i` in `1..=W`), for every node.
pub(super) struct CollapsePlan<const W: usize> {
    /// `cost[n][i - 1]`: the least summed half area of the wide nodes below the at most `i` roots
    /// that stand for node `n`'s subtree (those roots included).
    cost: Vec<[f64; W]>,
    /// `split[n][i - 1]` for `i >= 2`: 0 if `i - 1` roots do as well, else how many of the `i`
    /// roots go to the left child (the rest to the right); `split[n][0]`: the same for the `W`
    /// children of `n` as a wide node.
    split: Vec<[u8; W]>,
}

impl<const W: usize> CollapsePlan<W> {
    /// The plan of `bvh`, whose root is an interior node.
    pub(super) fn new(bvh: &Bvh) -> Self {
        let nodes = bvh.nodes();
        let mut plan = CollapsePlan { cost: vec![[0.0; W]; nodes.len()], split: vec![[0; W]; nodes.len()] };
        // Children before parents: the reverse of a preorder walk.
        let mut preorder = Vec::with_capacity(nodes.len());
        let mut stack = vec![0usize];
        while let Some(index) = stack.pop() {
            preorder.push(index);
            if !nodes[index].is_leaf() {
                stack.push(nodes[index].first as usize + 1);
                stack.push(nodes[index].first as usize);
            }
        }
        for &index in preorder.iter().rev() {
            plan.solve(nodes, index);
        }
        plan
    }

    fn solve(&mut self, nodes: &[Node], index: usize) {
        let node = &nodes[index];
        if node.is_leaf() {
            // A leaf is one child however many slots it is offered, and no wide node.
            return;
        }
        let (left, right) = (node.first as usize, node.first as usize + 1);
        // `spread[slots - 1]`: the best spread of `slots` roots over the two subtrees (each gets
        // at least one), as its cost and the roots that go left (`slots` from 2).
        let mut spread = [(f64::INFINITY, 0u8); W];
        for slots in 2..=W {
            for to_left in 1..slots {
                let cost = self.cost[left][to_left - 1] + self.cost[right][slots - to_left - 1];
                // The first spread is taken whatever its cost: boxes wider than f32's range have
                // infinite areas, and a spread must still give each side a root.
                if to_left == 1 || cost < spread[slots - 1].0 {
                    spread[slots - 1] = (cost, to_left as u8);
                }
            }
        }
        let mut cost = [0.0; W];
        let mut split = [0u8; W];
        (cost[0], split[0]) = (node.bounds().half_area() + spread[W - 1].0, spread[W - 1].1);
        for slots in 2..=W {
            let (spread_cost, to_left) = spread[slots - 1];
            // Fewer roots on a tie: the parent keeps slots for its other children.
            (cost[slots - 1], split[slots - 1]) =
                if spread_cost < cost[slots - 2] { (spread_cost, to_left) } else { (cost[slots - 2], 0) };
        }
        self.cost[index] = cost;
        self.split[index] = split;
    }

    /// Writes the binary nodes that become the children of interior node `index` as a wide node
    /// into `children`, and returns their number.
    pub(super) fn children_of(&self, nodes: &[Node], index: usize, children: &mut [usize; W]) -> usize {
        let node = &nodes[index];
        let to_left = self.split[index][0] as usize;
        let count = self.roots(nodes, node.first as usize, to_left, children, 0);
        self.roots(nodes, node.first as usize + 1, W - to_left, children, count)
    }

    /// Writes the at most `slots` roots that stand for the subtree of `index` from `children[at]`
    /// on; returns the index after the last.
    fn roots(&self, nodes: &[Node], index: usize, slots: usize, children: &mut [usize; W], at: usize) -> usize {
        if slots == 1 || nodes[index].is_leaf() {
            children[at] = index;
            return at + 1;
        }
        match self.split[index][slots - 1] as usize {
            0 => self.roots(nodes, index, slots - 1, children, at),
            to_left => {
                let node = &nodes[index];
                let at = self.roots(nodes, node.first as usize, to_left, children, at);
                self.roots(nodes, node.first as usize + 1, slots - to_left, children, at)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh2::BuildPreset;

    /// A binary tree over `count` small scattered triangles (a fixed pseudo-random scene).
    fn scattered_tree<const W: usize>(count: usize) -> Bvh {
        let mut next = crate::accel::wide::unit_floats(0x2545_F491_4F6C_DD1Du64);
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        for i in 0..count as u32 {
            let centre = Vec3::new(next(), next(), next()) * 10.0;
            for _ in 0..3 {
                positions.push(centre + Vec3::new(next(), next(), next()) * 0.5);
            }
            indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        Bvh::build_for_width::<W>(&positions, &indices, BuildPreset::Default)
    }

    /// The children of wide node `index` if the binary interior nodes in `wide` become the wide
    /// nodes: its nearest descendants that are leaves or wide nodes themselves.
    fn frontier(nodes: &[Node], wide: &[bool], index: usize, out: &mut Vec<usize>) {
        for child in [nodes[index].first as usize, nodes[index].first as usize + 1] {
            if nodes[child].is_leaf() || wide[child] {
                out.push(child);
            } else {
                frontier(nodes, wide, child, out);
            }
        }
    }

    /// Every choice of the binary interior nodes that become wide nodes (the root always does),
    /// kept where no wide node has more than `W` children: the least summed half area.
    fn least_area_by_enumeration<const W: usize>(bvh: &Bvh) -> f64 {
        let nodes = bvh.nodes();
        let interior: Vec<usize> = (1..nodes.len()).filter(|&i| !nodes[i].is_leaf()).collect();
        assert!(interior.len() <= 16, "{} interior nodes: too many to enumerate", interior.len());
        let mut least = f64::INFINITY;
        for subset in 0u32..1 << interior.len() {
            let mut wide = vec![false; nodes.len()];
            wide[0] = true;
            for (bit, &index) in interior.iter().enumerate() {
                wide[index] = subset & 1 << bit != 0;
            }
            let mut area = 0.0;
            let mut fits = true;
            for index in (0..nodes.len()).filter(|&i| wide[i]) {
                let mut children = Vec::new();
                frontier(nodes, &wide, index, &mut children);
                fits &= children.len() <= W;
                area += nodes[index].bounds().half_area();
            }
            if fits {
                least = least.min(area);
            }
        }
        least
    }

    /// Follows the plan from the root: the wide nodes' summed half area, after checking that no
    /// node gets more than `W` children and that every leaf is a child exactly once.
    fn planned_area<const W: usize>(bvh: &Bvh, plan: &CollapsePlan<W>) -> f64 {
        let nodes = bvh.nodes();
        let mut leaves_seen = vec![0; nodes.len()];
        let (mut area, mut pending) = (0.0, vec![0usize]);
        while let Some(index) = pending.pop() {
            area += nodes[index].bounds().half_area();
            let mut children = [usize::MAX; W];
            let count = plan.children_of(nodes, index, &mut children);
            assert!((2..=W).contains(&count), "node {index}: {count} children");
            for &child in &children[..count] {
                if nodes[child].is_leaf() {
                    leaves_seen[child] += 1;
                } else {
                    pending.push(child);
                }
            }
        }
        for (index, node) in nodes.iter().enumerate() {
            assert_eq!(leaves_seen[index], usize::from(node.is_leaf()), "leaf {index}");
        }
        area
    }

    fn plan_is_the_least_area_collapse<const W: usize>(triangles: &[usize]) {
        for &count in triangles {
            let bvh = scattered_tree::<W>(count);
            let plan = CollapsePlan::<W>::new(&bvh);
            let planned = planned_area(&bvh, &plan);
            let least = least_area_by_enumeration::<W>(&bvh);
            assert!((planned - least).abs() <= 1e-9 * least, "W = {W}, {count} triangles: {planned} > {least}");
        }
    }

    /// Against every collapse of small trees (up to 17 interior nodes), at both widths rendered.
    #[test]
    fn collapse_plan_is_the_least_area_collapse() {
        plan_is_the_least_area_collapse::<4>(&[20, 40, 60, 70]);
        plan_is_the_least_area_collapse::<8>(&[80, 120, 140, 160]);
    }
}
