//! Refusing a scene that would not fit in memory before its triangles are allocated: an OBJ file
//! once its statements are counted (`obj.rs`), and a scene made from arrays (the Python module's
//! `Scene.from_arrays`) before they are copied. Both ask the same estimate.

use std::io;
use std::path::Path;

use crate::error::{Error, Result, shown_bytes};
use crate::util::read;

/// Bytes per triangle that `World::new` adds to the mesh: the BVH (about 80 bytes per triangle)
/// and the temporaries of its build, at their peak. Measured on the 1.1M-triangle bunny with
/// `/usr/bin/time -v lumiere render stanford-bunny-1m.obj.gz --size 8x6 --mode hits` (2 threads):
/// 194 MB maximum resident, less 5 MB for the process and 24.5 MB for the mesh, is 148 bytes per
/// triangle; rounded up. (Loading alone peaks at 92 MB: the 45 MB of text and twice the mesh.)
const BVH_BYTES_PER_TRIANGLE: u64 = 160;

/// The memory a load may use: the system's (see [`read::available_memory`]) or, for tests, given.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Memory {
    System,
    Given(u64),
}

impl Memory {
    /// The bytes available when a load needs `needed`; `None` when it need not be checked.
    pub(crate) fn available(self, needed: u64) -> Option<u64> {
        match self {
            Memory::System => read::available_for(u128::from(needed)),
            Memory::Given(bytes) => Some(bytes),
        }
    }
}

/// How large a mesh will be, counted before it is allocated.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshSize {
    pub positions: usize,
    pub texcoords: usize,
    pub normals: usize,
    pub triangles: u64,
}

impl MeshSize {
    /// The memory the mesh needs while it is made and then rendered: making it holds the pieces
    /// and their concatenation (an OBJ's chunks, or an array's bytes and its values) at once;
    /// rendering holds the mesh and the BVH.
    fn estimated_bytes(self) -> u64 {
        let count = |n: usize| n as u64;
        let vertex_bytes = 12 * count(self.positions) + 8 * count(self.texcoords) + 12 * count(self.normals);
        // Position indices and material id, and attribute indices when the mesh has such attributes.
        let per_triangle = 12 + 4 + 12 * u64::from(self.texcoords > 0) + 12 * u64::from(self.normals > 0);
        let mesh = vertex_bytes.saturating_add(per_triangle.saturating_mul(self.triangles));
        mesh.saturating_mul(2).max(mesh.saturating_add(BVH_BYTES_PER_TRIANGLE.saturating_mul(self.triangles)))
    }
}

/// Refuses, before anything is allocated, a mesh of `size` whose making and BVH would not fit in
/// `memory` beside the `held` bytes its maker keeps meanwhile; `parts` names what the estimate
/// covers in the message.
pub(crate) fn check_mesh_memory(name: &Path, size: MeshSize, held: u64, memory: Memory, parts: &str) -> Result<()> {
    let needed = size.estimated_bytes().saturating_add(held);
    let Some(available) = memory.available(needed) else { return Ok(()) };
    if needed <= available {
        return Ok(());
    }
    let message = format!(
        "needs about {} of memory for its {} triangles and {} vertices ({parts}), but only {} is available; refusing \
         it",
        shown_bytes(needed),
        size.triangles,
        size.positions,
        shown_bytes(available)
    );
    Err(Error::io(name, io::Error::new(io::ErrorKind::OutOfMemory, message)))
}

/// Refuses a scene named `name` made from arrays, of `size`, whose `held` bytes (the arrays'
/// copies) are about to be taken, when it would not fit in the memory the system has left.
pub fn check_arrays_memory(name: &str, size: MeshSize, held: u64) -> Result<()> {
    check_mesh_memory(Path::new(name), size, held, Memory::System, "mesh, BVH and the copies of its arrays")
}

/// [`check_arrays_memory`] as if `available` bytes were left, for tests.
#[doc(hidden)]
pub fn check_arrays_memory_within(name: &str, size: MeshSize, held: u64, available: u64) -> Result<()> {
    check_mesh_memory(Path::new(name), size, held, Memory::Given(available), "mesh, BVH and the copies of its arrays")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_refused_when_their_mesh_bvh_and_copies_do_not_fit() {
        let size = MeshSize { positions: 3000, texcoords: 0, normals: 0, triangles: 14_000_000 };
        // The mesh (16 bytes a triangle and 12 a vertex) and the BVH's 160 bytes a triangle: 2.46 GB.
        let estimate = size.estimated_bytes();
        assert_eq!(estimate, 3000 * 12 + 14_000_000 * (16 + 160));
        let error = check_arrays_memory_within("big", size, 0, 1 << 30).unwrap_err().to_string();
        assert!(error.starts_with("big: needs about 2.3 GiB of memory for its 14000000 triangles"), "{error}");
        assert!(error.contains("(mesh, BVH and the copies of its arrays), but only 1.0 GiB is available"), "{error}");
        // The copies count: what fits alone is refused once they are held beside it.
        assert!(check_arrays_memory_within("big", size, 0, estimate).is_ok());
        assert!(check_arrays_memory_within("big", size, 1, estimate).is_err());
    }
}
