//! The film keeps its samples in the smallest exact form (nothing, one pass's values, f64 sums),
//! and every form must hold the very bits of sums added pass after pass, the way the film always
//! added them: `tests/cli/golden.rs` pins images, these pin the sums and second moments that
//! checkpoints, resumes and noise targets read.

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use glam::Vec3;
use lumiere::integrators::Technique;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::film::{Film, PassSamples, luminance};
use lumiere::render::{Hooks, RenderOptions, RenderStats, StopReason, render_pass_range, render_progressive};
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

const WIDTH: u32 = 5;
const HEIGHT: u32 = 3;

/// Pass `k`'s values: ordinary ones, and the ones the film must count as 0 or must not keep as
/// they are (NaN, infinities, negatives, -0, a denormal, the largest float).
fn pass(k: u32) -> PassSamples {
    pass_of_size(k, WIDTH, HEIGHT)
}

/// [`pass`] for a film of `width` x `height`.
fn pass_of_size(k: u32, width: u32, height: u32) -> PassSamples {
    let odd = [
        Vec3::new(f32::NAN, 1.0, 1.0),
        Vec3::new(0.5, f32::INFINITY, 0.0),
        Vec3::new(0.5, 0.25, f32::NEG_INFINITY),
        Vec3::new(-1e-30, 2.0, 3.0),
        Vec3::new(-0.0, -0.0, -0.0),
        Vec3::new(-0.0, 0.75, 0.0),
        Vec3::new(f32::MIN_POSITIVE / 4.0, 1e-3, 7.0),
        Vec3::new(f32::MAX, 1.0, 0.0),
    ];
    let values = (0..width * height)
        .map(|p| {
            let ordinary = Vec3::new(0.1 * (p + k) as f32, 1.0 / (1 + p * k) as f32, (p as f32).sqrt() / 3.0);
            if (p + k).is_multiple_of(2) { odd[((p + 3 * k) % 8) as usize] } else { ordinary }
        })
        .collect();
    PassSamples { sample: k, width, height, values, rays: 1 }
}

/// The film's definition, written out plainly: f64 sums from zero, one addition per pass, invalid
/// values counted and added as 0.
struct Reference {
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<f64>,
    discarded: u64,
}

impl Reference {
    fn add(&mut self, pass: &PassSamples) {
        for (p, value) in pass.values.iter().enumerate() {
            let valid = value.is_finite() && value.min_element() >= 0.0;
            let v = if valid { *value } else { Vec3::ZERO };
            self.discarded += u64::from(!valid);
            for c in 0..3 {
                self.sum[p][c] += v[c] as f64;
            }
            let y = luminance(v);
            self.sum_sq[p] += y * y;
        }
    }
}

fn bits(moments: impl Iterator<Item = ([f64; 3], f64)>) -> Vec<u64> {
    moments.flat_map(|(s, sq)| [s[0], s[1], s[2], sq]).map(f64::to_bits).collect()
}

fn image_bits(film: &Film) -> Vec<u32> {
    film.image().pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect()
}

#[test]
fn every_form_holds_the_bits_of_one_addition_per_pass() {
    let mut film = Film::new(WIDTH, HEIGHT).unwrap();
    let mut reference = Reference { sum: vec![[0.0; 3]; 15], sum_sq: vec![0.0; 15], discarded: 0 };
    assert_eq!(bits(film.moments()), bits(reference.sum.iter().copied().zip(reference.sum_sq.iter().copied())));
    assert!(image_bits(&film).iter().all(|&b| b == 0), "an empty film is black (+0)");
    for k in 0..4 {
        film.add_pass(&pass(k)).unwrap();
        reference.add(&pass(k));
        let expected = reference.sum.iter().copied().zip(reference.sum_sq.iter().copied());
        assert_eq!(bits(film.moments()), bits(expected), "after {} passes", k + 1);
        assert_eq!((film.samples, film.discarded), (k + 1, reference.discarded));
        let scale = 1.0 / (k + 1) as f64;
        let mean: Vec<u32> = reference.sum.iter().flat_map(|s| s.map(|c| ((c * scale) as f32).to_bits())).collect();
        assert_eq!(image_bits(&film), mean, "after {} passes", k + 1);
    }
}

/// The same for a film of more pixels than the film adds in one parallel job (8,192): pixels of
/// every chunk, not only the first, get their own first pass's values when a one-pass film becomes
/// sums. (The films above fit in one chunk, where chunk 0's offset is 0 however it is computed.)
#[test]
fn a_film_of_several_chunks_holds_the_bits_of_one_addition_per_pass() {
    let (width, height) = (128, 70);
    let pixels = (width * height) as usize;
    assert!(pixels > 8192, "at least two chunks");
    let mut film = Film::new(width, height).unwrap();
    let mut reference = Reference { sum: vec![[0.0; 3]; pixels], sum_sq: vec![0.0; pixels], discarded: 0 };
    for k in 0..3 {
        film.add_pass(&pass_of_size(k, width, height)).unwrap();
        reference.add(&pass_of_size(k, width, height));
        let expected = reference.sum.iter().copied().zip(reference.sum_sq.iter().copied());
        assert_eq!(bits(film.moments()), bits(expected), "after {} passes", k + 1);
        assert_eq!((film.samples, film.discarded), (k + 1, reference.discarded));
    }
}

/// Films are equal only where their sizes, counts, sums and second moments all are: equality is
/// what tells a resumed or distributed render from the one it must reproduce, so a film that
/// differs in any one of them, and only in it, is not equal.
#[test]
fn films_differing_in_one_sum_or_count_are_unequal() {
    let film_of = |width: u32, height: u32, passes: &[Vec<Vec3>]| {
        let mut film = Film::new(width, height).unwrap();
        for (k, values) in passes.iter().enumerate() {
            film.add_pass(&PassSamples { sample: k as u32, width, height, values: values.clone(), rays: 0 }).unwrap();
        }
        film
    };
    let (a, b) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 0.25, 4.0));
    let film = film_of(2, 1, &[vec![a, b], vec![b, a]]);
    assert_eq!(film, film_of(2, 1, &[vec![a, b], vec![b, a]]));
    // One component of one sample, one bit above: other sums.
    let nudged = Vec3::new(f32::from_bits(b.x.to_bits() + 1), b.y, b.z);
    assert_ne!(film, film_of(2, 1, &[vec![a, b], vec![nudged, a]]), "another sum");
    // The same values in a 1x2 film: equal sums, another size.
    assert_ne!(film, film_of(1, 2, &[vec![a, b], vec![b, a]]), "another size");
    // A third pass of zeros: equal sums and second moments, another sample count.
    assert_ne!(film, film_of(2, 1, &[vec![a, b], vec![b, a], vec![Vec3::ZERO; 2]]), "another count");
    // A zero that was a NaN: equal sums, another count of discarded samples.
    let (zeros, nans) = (film_of(2, 1, &[vec![Vec3::ZERO, a]]), film_of(2, 1, &[vec![Vec3::NAN, a]]));
    assert_eq!(zeros.moments().collect::<Vec<_>>(), nans.moments().collect::<Vec<_>>());
    assert_ne!(zeros, nans, "another discarded count");
}

/// A forged checkpoint can hold a film at the largest count: another pass is refused, and the film
/// is left whole, where the count wrapped to a film of no samples (a black image, then a
/// checkpoint that lumiere refused).
#[test]
fn a_film_at_the_largest_sample_count_refuses_another_pass() {
    let mut film = Film::new(WIDTH, HEIGHT).unwrap();
    film.add_pass(&pass(0)).unwrap();
    film.add_pass(&pass(1)).unwrap();
    film.samples = u32::MAX;
    let before = film.clone();
    let next = PassSamples { sample: u32::MAX, ..pass(2) };
    let error = film.add_pass(&next).unwrap_err().to_string();
    assert!(error.contains("cannot take another pass"), "{error}");
    assert_eq!(film, before);
}

/// A checkpoint stores sums and second moments whatever the film's form: it loads as an equal
/// film, which renders the same image and goes on the same way.
#[test]
fn checkpoints_of_every_form_resume_exactly() {
    let mut film = Film::new(WIDTH, HEIGHT).unwrap();
    for k in 0..4 {
        let checkpoint = Checkpoint {
            scene_fingerprint: 1,
            options_fingerprint: 2,
            seed: 3,
            options: String::new(),
            film: film.clone(),
            stats: RenderStats::default(),
        };
        let mut loaded = Checkpoint::decode(&checkpoint.encode().unwrap(), Path::new("film.ckpt")).unwrap().film;
        assert_eq!(loaded, film, "after {k} passes");
        assert_eq!(image_bits(&loaded), image_bits(&film), "after {k} passes");
        assert_eq!(loaded.relative_error().map(f64::to_bits), film.relative_error().map(f64::to_bits));
        film.add_pass(&pass(k)).unwrap();
        loaded.add_pass(&pass(k)).unwrap();
        assert_eq!(bits(loaded.moments()), bits(film.moments()), "resumed after {k} passes");
        assert_eq!(loaded.discarded, film.discarded);
    }
}

fn cornell() -> (World, Camera) {
    let world = World::new(Scene::builtin().unwrap(), Default::default());
    (world, Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 96, 72))
}

/// Passes are shaded straight into a buffer that becomes the film or is added to it once the pass
/// is complete: a pass stopped midway leaves no trace, whether it was the first or a later one.
/// It stops after the pass's first tile of 30, so that tiles not yet started see the stop.
#[test]
fn a_pass_stopped_midway_leaves_the_film_as_it_was() {
    let (world, camera) = cornell();
    let options = RenderOptions { spp: 4, ..RenderOptions::new(Technique::direct(2)) };
    let pixels = u64::from(camera.width * camera.height);
    for stop_after in [1, pixels + 1] {
        let cancel = AtomicBool::new(false);
        let shaded = AtomicU64::new(0);
        let progress = |n| {
            if shaded.fetch_add(n, Ordering::Relaxed) + n >= stop_after {
                cancel.store(true, Ordering::Relaxed);
            }
        };
        let hooks = Hooks { progress: &progress, pass_done: &mut |_, _| Ok(()), cancel: &cancel };
        let film = Film::new(camera.width, camera.height).unwrap();
        let stopped = render_progressive(&world, &camera, &options, film, RenderStats::default(), hooks).unwrap();
        let whole_passes = (stop_after / pixels) as u32;
        assert_eq!((stopped.stop, stopped.film.samples), (StopReason::Interrupted, whole_passes));
        let mut expected = Film::new(camera.width, camera.height).unwrap();
        let never = AtomicBool::new(false);
        for pass in render_pass_range(&world, &camera, &options, 0, whole_passes, &|_| {}, &never).unwrap() {
            expected.add_pass(&pass).unwrap();
        }
        assert_eq!(stopped.film, expected, "stopped after {stop_after} pixel samples");
        assert_eq!(stopped.image, expected.image());
    }
}

/// A stop that an integrator sees inside a tile's last block (here the only block: a 4x4 image, a
/// single tile) cuts that block's samples short, so the pass is not whole and must be dropped,
/// whether the stop is the time budget or a cancel. Each pixel asks for 2^30 ambient-occlusion
/// probes, seconds of work, so the stop always comes inside the block. The film was taking the
/// cut pass as whole: pixels of about 1e-7 where the image is about 0.2.
#[test]
fn a_stop_inside_a_tiles_last_block_drops_the_pass() {
    let world = World::new(Scene::builtin().unwrap(), Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 4, 4);
    let mut options = RenderOptions { spp: 2, ..RenderOptions::new(Technique::ambient_occlusion(1 << 30)) };
    options.time_budget = Some(std::time::Duration::from_millis(50));
    let never = AtomicBool::new(false);
    let hooks = Hooks { progress: &|_| {}, pass_done: &mut |_, _| Ok(()), cancel: &never };
    let film = Film::new(camera.width, camera.height).unwrap();
    let stopped = render_progressive(&world, &camera, &options, film, RenderStats::default(), hooks).unwrap();
    assert_eq!((stopped.stop, stopped.film.samples), (StopReason::TimeBudget, 0));

    options.time_budget = None;
    let cancel = AtomicBool::new(false);
    let stopped = std::thread::scope(|scope| {
        scope.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(50));
            cancel.store(true, Ordering::Relaxed);
        });
        let hooks = Hooks { progress: &|_| {}, pass_done: &mut |_, _| Ok(()), cancel: &cancel };
        let film = Film::new(camera.width, camera.height).unwrap();
        render_progressive(&world, &camera, &options, film, RenderStats::default(), hooks).unwrap()
    });
    assert_eq!((stopped.stop, stopped.film.samples), (StopReason::Interrupted, 0));
}

/// The noise estimate against its definition, written out plainly: the root mean square over
/// pixels of the standard error of each pixel's mean luminance (the unbiased sample variance over
/// n), divided by the image's mean luminance; none before two samples, 0 for a black image.
#[test]
fn the_relative_error_is_the_rms_standard_error_over_the_mean_luminance() {
    let grey = |k: u32, values: [f32; 2]| PassSamples {
        sample: k,
        width: 2,
        height: 1,
        values: values.map(Vec3::splat).to_vec(),
        rays: 0,
    };
    let passes = [[1.0, 2.0], [3.0, 2.0], [2.0, 5.0]];
    let mut film = Film::new(2, 1).unwrap();
    assert_eq!(film.relative_error(), None, "no sample");
    for (k, values) in passes.iter().enumerate() {
        film.add_pass(&grey(k as u32, *values)).unwrap();
        let samples = &passes[..=k];
        let n = samples.len() as f64;
        if n < 2.0 {
            assert_eq!(film.relative_error(), None, "one sample has no variance");
            continue;
        }
        let (mut variance_sum, mut mean_sum) = (0.0, 0.0);
        for pixel in 0..2 {
            let mean = samples.iter().map(|s| f64::from(s[pixel])).sum::<f64>() / n;
            let variance = samples.iter().map(|s| (f64::from(s[pixel]) - mean).powi(2)).sum::<f64>() / (n - 1.0);
            variance_sum += variance / n;
            mean_sum += mean;
        }
        let expected = (variance_sum / 2.0).sqrt() / (mean_sum / 2.0);
        let error = film.relative_error().unwrap();
        assert!((error - expected).abs() < 1e-6 * expected, "{} samples: {error} where {expected}", k + 1);
    }
    // By hand, for the first two: pixel 0 (1, 3) has variance of the mean 1, pixel 1 (2, 2) none.
    let mut two = Film::new(2, 1).unwrap();
    two.add_pass(&grey(0, passes[0])).unwrap();
    two.add_pass(&grey(1, passes[1])).unwrap();
    assert!((two.relative_error().unwrap() - 0.5f64.sqrt() / 2.0).abs() < 1e-6);
    let mut black = Film::new(2, 1).unwrap();
    black.add_pass(&grey(0, [0.0; 2])).unwrap();
    black.add_pass(&grey(1, [0.0; 2])).unwrap();
    assert_eq!(black.relative_error(), Some(0.0), "a black image has no relative error, not NaN");
}

/// A pass must match the film in its size and its number of values, both: a transposed pass (the
/// same count of values) or one short of a value is refused, and the film is left as it was.
#[test]
fn a_pass_of_another_shape_or_length_is_refused() {
    let mut film = Film::new(WIDTH, HEIGHT).unwrap();
    film.add_pass(&pass(0)).unwrap();
    let before = film.clone();
    let transposed = PassSamples { width: HEIGHT, height: WIDTH, ..pass(1) };
    let short = PassSamples { values: pass(1).values[1..].to_vec(), ..pass(1) };
    for bad in [transposed, short] {
        let error = film.add_pass(&bad).unwrap_err().to_string();
        assert!(error.contains("but the film is 5x3"), "{error}");
        assert_eq!(film, before);
    }
    film.add_pass(&pass(1)).unwrap();
}
