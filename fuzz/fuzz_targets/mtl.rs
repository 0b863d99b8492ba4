//! Fuzz target `mtl`: the MTL parser, through a small OBJ that uses its materials. The body is `harness::mtl_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::mtl_target(data) {
        panic!("{problem}");
    }
});
