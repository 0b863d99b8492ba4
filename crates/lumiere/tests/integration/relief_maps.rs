//! Bump and normal maps from MTL files, through the world's surface points: a height ramp tilts
//! the normal by its slope in scene units (times `-bm`, through the placement's scale, along `u`
//! and `v`), a bump map with a normal map's colours reads as one, and every relief seen from
//! behind shows the opposite of its front's normal.

use crate::common::TempDir;
use glam::Vec3;
use image::{ImageFormat, Rgb, RgbImage};
use lumiere::math::Ray;
use lumiere::scene::Scene;
use lumiere::world::World;

/// A ramp of 16 texels whose stored values rise by 17 a texel (0 to 255): between texel centres
/// the filtered height rises by 1/15 a texel, 16/15 over the texture's width. `along_v` lays it
/// out as a column (rows from the top, so the height falls as `v` rises); `rgb` makes a texel's
/// colour from its code.
fn ramp(along_v: bool, rgb: impl Fn(u8) -> [u8; 3]) -> RgbImage {
    let (width, height) = if along_v { (1, 16) } else { (16, 1) };
    RgbImage::from_fn(width, height, |x, y| Rgb(rgb(17 * (x + y) as u8)))
}

/// One unit quad per material in the z = 0 plane, facing +z, material `k` over `x` in
/// `[2k, 2k + 1]`, with texture coordinates `(x - 2k, y)` and no normals.
fn quads(materials: &[&str]) -> String {
    let mut obj = "mtllib m.mtl\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n".to_string();
    for (k, name) in materials.iter().enumerate() {
        let x = 2.0 * k as f32;
        obj += &format!("v {x} 0 0\nv {} 0 0\nv {} 1 0\nv {x} 1 0\n", x + 1.0, x + 1.0);
        let first = 4 * k + 1;
        let [a, b, c, d] = [first, first + 1, first + 2, first + 3];
        obj += &format!("usemtl {name}\nf {a}/1 {b}/2 {c}/3\nf {a}/1 {c}/3 {d}/4\n");
    }
    obj
}

/// The shading normal at `(x, y)` on the quads, seen from above (`z = 1`) or from below; the
/// rows a packet shades from must agree with the single point.
fn normal_at(world: &World, x: f32, y: f32, above: bool) -> Vec3 {
    let z = if above { 1.0 } else { -1.0 };
    let ray = Ray::new(Vec3::new(x, y, z), Vec3::new(0.0, 0.0, -z));
    let hits = [world.intersect(&ray), None];
    let surface = world.surface(&ray, &hits[0].expect("the quad is hit"));
    assert_eq!(world.surfaces(&[ray, ray], &hits)[0].ns, surface.ns, "the rows' normal at ({x}, {y})");
    surface.ns
}

#[test]
fn height_maps_tilt_the_normal_by_their_slope_and_normal_coloured_ones_read_as_directions() {
    let dir = TempDir::new("relief-maps");
    let grey = |code| [code; 3];
    ramp(false, grey).save_with_format(dir.path("ramp.png"), ImageFormat::Png).unwrap();
    ramp(true, grey).save_with_format(dir.path("column.png"), ImageFormat::Png).unwrap();
    // The red channel rises while the luminance falls: only `-imfchan r` reads the ramp.
    ramp(false, |code| [code, 255 - code, 0]).save_with_format(dir.path("red.png"), ImageFormat::Png).unwrap();
    // Bright grey: its blue is never below one half, but it is no bluer than its red and green.
    RgbImage::from_pixel(4, 4, Rgb([200; 3])).save_with_format(dir.path("flat.png"), ImageFormat::Png).unwrap();
    let texel = [204u8, 100, 230];
    RgbImage::from_pixel(1, 1, Rgb(texel)).save_with_format(dir.path("normal.png"), ImageFormat::Png).unwrap();
    let materials = [
        ("ramp", "map_Bump ramp.png"),
        ("gentle", "bump -bm 0.25 ramp.png"),
        ("tiled", "map_bump -s 2 1 ramp.png"),
        ("column", "bump column.png"),
        ("red", "bump -imfchan r red.png"),
        ("flat", "bump -bm 5 flat.png"),
        ("coloured", "map_Bump normal.png"),
        ("norm", "norm normal.png"),
        ("half", "norm -bm 0.5 normal.png"),
    ];
    let mtl: String = materials.iter().map(|(name, map)| format!("newmtl {name}\nKd 1 1 1\n{map}\n")).collect();
    dir.write("m.mtl", mtl);
    let names = materials.map(|(name, _)| name);
    let scene = Scene::load(&dir.write("s.obj", quads(&names))).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let world = World::new(scene, Default::default());
    assert!(world.warnings().is_empty(), "{:?}", world.warnings());
    // The quads' texture axes are unit vectors along x and y: a slope `s` of the height in u tilts
    // the normal to (-s, 0, 1), one in v to (0, -s, 1).
    let slope = 16.0 / 15.0;
    let c = Vec3::from(texel.map(|code| f32::from(code) / 255.0 * 2.0 - 1.0));
    let expected = [
        Vec3::new(-slope, 0.0, 1.0),
        Vec3::new(-0.25 * slope, 0.0, 1.0),
        Vec3::new(-2.0 * slope, 0.0, 1.0),
        Vec3::new(0.0, slope, 1.0),
        Vec3::new(-slope, 0.0, 1.0),
        Vec3::Z,
        c,
        c,
        Vec3::new(0.5 * c.x, 0.5 * c.y, c.z),
    ]
    .map(Vec3::normalize);
    for (k, expected) in expected.into_iter().enumerate() {
        // Inside the ramps (their slope is the texels' there) and away from the texture's wrap.
        for (u, v) in [(0.3, 0.4), (0.45, 0.6)] {
            let x = 2.0 * k as f32 + u;
            let above = normal_at(&world, x, v, true);
            assert!((above - expected).abs().max_element() < 1e-4, "{}: {above} vs {expected}", names[k]);
            // From below the surface shows the opposite of its front's normal.
            let below = normal_at(&world, x, v, false);
            assert!((below + expected).abs().max_element() < 1e-4, "{} from below: {below}", names[k]);
        }
    }
}

/// A normal map whose direction would face away from the geometric normal keeps the interpolated
/// normal (no light leaks through the surface), and a bump map that cannot be decoded costs one
/// warning and leaves the surface its normals.
#[test]
fn facing_away_normal_maps_and_unusable_bump_maps_leave_the_interpolated_normal() {
    let dir = TempDir::new("relief-maps-steep");
    ramp(false, |code| [code; 3]).save_with_format(dir.path("ramp.png"), ImageFormat::Png).unwrap();
    dir.write("broken.png", "\u{89}PNG not an image");
    // A normal map whose one texel points below the surface.
    RgbImage::from_pixel(1, 1, Rgb([255, 128, 0])).save_with_format(dir.path("below.png"), ImageFormat::Png).unwrap();
    dir.write("m.mtl", "newmtl broken\nmap_Bump broken.png\nnewmtl below\nnorm below.png\n");
    let scene = Scene::load(&dir.write("s.obj", quads(&["broken", "below"]))).unwrap();
    let world = World::new(scene, Default::default());
    assert_eq!(world.warnings().len(), 1, "{:?}", world.warnings());
    assert!(world.warnings()[0].ends_with("the surface keeps its interpolated normals"), "{:?}", world.warnings());
    for k in 0..2 {
        let x = 2.0 * k as f32 + 0.3;
        assert_eq!(normal_at(&world, x, 0.5, true), Vec3::Z);
        assert_eq!(normal_at(&world, x, 0.5, false), -Vec3::Z);
    }
}
