//! Small geometric types shared by every module; vectors and matrices come from glam.

mod aabb;
mod frame;
mod offset;
mod ray;
pub mod rows;
mod uv_transform;

pub use aabb::Aabb;
pub use frame::Frame;
pub use glam::{DMat4, DVec3, DVec4, Mat4, Vec2, Vec3, Vec3A};
pub use offset::offset_ray_origin;
pub use ray::Ray;
pub use uv_transform::UvTransform;
