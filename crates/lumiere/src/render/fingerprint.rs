//! Stable 64-bit fingerprints of a scene and of render options, stored in checkpoints so that a
//! render is never resumed with different inputs, and the reasons a checkpoint cannot be resumed
//! ([`Fingerprints::mismatch`]), which the CLI and the Python module word. Not cryptographic: it
//! guards against mistakes.

use std::hash::Hasher;

use crate::materials::{CoverageTest, Cut, Relief};
use crate::render::checkpoint::{Checkpoint, differing_options};
use crate::render::film::Film;
use crate::render::{RenderOptions, RenderStats};
use crate::scene::camera::Camera;
use crate::util::hash::{StableHasher, hash_bytes};
use crate::world::World;

/// The geometry, materials and textures a render sees (emission overrides included).
pub fn scene_fingerprint(world: &World) -> u64 {
    let mut h = StableHasher::default();
    let scene = world.scene();
    let mesh = &scene.mesh;
    h.write_f32s(mesh.positions.iter().flat_map(|p| p.to_array()));
    h.write_f32s(mesh.normals.iter().flat_map(|p| p.to_array()));
    h.write_f32s(mesh.texcoords.iter().flat_map(|p| p.to_array()));
    for indices in [&mesh.indices, &mesh.normal_indices, &mesh.texcoord_indices] {
        h.write_usize(indices.len());
        indices.iter().flatten().for_each(|&i| h.write_u32(i));
    }
    mesh.material_ids.iter().for_each(|&m| h.write_u32(m));
    for (index, m) in scene.materials.iter().enumerate() {
        h.write(m.name.as_bytes());
        h.write_f32s([m.kd, m.ks, m.ke, m.tf].iter().flat_map(|v| v.to_array()).chain([m.ns, m.ni, m.dissolve]));
        h.write_f32s([m.metallic, m.roughness].map(|v| v.unwrap_or(f32::NAN)));
        h.write_u32(m.illum);
        h.write(m.map_kd.as_deref().map_or(&b""[..], |p| p.as_os_str().as_encoded_bytes()));
        // Only where it tints the texture, so that the fingerprints of MTL scenes stay.
        if m.map_kd_factor != glam::Vec3::ONE {
            h.write(b"map_kd factor");
            h.write_f32s(m.map_kd_factor.to_array());
        }
        // Only where present, so that the fingerprints of scenes without cutouts (and their
        // checkpoints) stay what they were before `map_d` was read.
        if let Some(map_d) = &m.map_d {
            h.write(b"map_d");
            h.write(map_d.as_os_str().as_encoded_bytes());
        }
        // The same for the coverage test: MTL's adds nothing.
        let test = m.map_d_test;
        if test != CoverageTest::MTL {
            h.write(b"map_d test");
            h.write_u8(u8::from(test.alpha_only));
            let threshold = match test.cut {
                Cut::Below(threshold) => threshold,
                Cut::Hashed => f32::NAN,
            };
            h.write_f32s([test.scale, threshold]);
        }
        // The same for the parameter maps: their files, channels, factors and placements.
        for (key, map) in [(&b"map_Pm"[..], &m.map_pm), (&b"map_Pr"[..], &m.map_pr)] {
            if let Some(map) = map {
                h.write(key);
                h.write(map.path.as_os_str().as_encoded_bytes());
                h.write_u8(map.channel as u8);
                h.write_f32s([map.transform.scale, map.transform.offset].iter().flat_map(|v| v.to_array()));
                h.write_f32s([map.scale]);
            }
        }
        if let Some(map) = &m.normal_map {
            h.write(b"normal map");
            h.write(map.path.as_os_str().as_encoded_bytes());
            h.write_f32s([map.transform.scale, map.transform.offset].iter().flat_map(|v| v.to_array()));
            h.write_f32s([map.scale]);
            // Directions add nothing: the fingerprints of scenes with normal maps stay what they were.
            if let Relief::Heights { channel } = map.relief {
                h.write(b"heights");
                h.write_u8(channel as u8);
            }
        }
        // The same for the textures' placements, hashed only where they move a texture.
        for (key, transform) in [(&b"map_kd -s -o"[..], m.map_kd_transform), (&b"map_d -s -o"[..], m.map_d_transform)] {
            if !transform.is_identity() {
                h.write(key);
                h.write_f32s([transform.scale, transform.offset].iter().flat_map(|v| v.to_array()));
            }
        }
        // And the bytes of the files the textures were decoded from: a file edited (or made
        // usable) between two sessions of a render changes its image. Only where a texture is
        // named, so that the fingerprints of scenes without one stay what they were.
        let [map_kd, map_d, map_pm, map_pr, normals] = world.texture_contents(index);
        for (key, named, contents) in [
            (&b"map_kd file"[..], m.map_kd.is_some(), map_kd),
            (&b"map_d file"[..], m.map_d.is_some(), map_d),
            (&b"map_Pm file"[..], m.map_pm.is_some(), map_pm),
            (&b"map_Pr file"[..], m.map_pr.is_some(), map_pr),
            (&b"normal map file"[..], m.normal_map.is_some(), normals),
        ] {
            if named {
                h.write(key);
                h.write_u8(u8::from(contents.is_some()));
                h.write_u64(contents.unwrap_or(0));
            }
        }
    }
    h.finish()
}

/// Everything that decides a sample's value, as readable `key: value` lines: the technique and its
/// options, seed, sampler, pixel sampling, camera and image size. Not the target spp nor the
/// budgets, which a resumed render may change. Checkpoints store it, so that a refused resume can
/// name what differs.
pub fn options_description(options: &RenderOptions, camera: &Camera) -> String {
    // Debug output of these plain records is exact (floats print in shortest round-trip form).
    let pixels = if options.samples_pixel_centres() { "centres (--spp 1)" } else { "jittered (--spp above 1)" };
    // The image size has a line of its own, so that a refusal can name it readably: the camera's
    // line (its matrices) is too long to quote (see `differing_options`).
    format!(
        "technique: {:?}\nseed: {}\nsampler: {:?}\npixel positions: {pixels}\nimage size: {}x{}\ncamera: {camera:?}\n",
        options.technique, options.seed, options.sampler, camera.width, camera.height
    )
}

/// What a checkpoint must match to be resumed by a render: its scene, the options that decide
/// sample values (seed included, kept as readable text so that a refusal can name what differs),
/// and the image size.
#[derive(Clone, Debug)]
pub struct Fingerprints {
    scene: u64,
    options: String,
    seed: u64,
    image: (u32, u32),
}

/// Why a checkpoint cannot be resumed: each front end words it, with its own names for options.
#[derive(Clone, Debug, PartialEq)]
pub enum Mismatch {
    /// Another scene: its geometry, materials, textures or emission differ.
    Scene,
    /// Other options: the lines of [`differing_options`] that differ.
    Options(Vec<String>),
    /// A film of another size than the image (one saved from Python's film API can be).
    FilmSize { film: (u32, u32), image: (u32, u32) },
}

impl Fingerprints {
    /// `scene` is the world's [`scene_fingerprint`] (a front end that keeps a world keeps it too).
    pub fn new(scene: u64, options: &RenderOptions, camera: &Camera) -> Fingerprints {
        Fingerprints {
            scene,
            options: options_description(options, camera),
            seed: options.seed,
            image: (camera.width, camera.height),
        }
    }

    /// The checkpoint of `film` and `stats`, rendered with these fingerprints.
    pub fn checkpoint(&self, film: Film, stats: RenderStats) -> Checkpoint {
        Checkpoint {
            scene_fingerprint: self.scene,
            options_fingerprint: hash_bytes(self.options.as_bytes()),
            seed: self.seed,
            options: self.options.clone(),
            film,
            stats,
        }
    }

    /// Why `checkpoint` cannot be resumed with these fingerprints, if it cannot.
    pub fn mismatch(&self, checkpoint: &Checkpoint) -> Option<Mismatch> {
        let film = (checkpoint.film.width, checkpoint.film.height);
        if checkpoint.scene_fingerprint != self.scene {
            Some(Mismatch::Scene)
        } else if checkpoint.options_fingerprint != hash_bytes(self.options.as_bytes()) || checkpoint.seed != self.seed
        {
            let mut differing = differing_options(&checkpoint.options, &self.options);
            // The same text under another fingerprint or seed: the file's fields disagree with
            // its own options (an altered file), which the refusal must still name.
            if differing.is_empty() {
                differing.push("its seed or options fingerprint, which disagree with its options text".to_string());
            }
            Some(Mismatch::Options(differing))
        } else if film != self.image {
            // Its options name the image size, but its film is written apart.
            Some(Mismatch::FilmSize { film, image: self.image })
        } else {
            None
        }
    }
}
