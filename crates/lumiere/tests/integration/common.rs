//! Helpers shared by the integration tests: a seeded RNG, mesh generators, and the mean of
//! independent estimates with its standard error.
#![allow(dead_code)]

use glam::{Vec2, Vec3};
use std::f32::consts::TAU;

/// SplitMix64: tiny, seeded, good enough to generate test inputs reproducibly.
pub struct TestRng(pub u64);

impl TestRng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// A uniformly distributed unit vector.
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(-1.0, 1.0);
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }
}

/// Mean and standard error of the mean of `estimate(seed)` over the seeds `0..seeds`, each an
/// independent estimate (an image's value or mean at that seed).
pub fn mean_and_error<T: Into<f64>>(seeds: u64, mut estimate: impl FnMut(u64) -> T) -> (f64, f64) {
    let values: Vec<f64> = (0..seeds).map(|seed| estimate(seed).into()).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

/// A closed cube `[-1, 1]^3` whose faces are `n x n` grids of quads (two triangles each), sharing
/// vertices along every edge: the test bed for watertightness.
pub fn grid_cube(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut index_of = std::collections::HashMap::new();
    let mut vertex = |p: Vec3, positions: &mut Vec<Vec3>| -> u32 {
        let key = (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
        *index_of.entry(key).or_insert_with(|| {
            positions.push(p);
            positions.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            let point = |i: usize, j: usize| {
                let mut p = Vec3::ZERO;
                p[axis] = side;
                p[u_axis] = -1.0 + 2.0 * i as f32 / n as f32;
                p[v_axis] = -1.0 + 2.0 * j as f32 / n as f32;
                p
            };
            for i in 0..n {
                for j in 0..n {
                    let a = vertex(point(i, j), &mut positions);
                    let b = vertex(point(i + 1, j), &mut positions);
                    let c = vertex(point(i + 1, j + 1), &mut positions);
                    let d = vertex(point(i, j + 1), &mut positions);
                    indices.push([a, b, c]);
                    indices.push([a, c, d]);
                }
            }
        }
    }
    (positions, indices)
}

/// A fresh folder under the system temp dir, removed when dropped (no tempfile crate).
pub struct TempDir(pub std::path::PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("lumiere-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create test dir");
        TempDir(dir)
    }

    pub fn path(&self, name: &str) -> std::path::PathBuf {
        self.0.join(name)
    }

    /// The path as a string, for command-line arguments.
    pub fn arg(&self, name: &str) -> String {
        self.path(name).to_string_lossy().into_owned()
    }

    pub fn write(&self, name: &str, content: impl AsRef<[u8]>) -> std::path::PathBuf {
        let path = self.path(name);
        std::fs::write(&path, content).expect("write test file");
        path
    }

    /// Names of everything in the folder, sorted (to catch stray temporary files).
    pub fn entries(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&self.0)
            .expect("read test dir")
            .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A test scene from `../shared/scenes` beside the repository, or `None` when this clone has no
/// `../shared` (a plain `git clone`): the test then says it is skipped and why, and passes. CI sets
/// `LUMIERE_REQUIRE_SHARED=1`, which turns a missing scene into a failure, so that CI never skips.
pub fn shared_scene(relative: &str) -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let path = root.join(relative);
    if path.exists() {
        return Some(path);
    }
    if std::env::var_os("LUMIERE_REQUIRE_SHARED").is_some_and(|v| v == "1") {
        panic!("{} is missing and LUMIERE_REQUIRE_SHARED=1", path.display());
    }
    eprintln!("skipped: needs ../shared/scenes/{relative}, which this clone does not have");
    None
}

/// Unwraps a chi-square result, printing the p-value (`--nocapture` shows them) or the report.
pub fn assert_passes(name: &str, result: Result<f64, String>) {
    match result {
        Ok(p) => println!("{name}: p = {p:.4}"),
        Err(report) => panic!("{name}: {report}"),
    }
}

/// The azimuth of `w` as a fraction of a turn, computed independently of the warps' inverses.
pub fn azimuth(w: Vec3) -> f32 {
    (w.y.atan2(w.x) / TAU).rem_euclid(1.0)
}

/// A direction on the sphere as a point of the square: `((1 − cos θ)/2, φ/2π)`, `dω = 4π dx dy`.
pub fn sphere_param(w: Vec3) -> Vec2 {
    Vec2::new(0.5 * (1.0 - w.z), azimuth(w))
}

/// A direction on the upper hemisphere as a point of the square: `(cos θ, φ/2π)`, `dω = 2π dx dy`.
/// Directions below the horizon land outside the square, which the harness rejects.
pub fn hemisphere_param(w: Vec3) -> Vec2 {
    Vec2::new(w.z, azimuth(w))
}
