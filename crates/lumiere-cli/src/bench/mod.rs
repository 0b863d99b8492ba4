//! Benchmarks shared by the CLI (`lumiere bench-bvh`) and the tests: the scenes with their cameras,
//! reproducible ray sets, and the BVH measurements.

pub mod bvh;
pub mod rays;
pub mod scenes;
