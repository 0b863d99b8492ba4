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
    /// Pads `28 * W` bytes of boxes and references to `32 * W`, whole cache lines for `W >= 2`.
    _pad: [u32; W],
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
    /// Evaluated (at compile time) for each width the program instantiates, by `WideBvh::from_binary`.
    pub(super) const BYTE_BUDGET: () = assert!(size_of::<Self>() == 32 * W, "a wide node is 32 bytes per child");

    /// No children: every box NaN, every slot empty.
    pub(super) fn empty() -> Self {
        WideNode { bounds: [[f32::NAN; W]; 6], children: [EMPTY_CHILD; W], _pad: [0; W] }
    }
}

impl<const W: usize> TriangleBlock<W> {
    /// Evaluated (at compile time) for each width the program instantiates, by `WideBvh::from_binary`.
    pub(super) const BYTE_BUDGET: () =
        assert!(size_of::<Self>() == 40 * W, "a triangle block is 40 bytes per triangle");
}

// The width rendered today, spelled out: 128-byte nodes (two cache lines), 160-byte blocks.
const _: () = assert!(size_of::<WideNode<4>>() == 128);
const _: () = assert!(size_of::<TriangleBlock<4>>() == 160);
