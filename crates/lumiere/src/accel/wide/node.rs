//! The wide layout's two hot types, generic in the width `W` and sized in whole cache lines or SIMD
//! rows, with their byte budgets asserted at compile time for every width that is instantiated.

/// Unused child slot; its box is NaN so no ray ever enters it.
pub(super) const EMPTY_CHILD: u32 = u32::MAX;

/// Up to `W` children: their boxes as SoA rows (min x, y, z then max x, y, z; one lane per child)
/// and their references (a node index, or a leaf: see `leaf.rs`). `32 * W` bytes aligned to cache
/// lines: two lines and one 16-byte load per row at `W = 4` (Dammertz et al., "Shallow Bounding
/// Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays", 2008; tinybvh's `BVH4_CPU`).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNode<const W: usize> {
    pub bounds: [[f32; W]; 6],
    pub children: [u32; W],
    /// The children's slots from near to far for rays of each octant of directions (see
    /// [`WideNode::near_to_far`]): 4 bits a slot, `W` slots an octant, in the `4 * W` bytes that
    /// pad `28 * W` bytes of boxes and references to `32 * W`, whole cache lines for `W >= 2`.
    near_to_far: [u32; W],
}

/// `W` triangles, corner-major SoA: `vertices[corner][axis][lane]`. A leaf whose triangle count is
/// not a multiple of `W` repeats its last triangle: a duplicate gives the same `t` and id, so it
/// never changes an answer, and the hot loop needs no lane mask. `40 * W` bytes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TriangleBlock<const W: usize> {
    pub vertices: [[[f32; W]; 3]; 3],
    pub ids: [u32; W],
}

impl<const W: usize> WideNode<W> {
    /// Evaluated (at compile time) for each width the program instantiates, by `WideBvh::from_tree`.
    pub(super) const BYTE_BUDGET: () = assert!(size_of::<Self>() == 32 * W, "a wide node is 32 bytes per child");

    /// No children: every box NaN, every slot empty.
    pub(super) fn empty() -> Self {
        WideNode { bounds: [[f32::NAN; W]; 6], children: [EMPTY_CHILD; W], near_to_far: Self::slot_order() }
    }

    /// Every octant's order the slots' own, as [`WideNode::order_children`] orders empty slots:
    /// an empty node's orders, without sorting them (the collapse makes each node empty first).
    fn slot_order() -> [u32; W] {
        let octant: u32 = (0..W).fold(0, |order, k| order | (k as u32) << (4 * k));
        let word = (0..8 / W).fold(0, |word, i| word | octant << (i * 4 * W));
        [word; W]
    }

    /// Octant `octant`'s order of the slots (bit `a` of the octant set where the direction's
    /// component on axis `a` is negative, as [`super::traverse::near_row`] reads it): nibble `k`
    /// holds the slot a ray of that octant tends to reach `k`-th.
    #[inline(always)]
    pub(super) fn near_to_far(&self, octant: usize) -> u32 {
        let octants_per_word = 8 / W;
        let bits = 4 * W as u32;
        // The shift is below 32: `(octants_per_word - 1) * bits = 32 - bits`.
        let order = self.near_to_far[octant / octants_per_word] >> ((octant % octants_per_word) as u32 * bits);
        if bits == 32 { order } else { order & ((1 << bits) - 1) }
    }

    /// Works out [`WideNode::near_to_far`] for every octant from the children's boxes, once they
    /// are all set: the children sorted by their centres' projection on the octant's diagonal
    /// (Ylitie et al. 2017, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
    /// BVHs", sec. 3.2), so that a ray visits near children first without sorting their entry
    /// distances. Empty slots come last; ties keep slot order.
    pub(super) fn order_children(&mut self) {
        const { assert!(W <= 8 && W.is_power_of_two(), "an octant's order fits its share of a word") };
        let octants_per_word = 8 / W;
        self.near_to_far = [0; W];
        for octant in 0..8 {
            let keys: [f32; W] = std::array::from_fn(|slot| {
                if self.children[slot] == EMPTY_CHILD {
                    return f32::INFINITY;
                }
                (0..3)
                    .map(|axis| {
                        let centre = self.bounds[axis][slot] + self.bounds[axis + 3][slot];
                        if octant & (1 << axis) == 0 { centre } else { -centre }
                    })
                    .sum()
            });
            let mut slots: [usize; W] = std::array::from_fn(|slot| slot);
            slots.sort_by(|&a, &b| keys[a].total_cmp(&keys[b]));
            let order = slots.iter().enumerate().fold(0u32, |order, (k, &slot)| order | (slot as u32) << (4 * k));
            self.near_to_far[octant / octants_per_word] |= order << ((octant % octants_per_word) * 4 * W);
        }
    }
}

impl<const W: usize> TriangleBlock<W> {
    /// Whether triangle `lane` is padding: the repeat of its predecessor that fills a leaf's last
    /// block (a duplicate never changes an answer, but need not be tested twice).
    #[inline(always)]
    pub(in crate::accel) fn is_padding(&self, lane: usize) -> bool {
        lane > 0 && self.ids[lane] == self.ids[lane - 1]
    }

    /// Evaluated (at compile time) for each width the program instantiates, by `WideBvh::from_tree`.
    pub(super) const BYTE_BUDGET: () =
        assert!(size_of::<Self>() == 40 * W, "a triangle block is 40 bytes per triangle");
}

// Width 4 (SSE2 and the portable kernel), spelled out: 128-byte nodes (two cache lines), 160-byte
// blocks.
const _: () = assert!(size_of::<WideNode<4>>() == 128);
const _: () = assert!(size_of::<TriangleBlock<4>>() == 160);

#[cfg(test)]
mod tests {
    use super::*;

    /// The order of each octant of `node`, as slots.
    fn orders<const W: usize>(node: &WideNode<W>) -> Vec<Vec<usize>> {
        (0..8).map(|octant| (0..W).map(|k| (node.near_to_far(octant) >> (4 * k)) as usize & 0xF).collect()).collect()
    }

    /// Children whose boxes lie along x in the slot order `positions`, some slots empty: rays going
    /// +x meet them from least to greatest x, rays going -x the other way; empty slots come last;
    /// every octant's order holds every slot once (at both widths stored: 4 and 8 slots, 16 and 32 bits an octant).
    fn check_orders<const W: usize>(positions: [Option<f32>; W]) {
        let mut node = WideNode::<W>::empty();
        for (slot, x) in positions.iter().enumerate() {
            let Some(x) = *x else { continue };
            for axis in 0..3 {
                let centre = if axis == 0 { x } else { 0.0 };
                (node.bounds[axis][slot], node.bounds[axis + 3][slot]) = (centre - 0.5, centre + 0.5);
            }
            node.children[slot] = slot as u32;
        }
        node.order_children();
        let mut by_x: Vec<usize> = (0..W).filter(|&slot| positions[slot].is_some()).collect();
        by_x.sort_by(|&a, &b| positions[a].unwrap().total_cmp(&positions[b].unwrap()));
        let empty: Vec<usize> = (0..W).filter(|&slot| positions[slot].is_none()).collect();
        for (octant, order) in orders(&node).iter().enumerate() {
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..W).collect::<Vec<_>>(), "octant {octant}: {order:?}");
            let mut expected = by_x.clone();
            if octant & 1 != 0 {
                expected.reverse();
            }
            expected.extend(&empty);
            assert_eq!(order, &expected, "octant {octant}");
        }
    }

    #[test]
    fn children_are_ordered_near_to_far_for_each_octant() {
        check_orders::<8>([Some(3.0), None, Some(-2.0), Some(7.0), Some(0.0), None, Some(5.0), Some(-9.0)]);
        check_orders::<4>([Some(1.0), Some(-1.0), None, Some(4.0)]);
        // An empty node keeps slot order.
        assert!(orders(&WideNode::<8>::empty()).iter().all(|order| *order == (0..8).collect::<Vec<_>>()));
        assert!(orders(&WideNode::<4>::empty()).iter().all(|order| *order == (0..4).collect::<Vec<_>>()));
    }
}
