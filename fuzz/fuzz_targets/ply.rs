//! Fuzz target `ply`: `parse_ply` on a PLY file's bytes, ASCII or binary. The body is `harness::ply_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::ply_target(data) {
        panic!("{problem}");
    }
});
