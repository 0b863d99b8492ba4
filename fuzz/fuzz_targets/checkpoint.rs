//! Fuzz target `checkpoint`: `Checkpoint::decode`, the checksum optionally fixed up (first byte).
//! The body is `harness::checkpoint_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::checkpoint_target(data) {
        panic!("{problem}");
    }
});
