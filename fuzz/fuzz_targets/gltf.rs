//! Fuzz target `gltf`: `parse_gltf` on a `.gltf` or `.glb` file's bytes, every external file
//! refused. The body is `harness::gltf_target`, shared with the stable tests.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(problem) = lumiere_fuzz::harness::gltf_target(data) {
        panic!("{problem}");
    }
});
