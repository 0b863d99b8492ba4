//! Helpers for the fuzz targets in `fuzz_targets/`; see `docs/FUZZING.md`.

pub mod harness;
pub mod process;
