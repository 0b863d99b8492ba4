//! Helpers with no knowledge of rendering: the one hash, and the file-system rules every reader
//! and writer follows (atomic writes, capped reads, the memory left).

pub mod hash;
pub mod memory;
pub mod read;
pub mod write;
