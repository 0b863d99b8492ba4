//! Pass ranges rendered apart and added in pass order give the bytes of a render made in one go,
//! whatever the split and the order the ranges finish in; that is what distributed renders rely on.

use std::sync::atomic::AtomicBool;

use lumiere::integrators::{Path, Technique};
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
