//! The one family of hashes lumiere uses: a 64-bit finaliser that the samplers build their numbers
//! from, and a stable streaming hasher for fingerprints and checksums. Both give the same value on
//! every run and platform (unlike `std`'s randomly keyed hashers). Not cryptographic.

use std::hash::Hasher;

/// The murmur3 64-bit finaliser: every input bit affects every output bit with probability ~1/2.
#[inline]
pub fn mix64(mut h: u64) -> u64 {
    h ^= h >> 33;
    h = h.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    h ^= h >> 33;
    h = h.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    h ^ (h >> 33)
}

/// A word-at-a-time multiply-rotate hash of a byte stream, for fingerprints of scenes and options
/// and for checkpoint checksums. Its values are stored in checkpoint files: changing it makes every
/// existing checkpoint unreadable.
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

    /// Hashes floats by their bits, so that `-0.0` and `0.0` (or two NaNs) differ as the bytes do.
    pub fn write_f32s(&mut self, values: impl IntoIterator<Item = f32>) {
        for v in values {
            self.write_u32(v.to_bits());
        }
    }
}

/// The stable hash of a byte string.
pub fn hash_bytes(bytes: &[u8]) -> u64 {
    let mut h = StableHasher::default();
    h.write(bytes);
    h.finish()
}
