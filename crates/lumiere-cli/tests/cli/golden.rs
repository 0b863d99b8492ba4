//! Every mode's image bytes at a small size: a refactor that changes one bit of one pixel of one mode
//! fails here. A deliberate change of an estimator updates the hash in the same commit and says why.
//!
//! History: recorded before the reshape of issue 8, which left `hits` and `materials` (and every
//! PNG of `shadows`) unchanged. Two deliberate changes moved the others: integrators now evaluate
//! the BSDF per light sample (`shadows` differs by at most 3 ulps: the factor `kd/π` is applied in
//! another order), and sample dimensions are now drawn from a cursor (`SampleStream`) instead of
//! fixed numbers, so `direct` and `ao` draw other, equally distributed numbers: at 128x96 and 64
//! spp their image means agree with the old renderer's within 0.1% (noise-level pixel differences).
//! Then every PNG gained its sRGB chunk (decoded pixels unchanged), and `path` joined. `path` then
//! changed on purpose: one 2D point chooses the light and places the point on it (one dimension
//! fewer per bounce) and an emitter hit's light pdf comes from the hit distance; over 16 seeds at
//! 128x96, 16 spp, depth 5 its image mean moved by -0.03% (-0.5 standard errors). Then `path`
//! changed sampler: `--mode path` defaults to Sobol (half the variance, the library's
//! `path::sobol_halves_the_path_tracers_variance_on_the_cornell_box`); at the same settings the
//! mean moved by -0.02% (-0.5 standard errors). The lab's modes keep the independent sampler.

use std::process::Command;

/// FNV-1a, 64 bits: a fixed, dependency-free digest of a file's bytes.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xCBF2_9CE4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01B3))
}

/// Renders the built-in scene at 64x48 with `args` to `.pfm` and `.png`; returns both files' hashes.
fn hashes(name: &str, args: &[&str]) -> (u64, u64) {
    let dir = std::env::temp_dir().join(format!("lumiere-golden-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let digest = |extension: &str| {
        let out = dir.join(format!("{name}.{extension}"));
        let status = Command::new(env!("CARGO_BIN_EXE_lumiere"))
            .args(["render", "--size", "64x48"])
            .args(args)
            .arg("-o")
            .arg(&out)
            .stderr(std::process::Stdio::null())
            .status()
            .expect("the binary runs");
        assert!(status.success(), "{name}: lumiere render {args:?} failed");
        fnv1a(&std::fs::read(&out).unwrap())
    };
    let result = (digest("pfm"), digest("png"));
    let _ = std::fs::remove_dir_all(&dir);
    result
}

#[test]
fn every_mode_renders_the_bytes_recorded_before_the_reshape() {
    let cases: [(&str, &[&str], u64, u64); 8] = [
        ("hits", &["--mode", "hits"], 0xe5be6fadb7d0387a, 0x7d3cdc4ae8c8cc5c),
        ("materials", &["--mode", "materials"], 0xdadcc58aa85add45, 0x03b4ff564eb04fcc),
        ("shadows", &["--mode", "shadows"], 0x76e28bae8e2de7eb, 0x723af1f9843debe7),
        ("direct", &["--mode", "direct", "--samples", "4"], 0x7cffffec638ac856, 0xeede221ff0030757),
        (
            "direct-power-sobol",
            &["--mode", "direct", "--samples", "4", "--light-sampling", "power", "--sampler", "sobol", "--spp", "2"],
            0xe26b10e03b77f0c3,
            0x2613623c2da3895c,
        ),
        ("ao", &["--mode", "ao", "--samples", "4", "--spp", "2"], 0xb49248264e68bada, 0x2412a30836c4fa51),
        (
            "ao-near",
            &["--mode", "ao", "--samples", "3", "--ao-distance", "0.5", "--seed", "7"],
            0xdd1e91c7a6954311,
            0x3eb8316883e5fef2,
        ),
        ("path", &["--mode", "path", "--spp", "2", "--max-depth", "5"], 0x80c5df54f8762710, 0x4e36eaaea82bfa93),
    ];
    let mut failures = Vec::new();
    for (name, args, pfm, png) in cases {
        let got = hashes(name, args);
        if got != (pfm, png) {
            failures.push(format!("{name}: pfm {:#018x} png {:#018x}, expected {pfm:#018x} {png:#018x}", got.0, got.1));
        }
    }
    assert!(failures.is_empty(), "image bytes changed:\n{}", failures.join("\n"));
}
