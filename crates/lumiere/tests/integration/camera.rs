//! gKit's camera reproduced to the published numbers, and the look-at pinhole's conventions.

use std::path::Path;

use glam::{DVec3, Vec3};
use lumiere::math::Aabb;
use lumiere::scene::camera::{Camera, Orbiter, framing};

fn orbiter_2022() -> Orbiter {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cornell/cornell_orbiter.txt"));
    Orbiter::load(path).expect("the shipped orbiter file parses")
}

fn assert_close(actual: DVec3, expected: [f64; 3], tolerance: f64) {
    let expected = DVec3::from_array(expected);
    assert!((actual - expected).abs().max_element() < tolerance, "got {actual:?}, expected {expected:?}");
}

#[test]
fn gkit_2022_pixel_0_0_matches_the_published_endpoints() {
    let camera = Camera::from_orbiter(&orbiter_2022(), 1024, 768);
    let (origin, extremity) = camera.gkit_ray_endpoints(0.5, 0.5).expect("an orbiter camera");
    assert_close(origin, [-0.561618, 1.428429, 2.241525], 2e-6);
    assert_close(extremity, [-2.434118, -2.905999, -3.579812], 2e-6);
}

#[test]
fn film_row_zero_is_gkit_top_row() {
    let camera = Camera::from_orbiter(&orbiter_2022(), 1024, 768);
    // Film pixel (0, 767) (bottom-left) is gKit's pixel (0, 0).
    let ray = camera.ray(0.5, 767.5);
    let (origin, extremity) = camera.gkit_ray_endpoints(0.5, 0.5).unwrap();
    assert!((ray.origin.as_dvec3() - origin).length() < 1e-5);
    let expected_dir = (extremity - origin).normalize();
    assert!((ray.dir.as_dvec3() - expected_dir).length() < 1e-5);
}

#[test]
fn orbiter_parse_reads_all_fields_and_rejects_garbage() {
    let o = orbiter_2022();
    assert_eq!(o.rotation.x, 18.0);
    assert_eq!(o.rotation.y, 16.0);
    assert_eq!(o.frame, Some((45.0, 1024.0, 640.0)));
    let path = Path::new("cam.txt");
    let err = Orbiter::parse(b"c 0 0 0\np 0 zero\n", path).unwrap_err().to_string();
    assert!(err.contains("cam.txt:2"), "{err}");
    let err = Orbiter::parse(b"c 0 0 0\np 0 0\nr 0 0\n", path).unwrap_err().to_string();
    assert!(err.contains("missing 's'"), "{err}");
    let err = Orbiter::parse(b"c 0 0 nan\n", path).unwrap_err().to_string();
    assert!(err.contains("cam.txt:1"), "{err}");
    // Tokens from the file are quoted escaped and cut: a terminal's escape sequence cannot act, and
    // a five-megabyte number does not make a five-megabyte message.
    let err = Orbiter::parse(b"c 0 0 0\n\x1b[31mzoom 1\n", path).unwrap_err().to_string();
    assert_eq!(err, "cam.txt:2: unknown orbiter field \"\\u{1b}[31mzoom\" (expected c, p, r, s or f)");
    let huge = format!("c 0 0 {}x\n", "9".repeat(5_000_000));
    let err = Orbiter::parse(huge.as_bytes(), path).unwrap_err().to_string();
    assert!(err.starts_with("cam.txt:1: 'c' expects finite numbers, found \"999") && err.len() < 200, "{err:.300}");
    // A missing line is reported at the file's last line, whether or not a newline ends it.
    for text in [&b"c 0 0 0\np 0 0\nr 0 0\n"[..], b"c 0 0 0\np 0 0\nr 0 0"] {
        let err = Orbiter::parse(text, path).unwrap_err().to_string();
        assert_eq!(err, "cam.txt:3: missing 's' line");
    }
}

#[test]
fn look_at_centre_ray_points_at_target_and_row_zero_is_up() {
    let camera = Camera::look_at(Vec3::new(0.0, 1.0, 3.9), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 45.0, 200, 100).unwrap();
    let centre = camera.ray(100.0, 50.0);
    assert!((centre.dir - Vec3::NEG_Z).length() < 1e-6);
    let top = camera.ray(100.0, 0.0);
    assert!((top.dir.angle_between(Vec3::NEG_Z).to_degrees() - 22.5).abs() < 1e-3);
    assert!(top.dir.y > 0.0, "row 0 is the top of the picture");
    let right = camera.ray(200.0, 50.0);
    assert!(right.dir.x > 0.0, "the last column is on the right");
}

#[test]
fn look_at_rejects_degenerate_frames() {
    assert!(Camera::look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 45.0, 10, 10).is_err());
    assert!(Camera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y, 45.0, 10, 10).is_err());
    assert!(Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 180.0, 10, 10).is_err());
    // A point that is not finite is named as such, not as a difference that overflows.
    let nan = Vec3::new(f32::NAN, 0.0, 0.0);
    for (eye, target) in [(nan, Vec3::ZERO), (Vec3::ZERO, Vec3::splat(f32::INFINITY))] {
        let message = Camera::look_at(eye, target, Vec3::Y, 45.0, 10, 10).unwrap_err().to_string();
        assert!(message.ends_with("must be finite"), "{message}");
    }
    let message = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::splat(f32::NAN), 45.0, 10, 10).unwrap_err().to_string();
    assert!(message.ends_with("must be finite"), "{message}");
    // A long but finite up vector is an up vector, not "parallel" because its cross product overflowed.
    let long_up = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::splat(1e38), 45.0, 10, 10).expect("a camera");
    let unit_up = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::ONE, 45.0, 10, 10).unwrap();
    assert!(long_up.ray(0.0, 0.0).dir.abs_diff_eq(unit_up.ray(0.0, 0.0).dir, 1e-6));
}

/// Many rays at once are the rays one at a time, bit for bit, for both projections: film corners,
/// pixel centres, jittered positions and positions off the film.
#[test]
fn rays_at_once_are_the_rays_one_at_a_time() {
    let gkit = Camera::from_orbiter(&orbiter_2022(), 1024, 768);
    let pinhole = Camera::look_at(Vec3::new(0.3, 1.0, 3.9), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 45.0, 640, 480)
        .expect("a valid look-at camera");
    let mut state = 0x9e37_79b9_u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    for camera in [&gkit, &pinhole] {
        let (w, h) = (camera.width as f32, camera.height as f32);
        for round in 0..64 {
            let (xs, ys): ([f32; 16], [f32; 16]) = match round {
                0 => (
                    [0.0, w, 0.0, w, 0.5, w - 0.5, 0.5, w - 0.5, w / 2.0, -1.0, w + 1.0, 0.25, 1e-3, 7.5, 3.0, 9.0],
                    [0.0, 0.0, h, h, 0.5, 0.5, h - 0.5, h - 0.5, h / 2.0, -1.0, h + 1.0, 0.75, 1e-3, 2.5, 5.0, 1.0],
                ),
                _ => (std::array::from_fn(|_| next() * w), std::array::from_fn(|_| next() * h)),
            };
            let rays = camera.rays(&xs, &ys);
            for lane in 0..16 {
                let one = camera.ray(xs[lane], ys[lane]);
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                assert_eq!(bits(rays[lane].origin), bits(one.origin), "({}, {})", xs[lane], ys[lane]);
                assert_eq!(bits(rays[lane].dir), bits(one.dir), "({}, {})", xs[lane], ys[lane]);
                assert_eq!(rays[lane].tmax.to_bits(), one.tmax.to_bits());
            }
        }
    }
}

/// The look-at pinhole's horizontal field follows the picture's shape: at 2:1 with a vertical
/// field of 45°, the film's right edge is `2 tan 22.5°` across at unit distance and its top
/// `tan 22.5°` up, so the rays through the middle of the right edge and the top-right corner
/// point along `(2t, 0, −1)` and `(2t, t, −1)`, `t = tan 22.5°`. (The centre and the top are the
/// same for any aspect, and the rays test compares `rays` with `ray`, not with a closed form.)
#[test]
fn a_look_at_cameras_horizontal_field_follows_the_aspect_ratio() {
    let camera = Camera::look_at(Vec3::new(0.0, 1.0, 3.9), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 45.0, 200, 100).unwrap();
    let t = 22.5f32.to_radians().tan();
    for ((x, y), expected) in
        [((200.0, 50.0), Vec3::new(2.0 * t, 0.0, -1.0)), ((200.0, 0.0), Vec3::new(2.0 * t, t, -1.0))]
    {
        let ray = camera.ray(x, y);
        assert!(
            (ray.dir - expected.normalize()).length() < 1e-6,
            "({x}, {y}): {} vs {}",
            ray.dir,
            expected.normalize()
        );
        assert_eq!(ray.origin, Vec3::new(0.0, 1.0, 3.9));
    }
}

/// `framing` backs away along +z until the bounds' bounding sphere fills the vertical field of
/// view: the sphere of radius `r` is tangent to the field's edges at the distance `r / sin(fov/2)`
/// from its centre. Bounds `(−1, 0, 2)..(3, 2, 6)`: centre `(1, 1, 4)`, diagonal 6, `r = 3`; at 60°
/// the distance is `3 / sin 30° = 6`.
#[test]
fn framing_fits_the_bounding_sphere_into_the_field_of_view() {
    let bounds = Aabb::from_points(&[Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 2.0, 6.0)]);
    let (eye, target) = framing(&bounds, 60.0).expect("frames");
    assert_eq!(target, Vec3::new(1.0, 1.0, 4.0));
    assert!((eye - Vec3::new(1.0, 1.0, 10.0)).length() < 1e-5, "eye {eye}");
    // A single point has no radius: the eye stands just above it.
    let (eye, target) = framing(&Aabb::from_points(&[Vec3::new(1.0, 2.0, 3.0)]), 45.0).expect("frames a point");
    assert!(eye.z > target.z && eye.z - target.z < 2e-6 && eye.truncate() == target.truncate(), "{eye} {target}");
}

/// What `framing` refuses, each for its documented reason, and where the limits lie: an empty
/// box; fields of view outside (0, 180); a field so narrow that the eye would stand more than
/// 65536 radii away (1e-3° puts it at ~115000 radii, 2e-3° at ~57300: accepted); bounds whose
/// eye or radius overflows `f32`, or so far from the origin that the eye rounds onto the target.
#[test]
fn framing_refuses_what_it_cannot_frame_and_says_why() {
    let bounds = Aabb::from_points(&[Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 2.0, 6.0)]);
    assert_eq!(framing(&Aabb::EMPTY, 60.0), Err("no vertices to frame".to_string()));
    for fov in [0.0, -5.0, 180.0, 200.0, f32::NAN] {
        let message = framing(&bounds, fov).unwrap_err();
        assert!(message.contains("must be in (0, 180) degrees"), "fov {fov}: {message}");
    }
    assert!(framing(&bounds, 1e-3).unwrap_err().contains("too narrow"));
    assert!(framing(&bounds, 2e-3).is_ok());
    let too_large = [
        // A radius that overflows (the diagonal is beyond f32::MAX).
        Aabb::from_points(&[Vec3::splat(-3e38), Vec3::splat(3e38)]),
        // A finite radius, target and distance (2.9e38 at 20°), but the eye beyond f32::MAX.
        Aabb::from_points(&[Vec3::new(0.0, 0.0, 1e38), Vec3::new(0.0, 0.0, 2e38)]),
        // A point far from the origin: 1e-6 above it rounds back onto it.
        Aabb::from_points(&[Vec3::splat(1e8)]),
    ];
    for bounds in too_large {
        let message = framing(&bounds, 20.0).unwrap_err();
        assert!(message.contains("too large"), "{bounds:?}: {message}");
    }
}

/// An orbiter whose numbers are finite but whose camera casts no finite ray is refused at its `s`
/// line: a radius of 1e39 puts the far plane 1e40 times beyond the near one, and huge numbers
/// overflow the matrices (the fuzz corpus's `huge-radius.txt` and `huge-finite.txt`).
#[test]
fn orbiters_whose_rays_are_not_finite_are_refused() {
    let path = Path::new("cam.txt");
    let huge_radius = b"c -0.01 0.995 -0.025\np 0.149664 -0.266665\nr 18 16\ns 2.450631 1e39\n";
    let huge =
        b"c 1e308 -1e308 1e308\np 1e308 1e308\nr 1e308 -1e308\ns 1.7976931348623157e308 1.7976931348623157e308\n";
    for text in [&huge_radius[..], huge] {
        let message = Orbiter::parse(text, path).unwrap_err().to_string();
        assert!(message.starts_with("cam.txt:4: the camera's rays are not finite"), "{message}");
    }
}
