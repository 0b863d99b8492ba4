//! The `lumiere` command line on top of the `lumiere` library: argument parsing, progress,
//! signals, statistics files, and the benchmark scenes and ray sets shared by `lumiere bench-bvh`
//! and `cargo bench`.

pub mod bench;
pub mod cli;
