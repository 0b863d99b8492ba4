//! Stable 64-bit fingerprints of a scene and of render options, stored in checkpoints so that a
//! render is never resumed with different inputs. Not cryptographic: it guards against mistakes.

use std::hash::Hasher;

use crate::render::RenderOptions;
use crate::scene::Scene;
use crate::scene::camera::Camera;
use crate::util::hash::StableHasher;

/// The geometry and materials a render sees (emission overrides included).
pub fn scene_fingerprint(scene: &Scene) -> u64 {
    let mut h = StableHasher::default();
    let mesh = &scene.mesh;
    h.write_f32s(mesh.positions.iter().flat_map(|p| p.to_array()));
    h.write_f32s(mesh.normals.iter().flat_map(|p| p.to_array()));
    h.write_f32s(mesh.texcoords.iter().flat_map(|p| p.to_array()));
    for indices in [&mesh.indices, &mesh.normal_indices, &mesh.texcoord_indices] {
        h.write_usize(indices.len());
        indices.iter().flatten().for_each(|&i| h.write_u32(i));
    }
    mesh.material_ids.iter().for_each(|&m| h.write_u32(m));
    for m in &scene.materials {
        h.write(m.name.as_bytes());
        h.write_f32s([m.kd, m.ks, m.ke, m.tf].iter().flat_map(|v| v.to_array()).chain([m.ns, m.ni, m.dissolve]));
        h.write_f32s([m.metallic, m.roughness].map(|v| v.unwrap_or(f32::NAN)));
        h.write_u32(m.illum);
        h.write(m.map_kd.as_deref().map_or(&b""[..], |p| p.as_os_str().as_encoded_bytes()));
        // Only where present, so that the fingerprints of scenes without cutouts (and their
        // checkpoints) stay what they were before `map_d` was read.
        if let Some(map_d) = &m.map_d {
            h.write(b"map_d");
            h.write(map_d.as_os_str().as_encoded_bytes());
        }
        // The same for the textures' placements, hashed only where they move a texture.
        for (key, transform) in [(&b"map_kd -s -o"[..], m.map_kd_transform), (&b"map_d -s -o"[..], m.map_d_transform)] {
            if !transform.is_identity() {
                h.write(key);
                h.write_f32s([transform.scale, transform.offset].iter().flat_map(|v| v.to_array()));
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

/// The fingerprint of [`options_description`].
pub fn options_fingerprint(options: &RenderOptions, camera: &Camera) -> u64 {
    crate::util::hash::hash_bytes(options_description(options, camera).as_bytes())
}
