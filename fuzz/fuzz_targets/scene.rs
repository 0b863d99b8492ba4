//! Fuzz target `scene`: parse, build the BVH and render 8x6 in every mode. The body is `harness::scene_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::scene_target(data) {
        panic!("{problem}");
    }
});
