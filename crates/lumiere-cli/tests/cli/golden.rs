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
//! Then the batched `ao` and `direct` cases joined (issue 11, before their ray-major kernels).
//! Then the independent sampler changed on purpose, for speed: a number's 64 bits now come from
//! one finaliser of its (pixel, dimension) key and its index, not two finalisers of (pixel,
//! index) and then the dimension, so `direct` and `ao` (the lab's modes draw from it; `path`
//! defaults to Sobol) draw other, equally distributed numbers. Over 64 seeds at 128x96, 16 spp,
//! the image means of `direct --samples 4` and `ao --samples 3 --ao-distance 0.5` moved by
//! -0.008% (-0.6 standard errors) and +0.012% (+1.2); over 16 seeds at 128x96, `ao --samples 4`
//! (16 spp), `direct --samples 16` (4 spp) and `ao --samples 40` (2 spp) by -0.7, -0.9 and -1.6.
//! Then `ao` with a multiple of four probes changed on purpose: its probes are stratified in
//! azimuth, a quarter of them in each quarter turn about the normal (so that each quarter can be
//! traced as a batch of its own). At 128x96 the image means of `ao --samples 4 --spp 4` and
//! `--samples 256` over 16 seeds, and of `--samples 40` over 64 seeds, moved by +0.7, +0.5 and
//! -0.5 standard errors, and the per-pixel variance across seeds fell by 30% (ratios 0.69-0.70).
//! Then `direct` (a light at a time) changed its additions, not its estimator: a diffuse
//! receiver's visible weights are summed lane by lane, then times `f Le`, instead of each
//! contribution added in sample order. At 256x192 the PFMs of `--samples 16`, `64` and `3 --spp
//! 4` differ from the old ones by at most 7.8e-7 relative (rounding), the PNGs not at all.
//! Then `direct-wide` joined, its hashes those of the binary before the batches' groups of 32
//! rays, so that it checks that a group of 32 adds its samples' weights as two groups of 16 did.

use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

use lumiere::accel::Isa;

/// FNV-1a, 64 bits: a fixed, dependency-free digest of a file's bytes.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xCBF2_9CE4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01B3))
}

/// Renders the built-in scene at 64x48 with `args` to `.pfm` and `.png`; returns both files' hashes.
fn hashes(name: &str, args: &[&str]) -> (u64, u64) {
    hashes_of(name, &["--size", "64x48"], args)
}

/// Renders with `scene_args` (a size, perhaps a scene file) and `args` to `.pfm` and `.png`;
/// returns both files' hashes.
fn hashes_of(name: &str, scene_args: &[&str], args: &[&str]) -> (u64, u64) {
    // Tests run in parallel threads of one process and render the same cases: a counter keeps
    // their folders apart (one test removing its folder must not pull another's files away).
    static RENDERS: AtomicUsize = AtomicUsize::new(0);
    let render = RENDERS.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("lumiere-golden-{name}-{}-{render}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let digest = |extension: &str| {
        let out = dir.join(format!("{name}.{extension}"));
        let status = Command::new(env!("CARGO_BIN_EXE_lumiere"))
            .arg("render")
            .args(scene_args)
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

/// Each mode's arguments and the hashes of its `.pfm` and `.png`.
type Case = (&'static str, &'static [&'static str], u64, u64);

#[rustfmt::skip]
const CASES: [Case; 13] = [
        ("hits", &["--mode", "hits"], 0xe5be6fadb7d0387a, 0x7d3cdc4ae8c8cc5c),
        ("materials", &["--mode", "materials"], 0xdadcc58aa85add45, 0x03b4ff564eb04fcc),
        ("shadows", &["--mode", "shadows"], 0x76e28bae8e2de7eb, 0x723af1f9843debe7),
        ("direct", &["--mode", "direct", "--samples", "4"], 0x9eec6ae54a75c304, 0xf38fe564439f6e5b),
        (
            "direct-power-sobol",
            &["--mode", "direct", "--samples", "4", "--light-sampling", "power", "--sampler", "sobol", "--spp", "2"],
            0xe26b10e03b77f0c3,
            0x2613623c2da3895c,
        ),
        ("ao", &["--mode", "ao", "--samples", "4", "--spp", "2"], 0x81a47897a1170fc0, 0xc108006be9b5e89c),
        (
            "ao-near",
            &["--mode", "ao", "--samples", "3", "--ao-distance", "0.5", "--seed", "7"],
            0x5a9e7b257c595a0c,
            0x935f2df37aea1b1f,
        ),
        ("path", &["--mode", "path", "--spp", "2", "--max-depth", "5"], 0x80c5df54f8762710, 0x4e36eaaea82bfa93),
        // Enough rays per origin for shared-origin batches (recorded before the ray-major batch
        // kernels, when fewer than 8 rays per shaft or 16 per hemisphere were traversed alone; now
        // 2 and 4, so `direct` and `ao` above are batched too, with the same bytes).
        ("ao-batch", &["--mode", "ao", "--samples", "40"], 0xd2a414dc4d239e2c, 0x7382b930850240ea),
        ("ao-batch-near", &["--mode", "ao", "--samples", "33", "--spp", "2", "--ao-distance", "0.3"], 0x140520f276826a14, 0xc7c8652cc1a07a34),
        ("direct-batch", &["--mode", "direct", "--samples", "16"], 0x659adb5d42622794, 0x6d973776a2f02a12),
        // A group of 32 shadow rays per light, then one of 16 (8 of them live).
        ("direct-wide", &["--mode", "direct", "--samples", "40"], 0x12cdc2aea2482d48, 0x1ab2b3bd5ae010db),
        // Enough probes per point for a batch per quarter of the hemisphere.
        ("ao-quarters", &["--mode", "ao", "--samples", "256"], 0x2ef61a1287131e64, 0xf4de07707fc3cc07),
];

/// The renders of `CASES` whose bytes differ from the recorded ones, each with `extra` arguments.
fn failures_with(extra: &[&str]) -> Vec<String> {
    let mut failures = Vec::new();
    for (name, args, pfm, png) in CASES {
        let args: Vec<&str> = args.iter().chain(extra).copied().collect();
        let got = hashes(name, &args);
        if got != (pfm, png) {
            failures.push(format!(
                "{name} {extra:?}: pfm {:#018x} png {:#018x}, expected {pfm:#018x} {png:#018x}",
                got.0, got.1
            ));
        }
    }
    failures
}

#[test]
fn every_mode_renders_the_bytes_recorded_before_the_reshape() {
    let failures = failures_with(&[]);
    assert!(failures.is_empty(), "image bytes changed:\n{}", failures.join("\n"));
}

/// The same bytes with the BVH and kernels of every ISA this CPU runs (4-wide portable and SSE,
/// 8-wide AVX2 and AVX-512): the kernels round exactly like the scalar test, so the ISA changes
/// speed, never an image.
#[test]
fn every_isa_renders_the_recorded_bytes() {
    let isas = Isa::supported();
    println!("ISAs on this CPU: {isas:?}");
    let failures: Vec<String> = isas.iter().flat_map(|isa| failures_with(&["--isa", isa.name()])).collect();
    assert!(failures.is_empty(), "image bytes differ between ISAs:\n{}", failures.join("\n"));
}

/// Real meshes, whose 8-wide trees have many levels (the built-in box fits in one node): every
/// mode that traces rays gives the same bytes on every ISA.
#[test]
fn every_isa_renders_the_same_bytes_of_real_scenes() {
    let (Some(bunny), Some(staircase)) = (
        crate::common::shared_scene("bunny/stanford-bunny.obj"),
        crate::common::shared_scene("staircase/staircase.obj.gz"),
    ) else {
        return;
    };
    let (bunny, staircase) = (bunny.to_str().unwrap(), staircase.to_str().unwrap());
    let staircase_camera = [
        "--eye",
        "0.0324209,1.52673,4.88197",
        "--target",
        "0.0247749,1.571785,3.883015",
        "--fov",
        "58.54",
        "--emission",
        "Emission=5,5,5",
    ];
    let renders: [(&str, Vec<&str>); 4] = [
        ("bunny-hits", vec![bunny, "--size", "96x72", "--mode", "hits"]),
        ("bunny-ao", vec![bunny, "--size", "96x72", "--mode", "ao", "--samples", "4"]),
        (
            "staircase-direct",
            [
                &[staircase, "--size", "36x64", "--mode", "direct", "--light-sampling", "power", "--samples", "2"][..],
                &staircase_camera,
            ]
            .concat(),
        ),
        (
            "staircase-path",
            [&[staircase, "--size", "36x64", "--mode", "path", "--spp", "2"][..], &staircase_camera].concat(),
        ),
    ];
    for (name, args) in renders {
        let per_isa: Vec<(Isa, (u64, u64))> =
            Isa::supported().into_iter().map(|isa| (isa, hashes_of(name, &args, &["--isa", isa.name()]))).collect();
        assert!(per_isa.windows(2).all(|w| w[0].1 == w[1].1), "{name}: bytes differ between ISAs: {per_isa:x?}");
    }
}
