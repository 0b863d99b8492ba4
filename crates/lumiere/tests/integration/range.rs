//! Pass ranges rendered apart and added in pass order give the bytes of a render made in one go,
//! whatever the split and the order the ranges finish in; that is what distributed renders rely on.

use std::sync::atomic::{AtomicBool, Ordering};

use lumiere::integrators::{AmbientOcclusion, Hits, Path, Technique};
use lumiere::render::film::{Film, PassSamples};
use lumiere::render::{RenderOptions, render, render_pass_range};
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

fn cornell(width: u32, height: u32) -> (World, Camera) {
    let world = World::new(Scene::builtin().unwrap(), Default::default());
    (world, Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), width, height))
}

fn bits(film: &Film) -> Vec<u32> {
    film.image().pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect()
}

#[test]
fn ranges_added_in_pass_order_give_the_bytes_of_one_render() {
    let (world, camera) = cornell(40, 30);
    let mut options = RenderOptions::new(Technique::Path(Path::default()));
    options.spp = 7;
    options.seed = 3;
    let whole = render(&world, &camera, &options, &|_| {}).unwrap();
    let cancel = AtomicBool::new(false);
    // Ranges of uneven sizes, rendered last first, as workers may finish.
    let mut passes: Vec<PassSamples> = Vec::new();
    for (first, count) in [(5, 2), (1, 4), (0, 1)] {
        let range = render_pass_range(&world, &camera, &options, first, count, &|_| {}, &cancel).unwrap();
        assert_eq!(range.len(), count as usize);
        passes.extend(range);
    }
    passes.sort_by_key(|p| p.sample);
    let mut film = Film::new(camera.width, camera.height).unwrap();
    for pass in &passes {
        film.add_pass(pass).unwrap();
    }
    assert_eq!(film, whole.film, "sums, second moments and counts are bit for bit the same");
    assert_eq!(bits(&film), bits(&whole.film));
    assert_eq!(passes.iter().map(|p| p.rays).sum::<u64>(), whole.stats.rays);
}

#[test]
fn passes_out_of_order_or_outside_the_render_are_refused() {
    let (world, camera) = cornell(8, 6);
    let mut options = RenderOptions::new(Technique::Path(Path::default()));
    options.spp = 3;
    let cancel = AtomicBool::new(false);
    let passes = render_pass_range(&world, &camera, &options, 0, 3, &|_| {}, &cancel).unwrap();
    let mut film = Film::new(camera.width, camera.height).unwrap();
    let error = film.add_pass(&passes[1]).unwrap_err().to_string();
    assert!(error.contains("passes are added in order"), "{error}");
    let error = render_pass_range(&world, &camera, &options, 2, 2, &|_| {}, &cancel).unwrap_err().to_string();
    assert!(error.contains("outside a render of 3 samples"), "{error}");
    let mut other = Film::new(4, 4).unwrap();
    assert!(other.add_pass(&passes[0]).is_err(), "a pass of another size is refused");
}

#[test]
fn a_cancelled_range_returns_whole_passes_only() {
    let (world, camera) = cornell(8, 6);
    let mut options = RenderOptions::new(Technique::Path(Path::default()));
    options.spp = 4;
    let cancel = AtomicBool::new(true);
    let passes = render_pass_range(&world, &camera, &options, 0, 4, &|_| {}, &cancel).unwrap();
    assert!(passes.is_empty());
}

/// A cancel seen inside the last block of a range's pass (a 4x4 image is one block) leaves that
/// pass out: a range never holds a partial pass, which a distributed render would add to its film.
#[test]
fn a_range_cancelled_inside_its_last_block_returns_no_partial_pass() {
    let (world, camera) = cornell(4, 4);
    let mut options = RenderOptions::new(Technique::ambient_occlusion(1 << 30));
    options.spp = 2;
    let cancel = AtomicBool::new(false);
    let passes = std::thread::scope(|scope| {
        scope.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(50));
            cancel.store(true, Ordering::Relaxed);
        });
        render_pass_range(&world, &camera, &options, 0, 2, &|_| {}, &cancel).unwrap()
    });
    assert!(passes.is_empty(), "{} passes", passes.len());
}

/// A range as long as a u32 counts asks for no memory up front: one cancelled at once returns
/// nothing, where reserving its records aborted the process (Python's `render_passes`).
#[test]
fn a_range_of_billions_of_passes_reserves_nothing_up_front() {
    let (world, camera) = cornell(8, 6);
    let mut options = RenderOptions::new(Technique::Path(Path::default()));
    options.spp = u32::MAX;
    let cancel = AtomicBool::new(true);
    let passes = render_pass_range(&world, &camera, &options, 0, u32::MAX - 1, &|_| {}, &cancel).unwrap();
    assert!(passes.is_empty());
}

/// Pixels are numbered in 32 bits for the sampler: an image of more pixels is refused rather than
/// rendered with pixels that share their random numbers.
#[test]
fn an_image_of_more_pixels_than_32_bits_number_is_refused() {
    let (world, camera) = cornell(65_536, 65_536);
    let options = RenderOptions::new(Technique::Path(Path::default()));
    let cancel = AtomicBool::new(true);
    let error = render_pass_range(&world, &camera, &options, 0, 1, &|_| {}, &cancel).unwrap_err().to_string();
    assert!(error.contains("more than 4,294,967,295 pixels"), "{error}");
}

/// Options are checked before any pass: a range of no passes renders nothing, so it says whether
/// options are accepted without rendering (nor allocating) an image.
fn accepts((world, camera): (World, Camera), options: &RenderOptions) -> Result<(), String> {
    let cancel = AtomicBool::new(false);
    render_pass_range(&world, &camera, options, 0, 0, &|_| {}, &cancel)
        .map(|passes| assert!(passes.is_empty()))
        .map_err(|e| e.to_string())
}

/// The most pixels a render numbers is 2^32 - 1 (65,535 x 65,537) exactly; an image without
/// pixels in either direction is refused.
#[test]
fn image_sizes_are_refused_at_the_bounds_exactly() {
    let options = RenderOptions::new(Technique::Path(Path::default()));
    assert_eq!(accepts(cornell(65_535, 65_537), &options), Ok(()));
    let error = accepts(cornell(65_536, 65_536), &options).unwrap_err();
    assert!(error.contains("more than 4,294,967,295 pixels"), "{error}");
    for (width, height) in [(0, 4), (4, 0)] {
        let error = accepts(cornell(width, height), &options).unwrap_err();
        assert!(error.contains("has no pixels"), "{width}x{height}: {error}");
    }
}

#[test]
fn a_noise_target_must_be_positive() {
    let with = |target: f64| RenderOptions {
        noise_target: Some(target),
        ..RenderOptions::new(Technique::Path(Path::default()))
    };
    assert_eq!(accepts(cornell(8, 6), &with(0.01)), Ok(()));
    for target in [0.0, -0.5, f64::NAN] {
        let error = accepts(cornell(8, 6), &with(target)).unwrap_err();
        assert!(error.contains("the noise target must be positive"), "{target}: {error}");
    }
}

/// Technique settings no render can use are refused: no samples, or an occlusion distance that is
/// not positive (NaN included).
#[test]
fn technique_settings_no_render_can_use_are_refused() {
    let ao = |samples, distance| Technique::AmbientOcclusion(AmbientOcclusion { samples, distance });
    for technique in [ao(4, 0.5), ao(1, f32::INFINITY), Technique::direct(1)] {
        assert!(technique.validate().is_ok(), "{technique:?}");
    }
    for distance in [0.0, -1.0, f32::NAN, f32::NEG_INFINITY] {
        let error = ao(4, distance).validate().unwrap_err().to_string();
        assert!(error.contains("distance must be positive"), "{distance}: {error}");
    }
    for technique in [ao(0, 1.0), Technique::direct(0)] {
        let error = technique.validate().unwrap_err().to_string();
        assert!(error.contains("must be at least 1"), "{technique:?}: {error}");
    }
}

/// A pass counts every ray its tiles traced: one camera ray a pixel for hits, over an image of
/// several bands and tile columns (and a partial tile at each far edge).
#[test]
fn a_pass_counts_every_ray_of_its_tiles() {
    let (world, camera) = cornell(150, 70);
    let options = RenderOptions { spp: 2, ..RenderOptions::new(Technique::Hits(Hits)) };
    let passes = render_pass_range(&world, &camera, &options, 0, 2, &|_| {}, &AtomicBool::new(false)).unwrap();
    assert!(passes.iter().all(|pass| pass.rays == 150 * 70), "{:?}", passes.iter().map(|p| p.rays).collect::<Vec<_>>());
}
