//! Checkpoint files from elsewhere: every size field checked against the bytes that follow before
//! anything is read (a checkpoint is never trusted to be lumiere's), and the wording of a refused
//! resume's differing options.

use std::path::Path;

use glam::Vec3;
use lumiere::integrators::{AmbientOcclusion, Hits, Materials, Shadows, Technique};
use lumiere::render::checkpoint::{Checkpoint, differing_options};
use lumiere::render::film::{Film, PassSamples};
use lumiere::render::fingerprint::{Fingerprints, Mismatch, options_description};
use lumiere::render::{RenderOptions, RenderStats};
use lumiere::sampler::SamplerKind;
use lumiere::scene::builtin;
use lumiere::scene::camera::Camera;
use lumiere::util::hash::hash_bytes;

/// Header bytes: magic, version, two fingerprints, width, height, samples, seed, rays, discarded,
/// elapsed.
const HEADER: usize = 72;

fn checkpoint(width: u32, height: u32, options: &str) -> Checkpoint {
    let mut film = Film::new(width, height).unwrap();
    for k in 0..2 {
        let values = (0..width * height).map(|p| Vec3::new(0.25 * p as f32, 1.0 + k as f32, 0.5)).collect();
        film.add_pass(&PassSamples { sample: k, width, height, values, rays: 1 }).unwrap();
    }
    Checkpoint {
        scene_fingerprint: 1,
        options_fingerprint: 2,
        seed: 3,
        options: options.to_string(),
        film,
        stats: RenderStats::default(),
    }
}

/// `body` (a checkpoint without its checksum) with a valid checksum: what a forger (or a bug)
/// writes, past the checks for accidents.
fn sealed(mut body: Vec<u8>) -> Vec<u8> {
    let hash = hash_bytes(&body);
    body.extend_from_slice(&hash.to_le_bytes());
    body
}

fn decode_error(bytes: &[u8]) -> String {
    Checkpoint::decode(bytes, Path::new("render.ckpt")).map(|_| ()).unwrap_err().to_string()
}

#[test]
fn size_fields_that_do_not_match_the_bytes_are_refused() {
    let bytes = checkpoint(3, 2, "seed: 3\n").encode().unwrap();
    let body = &bytes[..bytes.len() - 8];
    let set_u32 = |offset: usize, value: u32| {
        let mut body = body.to_vec();
        body[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
        sealed(body)
    };
    let options_length = HEADER + 6 * 32;
    // A film of no pixels, with no pixel data: the rest of the file reads as its options.
    let no_pixels = |offset: usize| {
        let mut body = body.to_vec();
        body[offset..offset + 4].copy_from_slice(&0u32.to_le_bytes());
        body.drain(HEADER..options_length);
        sealed(body)
    };
    for (what, forged) in [
        ("a zero width", no_pixels(28)),
        ("a zero height", no_pixels(32)),
        ("a zero width and pixel data", set_u32(28, 0)),
        ("more pixels than stored", set_u32(32, 3)),
        ("an options length past the end", set_u32(options_length, 9)),
        ("an options length short of the end", set_u32(options_length, 7)),
        ("no options length", sealed(body[..options_length].to_vec())),
    ] {
        let error = decode_error(&forged);
        assert!(
            error.contains("render.ckpt: not a valid lumiere checkpoint (its size does not match"),
            "{what}: {error}"
        );
    }
    // A whole header and a checksum, nothing else: a header, of a film with no pixel data.
    let header_only = sealed(body[..HEADER].to_vec());
    let error = decode_error(&header_only);
    assert!(error.contains("(its size does not match its pixel data)"), "{error}");
}

/// A file one byte short of a header and its checksum is refused as having no header, even with a
/// valid checksum (a forged file, or one cut short and sealed by a bug): its fields are never read
/// past its end, nor blamed on its pixel data.
#[test]
fn a_file_shorter_than_a_header_has_no_header() {
    let bytes = checkpoint(3, 2, "seed: 3\n").encode().unwrap();
    let error = decode_error(&sealed(bytes[..HEADER - 1].to_vec()));
    assert!(error.contains("render.ckpt: not a valid lumiere checkpoint (no checkpoint header)"), "{error}");
}

/// The options text is bounded (64 KiB) for hostile files: the bound itself is accepted.
#[test]
fn options_text_up_to_its_bound_is_kept() {
    let longest = "k".repeat(1 << 16);
    let saved = checkpoint(2, 1, &longest);
    let loaded = Checkpoint::decode(&saved.encode().unwrap(), Path::new("render.ckpt")).unwrap();
    assert_eq!(loaded, saved);
    let error = decode_error(&checkpoint(2, 1, &format!("{longest}k")).encode().unwrap());
    assert!(error.contains("its size does not match"), "{error}");
}

#[test]
fn differing_options_name_each_key_once_with_both_values() {
    let saved = "technique: Path(Path { max_depth: 8, rr_depth: 5, strategy: Mis })\nseed: 1\nold: yes\n";
    let now = "technique: Hits(Hits)\nseed: 2\nsampler: Sobol\n";
    assert_eq!(
        differing_options(saved, now),
        [
            "technique (checkpoint: --mode path --max-depth 8 (rr-depth 5, strategy mis); now: --mode hits)",
            "seed (checkpoint: 1; now: 2)",
            "sampler (checkpoint: (none); now: sobol)",
            "old (checkpoint: yes; now: (none))",
        ]
    );
    assert_eq!(
        differing_options("technique: Direct(Direct {  })\n", "technique: Hits(Hits)\n"),
        ["technique (checkpoint: --mode direct; now: --mode hits)"],
        "a record without fields is its mode alone"
    );
    assert_eq!(
        differing_options(
            "technique: Direct(Direct { samples: 16, light_sampling: PerLight })\n",
            "technique: AmbientOcclusion(AmbientOcclusion { samples: 16, distance: inf })\n"
        ),
        ["technique (checkpoint: --mode direct --samples 16 --light-sampling per-light; now: --mode ao --samples 16)"],
        "settings are named by their flags, with the flags' values"
    );
    assert_eq!(
        differing_options(
            "technique: AmbientOcclusion(AmbientOcclusion { samples: 4, distance: 0.5 })\n",
            "technique: AmbientOcclusion(AmbientOcclusion { samples: 4, distance: inf })\n"
        ),
        ["technique (checkpoint: --mode ao --samples 4 --ao-distance 0.5; now: --mode ao --samples 4)"],
        "no distance limit is no --ao-distance, which takes finite values only"
    );
}

/// A refused resume names every technique by its `--mode` flag, read from the Debug text that a
/// checkpoint's options description holds (`Materials(Materials)` is `--mode materials`).
#[test]
fn every_technique_is_named_by_its_mode_flag() {
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 3, 2);
    let description = |technique| options_description(&RenderOptions::new(technique), &camera);
    let ao = Technique::AmbientOcclusion(AmbientOcclusion { samples: 2, distance: 0.5 });
    for (technique, flags) in [
        (Technique::Materials(Materials), "--mode materials"),
        (Technique::Shadows(Shadows), "--mode shadows"),
        (Technique::direct(4), "--mode direct --samples 4 --light-sampling per-light"),
        (ao, "--mode ao --samples 2 --ao-distance 0.5"),
    ] {
        assert_eq!(
            differing_options(&description(technique), &description(Technique::Hits(Hits))),
            [format!("technique (checkpoint: {flags}; now: --mode hits)")]
        );
    }
}

/// Values are quoted up to 120 characters; longer ones (the camera's matrices) are only said to
/// differ.
#[test]
fn differing_values_are_quoted_up_to_120_characters() {
    let line = |n: usize, c: &str| format!("camera: {}\n", c.repeat(n));
    assert_eq!(
        differing_options(&line(120, "a"), &line(120, "b")),
        [format!("camera (checkpoint: {}; now: {})", "a".repeat(120), "b".repeat(120))]
    );
    assert_eq!(differing_options(&line(121, "a"), &line(120, "b")), ["camera (differs from the checkpoint's)"]);
}

/// A checkpoint resumes only with its scene, its options (the seed included) and a film of the
/// image's size; each mismatch is reported as what it is, the first of them in that order.
#[test]
fn a_checkpoint_resumes_only_with_its_scene_options_and_image_size() {
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 3, 2);
    let options = RenderOptions { seed: 1, ..RenderOptions::new(Technique::direct(2)) };
    let fingerprints = Fingerprints::new(7, &options, &camera);
    let saved = fingerprints.checkpoint(checkpoint(3, 2, "").film, RenderStats::default());
    assert_eq!(fingerprints.mismatch(&saved), None);
    assert_eq!(Fingerprints::new(8, &options, &camera).mismatch(&saved), Some(Mismatch::Scene));
    let sobol = RenderOptions { sampler: SamplerKind::Sobol, ..options.clone() };
    assert_eq!(
        Fingerprints::new(7, &sobol, &camera).mismatch(&saved),
        Some(Mismatch::Options(vec!["sampler (checkpoint: independent; now: sobol)".to_string()]))
    );
    // A seed altered apart from the options text (a forged file) is still another render, and the
    // refusal names something rather than an empty list.
    let reseeded = Checkpoint { seed: 2, ..saved.clone() };
    assert_eq!(
        fingerprints.mismatch(&reseeded),
        Some(Mismatch::Options(vec!["its seed or options fingerprint, which disagree with its options text".into()]))
    );
    let resized = Checkpoint { film: checkpoint(2, 3, "").film, ..saved.clone() };
    assert_eq!(fingerprints.mismatch(&resized), Some(Mismatch::FilmSize { film: (2, 3), image: (3, 2) }));
}
