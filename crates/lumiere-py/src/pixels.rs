//! Pixels across the boundary: `Vec3` buffers to and from native-endian float32 bytes, which the
//! Python side views as numpy arrays without another copy (`numpy.frombuffer`).

use glam::Vec3;
use pyo3::prelude::*;
use pyo3::types::PyByteArray;

use crate::errors::invalid;

/// A new `bytearray` holding `pixels` as float32 RGB triples, filled in place.
pub fn to_bytearray<'py>(py: Python<'py>, pixels: &[Vec3]) -> PyResult<Bound<'py, PyByteArray>> {
    PyByteArray::new_with(py, pixels.len() * 12, |bytes| {
        for (out, p) in bytes.chunks_exact_mut(12).zip(pixels) {
            out[0..4].copy_from_slice(&p.x.to_ne_bytes());
            out[4..8].copy_from_slice(&p.y.to_ne_bytes());
            out[8..12].copy_from_slice(&p.z.to_ne_bytes());
        }
        Ok(())
    })
}

/// float32 RGB triples back to `Vec3`s, refusing a length that is not `count` pixels.
pub fn from_bytes(bytes: &[u8], count: usize, what: &str) -> PyResult<Vec<Vec3>> {
    if bytes.len() != count * 12 {
        return Err(invalid(format!("{what}: {} bytes, expected {count} float32 RGB values", bytes.len())));
    }
    // Reserved fallibly: an image too large for the memory left is an exception, not an abort.
    let mut pixels = Vec::new();
    pixels.try_reserve_exact(count).map_err(|_| invalid(format!("{what}: out of memory for {count} pixels")))?;
    let float = |b: &[u8]| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
    pixels.extend(bytes.chunks_exact(12).map(|c| Vec3::new(float(&c[0..4]), float(&c[4..8]), float(&c[8..12]))));
    Ok(pixels)
}
