//! Fuzz target `orbiter`: Orbiter::parse and the camera built from it. The body is `harness::orbiter_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::orbiter_target(data) {
        panic!("{problem}");
    }
});
