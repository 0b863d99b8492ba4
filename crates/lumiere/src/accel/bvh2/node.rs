use crate::math::Aabb;
use glam::Vec3;

/// A flat BVH node in 32 bytes, so two siblings share one 64-byte cache line.
///
/// Interior node (`count == 0`): children are nodes `first` and `first + 1`.
/// Leaf (`count > 0`): triangles `first .. first + count` in leaf order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Node {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

const _: () = assert!(size_of::<Node>() == 32);

impl Node {
    pub fn new(bounds: Aabb, first: u32, count: u32) -> Self {
        Node { min: bounds.min.to_array(), first, max: bounds.max.to_array(), count }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    #[inline]
    pub fn bounds(&self) -> Aabb {
        Aabb { min: Vec3::from_array(self.min), max: Vec3::from_array(self.max) }
    }
}
