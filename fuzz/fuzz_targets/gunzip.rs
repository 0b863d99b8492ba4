//! Fuzz target `gunzip`: the inflation of `.obj.gz` files under a size limit (first byte). The body
//! is `harness::gunzip_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::gunzip_target(data) {
        panic!("{problem}");
    }
});
