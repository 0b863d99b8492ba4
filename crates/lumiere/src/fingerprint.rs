//! Stable 64-bit fingerprints of a scene and of render options, stored in checkpoints so that a
//! render is never resumed with different inputs. Not cryptographic: it guards against mistakes.

use std::hash::Hasher;

use crate::render::RenderOptions;
use crate::scene::Scene;
use crate::scene::camera::Camera;

/// A word-at-a-time multiply-rotate hash; the same input gives the same value on every run and
/// platform (unlike `std`'s randomly keyed hashers).
pub struct StableHasher(u64);

impl Default for StableHasher {
    fn default() -> Self {
        StableHasher(0x243F_6A88_85A3_08D3)
    }
}

impl Hasher for StableHasher {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for chunk in &mut chunks {
            self.mix(u64::from_le_bytes(chunk.try_into().unwrap_or_default()));
        }
        let mut tail = [0u8; 8];
        tail[..chunks.remainder().len()].copy_from_slice(chunks.remainder());
        self.mix(u64::from_le_bytes(tail) ^ (bytes.len() as u64) << 56);
    }

    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 33)).wrapping_mul(0xFF51_AFD7_ED55_8CCD);
        z ^ (z >> 33)
    }
}

impl StableHasher {
    fn mix(&mut self, word: u64) {
        self.0 = (self.0 ^ word).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
    }

    fn write_f32s(&mut self, values: impl IntoIterator<Item = f32>) {
        for v in values {
            self.write_u32(v.to_bits());
        }
    }
}

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
        h.write_f32s([m.kd, m.ks, m.ke].iter().flat_map(|v| v.to_array()).chain([m.ns, m.ni, m.dissolve]));
    }
    h.finish()
}

/// Everything that decides a sample's value: mode, sample counts per camera sample, seed, sampler,
/// camera and image size. Not the target spp nor the budgets, which a resumed render may change.
pub fn options_fingerprint(options: &RenderOptions, camera: &Camera) -> u64 {
    let mut h = StableHasher::default();
    // Debug output of these plain records is exact (floats print in shortest round-trip form).
    let described = format!(
        "{:?} {} {} {:?} {:?} {} {camera:?}",
        options.mode,
        options.samples,
        options.seed,
        options.sampler,
        options.light_sampling,
        options.ao_distance.to_bits()
    );
    h.write(described.as_bytes());
    h.finish()
}
