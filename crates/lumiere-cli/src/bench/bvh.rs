//! BVH measurements: build time and quality, traversal throughput, work per ray, and a check of
//! every answer of the fast path against the scalar reference while measuring.

use std::hint::black_box;
use std::time::Instant;

use rayon::prelude::*;

use super::rays::{Query, RaySet};
use lumiere::accel::{Accel, BuildPreset, Bvh, Isa, TraversalStats};
use lumiere::scene::mesh::TriangleMesh;

/// Rays per rayon task: large enough to amortise scheduling, small enough to balance two cores.
const CHUNK: usize = 1024;

/// Median of `repeats` timings of `f`, in seconds.
pub fn median_seconds(repeats: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Builds the renderer's BVH for `isa` (binary SAH build for its leaf width, then the collapse to
/// its width) on the current rayon pool.
pub fn build(mesh: &TriangleMesh, preset: BuildPreset, isa: Isa) -> Accel {
    Accel::build(&mesh.positions, &mesh.indices, preset, isa)
}

/// Bytes of the mesh data the renderer keeps: positions, indices, material ids, normals, texcoords.
pub fn mesh_bytes(mesh: &TriangleMesh) -> usize {
    size_of_val(mesh.positions.as_slice())
        + size_of_val(mesh.indices.as_slice())
        + size_of_val(mesh.material_ids.as_slice())
        + size_of_val(mesh.normals.as_slice())
        + size_of_val(mesh.normal_indices.as_slice())
        + size_of_val(mesh.texcoords.as_slice())
        + size_of_val(mesh.texcoord_indices.as_slice())
}

/// Traces every ray of `set` once with the wide BVH on the current rayon pool.
pub fn trace(bvh: &Accel, set: &RaySet) {
    let found: u64 = match set.query {
        Query::Closest => set
            .rays
            .par_chunks(CHUNK)
            .map(|rays| rays.iter().filter_map(|r| bvh.intersect(r)).map(|h| h.triangle as u64).sum::<u64>())
            .sum(),
        Query::Occluded => {
            set.rays.par_chunks(CHUNK).map(|rays| rays.iter().filter(|r| bvh.occluded(r)).count() as u64).sum()
        }
    };
    black_box(found);
}

/// Average interior nodes and triangle blocks visited per ray.
pub fn work_per_ray(bvh: &Accel, set: &RaySet) -> (f64, f64) {
    let mut stats = TraversalStats::default();
    for ray in &set.rays {
        match set.query {
            Query::Closest => drop(bvh.intersect_counted(ray, &mut stats)),
            Query::Occluded => drop(bvh.occluded_counted(ray, &mut stats)),
        }
    }
    let n = set.rays.len().max(1) as f64;
    (stats.nodes as f64 / n, stats.blocks as f64 / n)
}

/// Rays whose wide-BVH answer differs from the scalar binary BVH's (must be 0).
pub fn mismatches(binary: &Bvh, wide: &Accel, set: &RaySet) -> usize {
    set.rays
        .par_iter()
        .filter(|r| match set.query {
            Query::Closest => binary.intersect(r) != wide.intersect(r),
            Query::Occluded => binary.occluded(r) != wide.occluded(r),
        })
        .count()
}

/// Peak resident memory of this process (Linux `VmHWM`) since the last [`reset_peak_rss`], in
/// MiB, if known.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Starts a new peak at the memory in use now (Linux 4.0 and later), so that each scene's peak is
/// its own, not the largest scene's before it (the process's where it cannot).
pub fn reset_peak_rss() {
    // Memory freed by the scenes before, which the allocator would keep and count in this scene's
    // peak, goes back to the system first.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only hands free pages of the heap back to the system.
    unsafe {
        libc::malloc_trim(0);
    }
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
