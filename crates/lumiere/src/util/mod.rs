//! Helpers with no knowledge of rendering: the one hash, and the file-system rules every reader
//! and writer follows (atomic writes, capped reads, the memory left, no output over an input, thread counts).

pub mod hash;
pub mod memory;
pub mod overwrite;
pub mod read;
pub mod threads;
pub mod write;
