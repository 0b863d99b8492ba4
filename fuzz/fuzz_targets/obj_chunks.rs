//! Fuzz target `obj_chunks`: chunked vs single-chunk OBJ parsing (first byte: chunk size). The body is `harness::obj_chunks_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::obj_chunks_target(data) {
        panic!("{problem}");
    }
});
