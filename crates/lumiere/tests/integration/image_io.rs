//! Image writers: values survive a round trip through each format, rows land the right way up, and
//! writes are atomic (old content fully replaced, nothing left behind on success or failure).

use std::fs;
use std::path::Path;

use crate::common::TempDir;
use glam::Vec3;
use lumiere::Error;
use lumiere::image_io::{
    ExrLayer, PngEncoding, PngStyle, Tonemap, check_output_path, linear_to_srgb8, write_exr_with_layers, write_image,
};
use lumiere::util::write::{remove_stale_temporaries, write_atomically};

/// The reference: IEC 61966-2-1 in f64, rounded to nearest.
fn srgb8_exact(c: f32) -> u8 {
    let c = f64::from(c).clamp(0.0, 1.0);
    let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

/// A gray pixel.
fn g(c: f32) -> Vec3 {
    Vec3::splat(c)
}

fn assert_io_error(result: lumiere::Result<()>, expected_path: &Path) {
    match result {
        Err(Error::Io { path, .. }) => assert_eq!(path, expected_path),
        other => panic!("expected Error::Io for {}, got {other:?}", expected_path.display()),
    }
}

fn assert_invalid(result: lumiere::Result<()>, needle: &str) {
    match result {
        Err(Error::Invalid(message)) => {
            assert!(message.contains(needle), "message {message:?} should mention {needle:?}")
        }
        other => panic!("expected Error::Invalid mentioning {needle:?}, got {other:?}"),
    }
}

#[test]
fn png_srgb_round_trip_values_and_row_order() {
    let dir = TempDir::new("png-srgb");
    let path = dir.path("out.png");
    let boundary = 0.0031308_f32;
    let top = [g(0.0), g(1.0), g(0.5), g(boundary)];
    let bottom = [
        g(boundary.next_up()),
        Vec3::new(0.2, 0.04, 0.8),
        Vec3::new(f32::NAN, f32::INFINITY, -1.0),
        g(f32::NEG_INFINITY),
    ];
    let pixels: Vec<Vec3> = top.iter().chain(&bottom).copied().collect();
    write_image(&path, 4, 2, &pixels, PngEncoding::Srgb).expect("write png");

    let img = image::open(&path).expect("decode png").to_rgb8();
    assert_eq!(img.dimensions(), (4, 2));
    let px = |x, y| img.get_pixel(x, y).0;
    assert_eq!(px(0, 0), [0, 0, 0], "row 0 is the top row");
    assert_eq!(px(1, 0), [255, 255, 255]);
    assert_eq!(px(2, 0), [188, 188, 188]);
    assert_eq!(px(3, 0), [10, 10, 10], "12.92 * 0.0031308 * 255 = 10.3");
    assert_eq!(px(0, 1), [10, 10, 10], "continuous across the linear/power boundary");
    assert_eq!(px(1, 1), [srgb8_exact(0.2), srgb8_exact(0.04), srgb8_exact(0.8)]);
    assert_eq!(px(2, 1), [0, 255, 0], "NaN -> 0, +inf -> 255, negative -> 0");
    assert_eq!(px(3, 1), [0, 0, 0]);
    assert_eq!(dir.entries(), ["out.png"]);
}

/// The filmic curve rises with radiance and saturates to white, however bright or exposed the
/// pixel: from about 1e19 its squares overflowed, and inf / inf turned the brightest pixels black.
#[test]
fn aces_rises_to_white_and_never_turns_black() {
    let dir = TempDir::new("png-aces");
    let path = dir.path("out.png");
    let radiance = [0.0, 0.01, 0.18, 1.0, 4.0, 12.0, 100.0, 1e19, 1e30, f32::MAX, f32::INFINITY];
    let pixels: Vec<Vec3> = radiance.iter().map(|&c| g(c)).collect();
    let width = pixels.len() as u32;
    let grey = |exposure: f32| {
        let style = PngStyle { encoding: PngEncoding::Srgb, exposure, tonemap: Tonemap::Aces };
        write_image(&path, width, 1, &pixels, style).expect("write png");
        let img = image::open(&path).expect("decode png").to_rgb8();
        (0..width).map(|x| img.get_pixel(x, 0).0[0]).collect::<Vec<u8>>()
    };
    let plain = grey(0.0);
    assert_eq!(plain[0], 0);
    assert!(plain.windows(2).all(|w| w[0] <= w[1]), "not rising: {plain:?}");
    assert!(plain[3] > 100 && plain[3] < 255, "radiance 1 is mid-grey, not white: {plain:?}");
    assert!(plain[5..].iter().all(|&v| v == 255), "bright pixels are white: {plain:?}");
    let exposed = grey(PngStyle::MAX_EXPOSURE);
    assert!(exposed[1..].iter().all(|&v| v == 255), "every lit pixel is white at +64 stops: {exposed:?}");
}

/// The filmic curve's values, not only its shape: Narkowicz's fit `x (2.51 x + 0.03) / (x (2.43 x +
/// 0.59) + 0.14)` of `x = 0.6 × radiance × 2^exposure`, then sRGB. Each code is the formula's in
/// f64, at least 0.1 from a rounding edge (0.18 gives 104.60, 1 gives 214.12, 2 gives 236.11).
#[test]
fn aces_follows_narkowiczs_fit_after_the_exposure() {
    let dir = TempDir::new("png-aces-values");
    let path = dir.path("out.png");
    let codes = |exposure: f32, radiance: &[f32]| {
        let pixels: Vec<Vec3> = radiance.iter().map(|&c| g(c)).collect();
        let style = PngStyle { encoding: PngEncoding::Srgb, exposure, tonemap: Tonemap::Aces };
        write_image(&path, pixels.len() as u32, 1, &pixels, style).expect("write png");
        let img = image::open(&path).expect("decode png").to_rgb8();
        img.pixels().map(|p| p.0[0]).collect::<Vec<u8>>()
    };
    assert_eq!(codes(0.0, &[0.01, 0.05, 0.18, 1.0, 2.0, 7.0]), [6, 38, 105, 214, 236, 252]);
    // +1 stop doubles the radiance, -2 stops quarter it, before the curve.
    assert_eq!(codes(1.0, &[0.5, 1.0]), [214, 236]);
    assert_eq!(codes(-2.0, &[4.0, 8.0]), [214, 236]);
}

/// An sRGB PNG says so (an `sRGB` chunk, perceptual intent), so that viewers show its codes as
/// sRGB; gKit's linear bytes are not sRGB-encoded and carry no such chunk.
#[test]
fn only_srgb_pngs_carry_the_srgb_chunk() {
    let dir = TempDir::new("png-chunk");
    let path = dir.path("out.png");
    for (encoding, intent) in
        [(PngEncoding::Srgb, Some(png::SrgbRenderingIntent::Perceptual)), (PngEncoding::GkitLinear, None)]
    {
        write_image(&path, 2, 1, &[g(0.25), g(0.75)], encoding).expect("write png");
        let reader = png::Decoder::new(std::io::Cursor::new(fs::read(&path).expect("read png")))
            .read_info()
            .expect("decode png header");
        assert_eq!(reader.info().srgb, intent, "{encoding:?}");
    }
}

#[test]
fn png_gkit_linear_truncates_without_gamma() {
    let dir = TempDir::new("png-gkit");
    let path = dir.path("gkit.PNG");
    let pixels = [g(0.5), g(0.999), g(1.0), g(2.0), Vec3::new(f32::NAN, f32::INFINITY, -0.5)];
    write_image(&path, 5, 1, &pixels, PngEncoding::GkitLinear).expect("write png");

    let bytes = fs::read(&path).expect("read png");
    let img = image::load_from_memory(&bytes).expect("decode png").to_rgb8();
    let row: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert_eq!(row, [[127; 3], [254; 3], [255; 3], [255; 3], [0, 255, 0]]);
}

/// One image gives one EXR file, byte for byte: the tiles (64x64, compressed in parallel) are
/// stored in order, not as they finish. Without the order, two of five writes of this image
/// already differed.
#[test]
fn exr_bytes_do_not_depend_on_the_order_tiles_finish_in() {
    let dir = TempDir::new("exr-order");
    let (w, h) = (640u32, 448u32);
    // Tiles that take different times to compress: flat ones (long runs) and noisy ones.
    let pixels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (x / 64 + y / 64) % 2 == 0 {
                Vec3::splat(0.5)
            } else {
                Vec3::splat((i.wrapping_mul(2_654_435_761) >> 8) as f32)
            }
        })
        .collect();
    let layer = ExrLayer { name: "albedo", channels: &["R", "G", "B"], pixels: &pixels };
    let mut firsts: Vec<Vec<u8>> = Vec::new();
    for round in 0..5 {
        let (plain, layered) = (dir.path(&format!("plain{round}.exr")), dir.path(&format!("layers{round}.exr")));
        write_image(&plain, w, h, &pixels, PngEncoding::default()).expect("write exr");
        write_exr_with_layers(&layered, w, h, &pixels, &[layer]).expect("write exr");
        let bytes = [fs::read(&plain).unwrap(), fs::read(&layered).unwrap()];
        if firsts.is_empty() {
            firsts.extend(bytes);
        } else {
            assert!(bytes[0] == firsts[0], "round {round}: the image's EXR changed");
            assert!(bytes[1] == firsts[1], "round {round}: the layered EXR changed");
        }
    }
    // Where the tiles happen to finish in order (one core), equal bytes prove nothing: the header
    // must fix the order too.
    for bytes in &firsts {
        let meta = exr::meta::MetaData::read_from_buffered(bytes.as_slice(), false).expect("read exr header");
        assert!(meta.headers.iter().all(|h| h.line_order == exr::prelude::LineOrder::Increasing));
    }
}

#[test]
fn exr_round_trip_is_bit_exact_and_top_down() {
    let dir = TempDir::new("exr");
    let path = dir.path("out.Exr");
    let (w, h) = (3usize, 2usize);
    let pixels = [
        Vec3::new(0.0, 1.0, 0.5),
        Vec3::new(1e-42, -3.25, 1e30),
        Vec3::new(f32::INFINITY, f32::NEG_INFINITY, f32::NAN),
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(-0.0, 65504.5, 1.0 / 3.0),
        Vec3::new(7.0, 8.0, 9.0),
    ];
    write_image(&path, w as u32, h as u32, &pixels, PngEncoding::default()).expect("write exr");

    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |size, _| vec![[0.0f32; 3]; size.width() * size.height()],
        move |out: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            out[pos.y() * w + pos.x()] = [r, g, b];
        },
    )
    .expect("read exr");
    let size = image.layer_data.size;
    assert_eq!((size.width(), size.height()), (w, h));
    let read = &image.layer_data.channel_data.pixels;
    for (i, (got, want)) in read.iter().zip(&pixels).enumerate() {
        let got_bits = got.map(f32::to_bits);
        let want_bits = want.to_array().map(f32::to_bits);
        assert_eq!(got_bits, want_bits, "pixel {i} (row {}, from the top)", i / w);
    }
    assert_eq!(dir.entries(), ["out.Exr"]);
}

#[test]
fn pfm_round_trip_rows_bottom_to_top() {
    let dir = TempDir::new("pfm");
    let path = dir.path("out.pfm");
    let (w, h) = (2usize, 3usize);
    let pixels: Vec<Vec3> = (0..w * h).map(|i| Vec3::new(i as f32, -(i as f32) * 0.5, 1e-3 * i as f32)).collect();
    let mut with_specials = pixels.clone();
    with_specials[1] = Vec3::new(f32::NAN, f32::INFINITY, f32::NEG_INFINITY);
    write_image(&path, w as u32, h as u32, &with_specials, PngEncoding::Srgb).expect("write pfm");

    let bytes = fs::read(&path).expect("read pfm");
    let header = format!("PF\n{w} {h}\n-1.0\n");
    assert!(bytes.starts_with(header.as_bytes()), "header");
    let data = &bytes[header.len()..];
    assert_eq!(data.len(), w * h * 3 * 4);
    let floats: Vec<f32> = data.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
    for (file_row, row) in floats.chunks_exact(w * 3).enumerate() {
        let picture_row = h - 1 - file_row;
        let expected = &with_specials[picture_row * w..(picture_row + 1) * w];
        let got: Vec<u32> = row.iter().map(|f| f.to_bits()).collect();
        let want: Vec<u32> = expected.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect();
        assert_eq!(got, want, "file row {file_row} holds picture row {picture_row}");
    }
}

#[test]
fn unknown_or_missing_extension_is_invalid_and_writes_nothing() {
    let dir = TempDir::new("ext");
    for name in ["out.jpg", "out", "out.png.bak"] {
        let path = dir.path(name);
        let result = write_image(&path, 1, 1, &[g(0.5)], PngEncoding::Srgb);
        assert_invalid(result, ".png, .exr, .pfm");
        assert_invalid(check_output_path(&path), ".png, .exr, .pfm");
    }
    assert!(dir.entries().is_empty());
}

#[test]
fn wrong_pixel_count_or_zero_size_is_invalid() {
    let dir = TempDir::new("dims");
    let path = dir.path("out.png");
    assert_invalid(write_image(&path, 2, 2, &[g(0.0); 3], PngEncoding::Srgb), "3 pixels");
    assert_invalid(write_image(&path, 0, 2, &[], PngEncoding::Srgb), "zero");
    assert_invalid(write_image(&path, 2, 0, &[], PngEncoding::Srgb), "zero");
    assert!(dir.entries().is_empty());
}

#[test]
fn missing_directory_is_an_io_error_naming_the_path_and_leaves_nothing() {
    let dir = TempDir::new("missing");
    let path = dir.path("no/such/dir/out.exr");
    assert_io_error(write_image(&path, 1, 1, &[g(1.0)], PngEncoding::Srgb), &path);
    assert_io_error(write_atomically(&path, b"bytes"), &path);
    assert_io_error(check_output_path(&path), &path);
    // The message names the folder that is missing, not only the file that could not be made.
    let message = check_output_path(&path).unwrap_err().to_string();
    let folder = dir.path("no/such/dir");
    assert!(message.ends_with(&format!("the folder {} does not exist", folder.display())), "{message}");
    assert!(dir.entries().is_empty());
}

#[test]
fn overwrite_replaces_old_content_fully() {
    let dir = TempDir::new("overwrite");
    let path = dir.path("stats.json");
    write_atomically(&path, &vec![b'x'; 100_000]).expect("first write");
    write_atomically(&path, b"{}").expect("second write");
    assert_eq!(fs::read(&path).expect("read back"), b"{}");

    let image = dir.path("img.pfm");
    fs::write(&image, vec![0u8; 10_000]).expect("old image");
    write_image(&image, 1, 1, &[g(2.0)], PngEncoding::Srgb).expect("overwrite image");
    let mut expected = b"PF\n1 1\n-1.0\n".to_vec();
    expected.extend([2.0f32; 3].iter().flat_map(|f| f.to_le_bytes()));
    assert_eq!(fs::read(&image).expect("read back"), expected);
    assert_eq!(dir.entries(), ["img.pfm", "stats.json"]);
}

#[test]
fn writing_over_a_directory_is_refused_and_leaves_it_untouched() {
    let dir = TempDir::new("rename-fails");
    let target = dir.path("taken.png");
    fs::create_dir(&target).expect("dir in the way");
    fs::write(target.join("keep"), b"keep").expect("content");
    assert_invalid(write_image(&target, 1, 1, &[g(0.5)], PngEncoding::Srgb), "directory");
    assert_eq!(dir.entries(), ["taken.png"]);
    assert_eq!(fs::read(target.join("keep")).expect("untouched"), b"keep");
    assert_invalid(check_output_path(&target), "directory");
}

/// A device node in place of an output is never replaced by a regular file (as root, a rename over
/// `/dev/null` would succeed); a FIFO neither, and nothing blocks on it.
#[test]
fn existing_non_regular_targets_are_refused() {
    assert_invalid(write_atomically(Path::new("/dev/null"), b"x"), "not a regular file");
    let dir = TempDir::new("fifo-target");
    let fifo = dir.path("out.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    if made {
        assert_invalid(write_atomically(&fifo, b"x"), "not a regular file");
        assert_eq!(dir.entries(), ["out.json"]);
    }
}

/// A replaced file keeps its permissions: the rename publishes a new file, which would otherwise
/// take the umask's (a group-readable or read-only image came back as 0644).
#[cfg(unix)]
#[test]
fn a_replaced_file_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new("permissions");
    let path = dir.path("image.bin");
    for mode in [0o640, 0o600, 0o664] {
        fs::write(&path, b"old").unwrap();
        fs::set_permissions(&path, fs::Permissions::from_mode(mode)).unwrap();
        write_atomically(&path, b"new").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new");
        assert_eq!(fs::metadata(&path).unwrap().permissions().mode() & 0o7777, mode, "{mode:o}");
    }
    assert_eq!(dir.entries(), ["image.bin"]);
}

/// Temporaries that no writer holds and that have gone unwritten for a while are removed, whatever
/// the pid in their names (a live one: this process's, as when a container reuses the pid of the run
/// it replaced); those a writer holds, those written just now, and other files are kept.
#[cfg(unix)]
#[test]
fn abandoned_temporaries_are_removed_whatever_their_pid() {
    use std::os::unix::io::AsRawFd;
    let dir = TempDir::new("stale");
    let aged = |name: &str| {
        dir.write(name, "half");
        let file = fs::File::options().write(true).open(dir.path(name)).unwrap();
        file.set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(3600)).unwrap();
        file
    };
    let mine = format!(".lumiere-{}-999999.tmp", std::process::id());
    drop(aged(".lumiere-4194304-0.tmp"));
    drop(aged(&mine));
    // A writer elsewhere (another container's process, unknown here) still holds this one.
    let held = aged(".lumiere-4194305-0.tmp");
    // SAFETY: flock on a descriptor `held` owns; released when it is dropped below.
    assert_eq!(unsafe { libc::flock(held.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) }, 0);
    dir.write(".lumiere-4194306-0.tmp", "written just now");
    drop(aged(".lumiere-notapid-0.tmp"));
    dir.write("render.png", "kept");
    assert_eq!(remove_stale_temporaries(&dir.0), 2);
    let kept = [".lumiere-4194305-0.tmp", ".lumiere-4194306-0.tmp", ".lumiere-notapid-0.tmp", "render.png"];
    assert_eq!(dir.entries(), kept);
    drop(held);
    assert_eq!(remove_stale_temporaries(&dir.0), 1, "no writer holds it any more");
}

/// Names of temporaries that a killed process left under this process's pid do not stop a write:
/// the next free name is used, and the old files are left to the cleanup.
#[test]
fn a_write_takes_the_next_name_when_stale_temporaries_hold_its_own() {
    let dir = TempDir::new("taken");
    let pid = std::process::id();
    for n in 0..2000 {
        dir.write(&format!(".lumiere-{pid}-{n}.tmp"), "left by a killed run");
    }
    let path = dir.path("out.bin");
    write_atomically(&path, b"new").expect("a free name is found");
    assert_eq!(fs::read(&path).unwrap(), b"new");
    assert_eq!(dir.entries().len(), 2001, "the old files stay, nothing else is left");
}

#[test]
fn concurrent_writers_never_collide_or_leave_temp_files() {
    let dir = TempDir::new("threads");
    let path = dir.path("shared.bin");
    let contents: Vec<Vec<u8>> = (0..8u8).map(|i| vec![i; 50_000 + usize::from(i)]).collect();
    std::thread::scope(|s| {
        for bytes in &contents {
            let path = &path;
            s.spawn(move || {
                for _ in 0..20 {
                    write_atomically(path, bytes).expect("concurrent write");
                }
            });
        }
    });
    let last = fs::read(&path).expect("read back");
    assert!(contents.contains(&last), "the file is one writer's complete content");
    assert_eq!(dir.entries(), ["shared.bin"]);
}

#[test]
fn linear_to_srgb8_matches_exact_formula() {
    // A dense uniform grid over [0, 1] ...
    let n = 1 << 20;
    for i in 0..=n {
        let c = i as f32 / n as f32;
        assert_eq!(linear_to_srgb8(c), srgb8_exact(c), "c = {c:e}");
    }
    // ... every f32 within 64 ulps of each rounding threshold, where a table would slip ...
    for code in 1..=255u32 {
        let v = (f64::from(code) - 0.5) / 255.0;
        let lin = if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) };
        let centre = (lin as f32).to_bits();
        for bits in centre - 64..centre + 64 {
            let x = f32::from_bits(bits);
            assert_eq!(linear_to_srgb8(x), srgb8_exact(x), "c = {x:e} near code {code}");
        }
    }
    // ... tiny values and out-of-range inputs.
    for c in [f32::MIN_POSITIVE, 1e-45, 1e-10, 1e-5, 1.0f32.next_down()] {
        assert_eq!(linear_to_srgb8(c), srgb8_exact(c), "c = {c:e}");
    }
    assert_eq!(linear_to_srgb8(f32::NAN), 0);
    assert_eq!(linear_to_srgb8(-f32::NAN), 0);
    assert_eq!(linear_to_srgb8(-1.0), 0);
    assert_eq!(linear_to_srgb8(f32::NEG_INFINITY), 0);
    assert_eq!(linear_to_srgb8(1.5), 255);
    assert_eq!(linear_to_srgb8(f32::INFINITY), 255);
}

#[test]
fn check_output_path_accepts_writable_targets_and_leaves_nothing() {
    let dir = TempDir::new("check");
    for name in ["a.png", "b.EXR", "c.pfm"] {
        check_output_path(&dir.path(name)).expect("writable path");
    }
    let existing = dir.path("existing.png");
    fs::write(&existing, b"old").expect("existing file");
    check_output_path(&existing).expect("existing file may be overwritten");
    assert_eq!(fs::read(&existing).expect("untouched"), b"old");
    assert_eq!(dir.entries(), ["existing.png"]);
}

#[cfg(unix)]
#[test]
fn check_output_path_rejects_a_read_only_directory() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new("read-only");
    let sub = dir.path("ro");
    fs::create_dir(&sub).expect("subdir");
    fs::set_permissions(&sub, fs::Permissions::from_mode(0o555)).expect("chmod");
    // Root ignores directory permissions; then there is nothing to test.
    let probe = sub.join("probe");
    let privileged = fs::write(&probe, b"").is_ok();
    let _ = fs::remove_file(&probe);
    let path = sub.join("out.png");
    if !privileged {
        assert_io_error(check_output_path(&path), &path);
        assert_io_error(write_image(&path, 1, 1, &[g(0.5)], PngEncoding::Srgb), &path);
    }
    fs::set_permissions(&sub, fs::Permissions::from_mode(0o755)).expect("chmod back");
    assert!(fs::read_dir(&sub).expect("read subdir").next().is_none());
}

/// AOVs line up with the image: at pixel centres the albedo AOV is what `materials` mode shows,
/// normals are unit vectors facing the camera, depth is the distance to the hit; and they go to
/// EXR channels by name, bit for bit.
#[test]
fn aovs_match_the_first_hit_and_round_trip_through_exr() {
    use lumiere::image_io::{ExrLayer, write_exr_with_layers};
    use lumiere::integrators::{Materials, Technique};
    use lumiere::render::aov::{Aov, render_aovs};
    use lumiere::render::{RenderOptions, render};
    use lumiere::scene::{Scene, builtin, camera::Camera};
    use lumiere::world::World;
    use std::sync::atomic::AtomicBool;

    let world = World::new(Scene::builtin().unwrap(), Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 32, 24);
    let options = RenderOptions::new(Technique::Materials(Materials));
    let colours = render(&world, &camera, &options, &|_| {}).unwrap().image.pixels;
    let all = [Aov::Albedo, Aov::Normal, Aov::Depth];
    let aovs = render_aovs(&world, &camera, &options, &all, &AtomicBool::new(false)).expect("not cancelled");
    assert_eq!(aovs[0], colours, "albedo AOV = materials mode at pixel centres");
    assert!(render_aovs(&world, &camera, &options, &all, &AtomicBool::new(true)).is_none(), "cancelled");
    for (i, (n, d)) in aovs[1].iter().zip(&aovs[2]).enumerate() {
        if colours[i] == Vec3::ZERO {
            continue;
        }
        assert!((n.length() - 1.0).abs() < 1e-4, "pixel {i}: normal {n}");
        assert!(d.x > 0.0 && d.x.is_finite(), "pixel {i}: depth {d}");
    }

    let dir = TempDir::new("aov-exr");
    let path = dir.path("aov.exr");
    let layers = [
        ExrLayer { name: "albedo", channels: &["R", "G", "B"], pixels: &aovs[0] },
        ExrLayer { name: "depth", channels: &["Z"], pixels: &aovs[2] },
    ];
    write_exr_with_layers(&path, 32, 24, &colours, &layers).unwrap();
    let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let layer = &image.layer_data[0];
    let channel = |name: &str| -> Vec<f32> {
        let found = layer.channel_data.list.iter().find(|c| c.name.to_string() == name).expect(name);
        match &found.sample_data {
            exr::prelude::FlatSamples::F32(values) => values.clone(),
            _ => panic!("{name} is not f32"),
        }
    };
    assert_eq!(channel("albedo.G"), aovs[0].iter().map(|p| p.y).collect::<Vec<_>>());
    assert_eq!(channel("depth.Z"), aovs[2].iter().map(|p| p.x).collect::<Vec<_>>());
    assert_eq!(channel("R"), colours.iter().map(|p| p.x).collect::<Vec<_>>());
    assert_invalid(write_exr_with_layers(&dir.path("aov.png"), 32, 24, &colours, &layers), "need an .exr");
}
