//! End-to-end tests through the `lumiere` binary, and the hostile corpus replayed through both the
//! library and the binary, linked as one test binary.

#[path = "../../../lumiere/tests/integration/common.rs"]
mod common;
#[path = "../../../../fuzz/src/harness.rs"]
mod harness;
#[path = "../../../../fuzz/src/process.rs"]
mod process;

mod cli;
mod denoise;
mod edges;
mod fuzz_corpus;
mod fuzz_parsers;
mod golden;
mod hostile_inputs;
mod progressive;
