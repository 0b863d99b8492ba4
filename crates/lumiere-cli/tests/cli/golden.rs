//! Every mode's image bytes at a small size, recorded before the code was reshaped (issue 8): a
//! refactor that changes one bit of one pixel of one mode fails here. A deliberate change of an
//! estimator updates the hash in the same commit and says why.

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
    let cases: [(&str, &[&str], u64, u64); 7] = [
        ("hits", &["--mode", "hits"], 0xe5be6fadb7d0387a, 0xe7dfa7e3ad2a1f36),
        ("materials", &["--mode", "materials"], 0xdadcc58aa85add45, 0x11a8b1a16ec58312),
        ("shadows", &["--mode", "shadows"], 0x168145363847eff2, 0x83f88c2bfe407eb8),
        ("direct", &["--mode", "direct", "--samples", "4"], 0x737eef36608307ea, 0x9e37ed627fca624a),
        (
            "direct-power-sobol",
            &["--mode", "direct", "--samples", "4", "--light-sampling", "power", "--sampler", "sobol", "--spp", "2"],
            0x8e6a1891e1a47a07,
            0xac55e9106b5745a1,
        ),
        ("ao", &["--mode", "ao", "--samples", "4", "--spp", "2"], 0x2ccb478d009524fa, 0xc8338e2367a19ba6),
        (
            "ao-near",
            &["--mode", "ao", "--samples", "3", "--ao-distance", "0.5", "--seed", "7"],
            0x05df0f9f48878324,
            0xe40fd7a08f1226e0,
        ),
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
