//! Occlusion of up to 32 rays leaving one point in any directions (ambient occlusion's probes,
//! shadow segments to many light points), walking the wide BVH together.
//!
//! Rays from one point share the nodes around it: on the 1.1M-triangle bunny, the nodes sixteen
//! probes of a point visit one by one are five times the distinct nodes among them, and their
//! blocks three times. Walked together, each node is fetched once and tested against every ray
//! that reached it, ray-major (one lane per ray, `W` rays per vector of the BVH's kernel: left to
//! the compiler, the loops over the rays came out in 4- and 8-lane pieces, 9-14% slower on the
//! bunny's ambient occlusion); each triangle block is tested ray by ray, with
//! the single-ray kernel, for the rays that reached it. A subtree that few rays entered is left to
//! the single-ray walk, whose test takes a node's `W` boxes in one vector. Children are visited
//! nearest to the origin first, or farthest first (`accel/visit_order.rs` chooses): one distance
//! per child serves all the rays, whatever their directions.
//!
//! Unlike [`super::RayPacket`], the rays need not share their direction signs: the origin is
//! common, so each box plane minus the origin is one number for all rays, and each lane picks its
//! entry and exit planes by its own signs. Every lane performs the single-ray slab test's
//! operations, so a ray reaches exactly the nodes it would reach alone, and is tested against the
//! same blocks with the same kernel: the answers are the single rays' (order does not matter to
//! "is anything in the way").

use glam::Vec3;

use super::WideBvh;
use super::leaf::{self, LEAF_BIT};
use super::node::{EMPTY_CHILD, WideNode};
use super::traverse::{BoxRay, Stack};
use super::triangles::{TriangleRay, intersect_block};
use crate::accel::simd::{LaneMask, Lanes, lanes_of, max_ps};
use crate::accel::slab::{BOX_EXPANSION, PRUNE_SLACK, safe_reciprocal};
use crate::accel::{TraversalStats, VisitOrder};
use crate::geometry::triangle::WatertightRay;
use crate::math::Ray;

/// Subtrees that at most half of the rays entered are walked ray by ray. A node's ray-major test
/// costs the same however many rays entered it, about what eight single-ray tests of its `W` boxes
/// do: on the 1.1M-triangle bunny (ambient occlusion, 16 probes), walking subtrees of at most 1, 2,
/// 4, 6, 8 and 11 of the 16 rays alone took 1,341, 1,255, 1,197, 1,181, 1,176 and 1,181 ms (and,
/// once the rays were splatted only where used, a third, half and two thirds within 1%).
const fn alone_below(rays: usize) -> u32 {
    rays as u32 / 2
}

/// The rays of a walk, SoA, with what the per-lane slab test needs.
struct Rays<const N: usize> {
    origin: [f32; 3],
    /// Per axis and lane, the reciprocal of the direction component (`safe_reciprocal`, which
    /// keeps its sign: a negative one enters through the max plane, as the single-ray walk's
    /// `near_row` decides).
    inv_dir: [[f32; N]; 3],
    limit: f32,
}

impl<const N: usize> Rays<N> {
    /// Which of `lanes` enter child `child` of `node` (the single-ray slab test, one lane per ray,
    /// `W` rays per vector of the kernel `L`).
    #[inline(always)]
    fn enter<const W: usize, L: Lanes<W>>(&self, node: &WideNode<W>, child: usize, lanes: u32) -> u32 {
        const { assert!(N.is_multiple_of(W), "the rays fill whole vectors") };
        // The plane minus the origin: one number per plane, whatever the ray.
        let low: [L; 3] = std::array::from_fn(|axis| L::splat(node.bounds[axis][child] - self.origin[axis]));
        let high: [L; 3] = std::array::from_fn(|axis| L::splat(node.bounds[axis + 3][child] - self.origin[axis]));
        let mut mask = 0u32;
        for first in (0..N).step_by(W) {
            let mut near = L::splat(0.0);
            let mut far = L::splat(self.limit);
            for axis in 0..3 {
                let inv_dir = L::load(self.inv_dir[axis][first..first + W].try_into().expect("W lanes"));
                let entry = L::select_by_sign(inv_dir, high[axis], low[axis]);
                let exit = L::select_by_sign(inv_dir, low[axis], high[axis]);
                near = near.max(entry * inv_dir);
                far = far.min(exit * inv_dir * L::splat(BOX_EXPANSION));
            }
            mask |= near.le(far).bits() << first;
        }
        mask & lanes
    }
}

/// The squared distance from `origin` to each child box of `node` (0 inside; NaN for an empty
/// slot): rays leaving `origin` tend to meet nearer boxes first, whatever their directions.
#[inline(always)]
fn distances_from<const W: usize>(node: &WideNode<W>, origin: &[f32; 3]) -> [f32; W] {
    let mut squared = [0.0f32; W];
    for (axis, &o) in origin.iter().enumerate() {
        let (low, high) = (&node.bounds[axis], &node.bounds[axis + 3]);
        for ((sum, &low), &high) in squared.iter_mut().zip(low).zip(high) {
            let gap = max_ps(max_ps(0.0, low - o), o - high);
            *sum += gap * gap;
        }
    }
    squared
}

// Inlined into the caller, which runs it in its ISA's `Accel::simd`.
impl<const W: usize, L: Lanes<W>> WideBvh<W, L> {
    /// Which of the `live` rays (bit `i` for ray `i`) among `N <= 32` leaving `origin` with the
    /// directions `dirs` (SoA) and one `tmax` are blocked, as [`WideBvh::occluded`] answers each
    /// (bits outside `live` are 0), visiting children in `order`.
    #[inline(always)]
    pub fn occluded_from_origin<const N: usize>(
        &self,
        origin: Vec3,
        dirs: &[[f32; N]; 3],
        tmax: f32,
        live: u32,
        order: VisitOrder,
    ) -> u32 {
        const { assert!(N <= 32, "a lane mask is a u32") };
        if live == 0 {
            return 0;
        }
        let ray = |lane: usize| Ray { origin, dir: Vec3::new(dirs[0][lane], dirs[1][lane], dirs[2][lane]), tmax };
        // Lanes outside `live` take a live lane's ray: whatever their directions, they build
        // harmless vectors, and their bits are masked out.
        let first = live.trailing_zeros() as usize;
        // Kept scalar and splatted where a block is tested: sixteen rays splatted up front (4 KB)
        // were copied as a whole, which cost more than splatting them again and again.
        let triangle_rays: [WatertightRay; N] =
            std::array::from_fn(|lane| WatertightRay::new(&ray(if live & (1 << lane) != 0 { lane } else { first })));
        let rays = Rays {
            origin: origin.to_array(),
            inv_dir: dirs.map(|row| row.map(safe_reciprocal)),
            limit: tmax * PRUNE_SLACK,
        };

        let mut blocked = 0u32;
        let mut stack = Stack::<W, (u32, u32)>::new();
        stack.push((0, live));
        while let Some((reference, entered)) = stack.pop() {
            let lanes = entered & !blocked;
            if lanes == 0 {
                continue;
            }
            if lanes.count_ones() <= const { alone_below(N) } {
                for lane in lanes_of(lanes) {
                    let box_ray = BoxRay::<L>::new::<W>(&ray(lane));
                    let stats = &mut TraversalStats::default();
                    let hit = self.occluded_below::<false>(
                        reference,
                        &box_ray,
                        &TriangleRay::<L>::splat::<W>(triangle_rays[lane]),
                        tmax,
                        order,
                        stats,
                        |_, _, _| true,
                    );
                    blocked |= u32::from(hit) << lane;
                }
                continue;
            }
            if reference & LEAF_BIT != 0 {
                for block in &self.blocks[leaf::blocks::<W>(reference)] {
                    for lane in lanes_of(lanes & !blocked) {
                        blocked |= u32::from(
                            intersect_block(&TriangleRay::<L>::splat::<W>(triangle_rays[lane]), block, tmax).mask != 0,
                        ) << lane;
                    }
                }
                continue;
            }
            // The children some ray enters, the first to visit last, so that it is popped first.
            let node = &self.nodes[reference as usize];
            let distances = distances_from(node, &rays.origin);
            // Sorted by key, least key last (an empty slot's NaN is skipped either way).
            let keys = order.keys(distances);
            let mut children = [(0u32, 0u32, 0f32); W];
            let mut count = 0;
            for (slot, (&distance, &key)) in distances.iter().zip(&keys).enumerate() {
                let child = node.children[slot];
                if child == EMPTY_CHILD {
                    continue;
                }
                // Every ray leaves from inside a box that holds the origin (the slab test would
                // say so too; a distance that underflows to 0 only adds a box, never drops one).
                let mask = if distance == 0.0 { lanes } else { rays.enter::<W, L>(node, slot, lanes) };
                if mask == 0 {
                    continue;
                }
                let mut i = count;
                while i > 0 && children[i - 1].2 < key {
                    children[i] = children[i - 1];
                    i -= 1;
                }
                children[i] = (child, mask, key);
                count += 1;
            }
            for &(child, mask, _) in &children[..count] {
                stack.push((child, mask));
            }
        }
        blocked & live
    }
}
