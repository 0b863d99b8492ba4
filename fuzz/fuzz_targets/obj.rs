//! Fuzz target `obj`: `parse_obj` on OBJ text, optionally NUL + MTL text. The body is `harness::obj_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::obj_target(data) {
        panic!("{problem}");
    }
});
