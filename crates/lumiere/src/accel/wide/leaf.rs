//! The leaf reference of a `W`-wide node: `LEAF_BIT | first_block << COUNT_BITS | (block_count - 1)`,
//! with as few count bits as the largest leaf needs at that width, so that the first block index
//! keeps the rest.

use crate::accel::bvh2::MAX_LEAF_SIZE;

/// Child reference with this bit set: a leaf; without it, a node index.
pub(in crate::accel) const LEAF_BIT: u32 = 1 << 31;

/// Blocks of the largest leaf the build makes, `W` triangles to a block.
const fn max_blocks(width: usize) -> usize {
    MAX_LEAF_SIZE.div_ceil(width)
}

/// Bits holding `block_count - 1`: 2 at width 4 (up to 4 blocks of 4), 1 at width 8.
const fn count_bits(width: usize) -> u32 {
    usize::BITS - (max_blocks(width) - 1).leading_zeros()
}

/// The reference of a leaf of `block_count` blocks starting at block `first_block`.
pub(super) fn encode<const W: usize>(first_block: usize, block_count: usize) -> u32 {
    let bits = const { count_bits(W) };
    debug_assert!((1..=max_blocks(W)).contains(&block_count) && first_block < 1 << (31 - bits));
    LEAF_BIT | (first_block as u32) << bits | (block_count as u32 - 1)
}

/// The block range of a leaf reference.
#[inline(always)]
pub(in crate::accel) fn blocks<const W: usize>(reference: u32) -> std::ops::Range<usize> {
    let bits = const { count_bits(W) };
    let first = ((reference & !LEAF_BIT) >> bits) as usize;
    first..first + (reference & ((1 << bits) - 1)) as usize + 1
}
