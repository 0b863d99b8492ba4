//! Writing images with the CLI's writers (`.png` tone mapped and sRGB-encoded, `.exr` and `.pfm`
//! linear), atomically, so a file written from Python has the bytes `lumiere render -o` writes.

use std::path::PathBuf;

use lumiere::image_io::{PngEncoding, PngStyle, Tonemap, write_image as write};
use pyo3::prelude::*;

use crate::errors::{OrPyErr, invalid};
use crate::pixels::from_bytes;

/// Writes float32 RGB `pixels` (row 0 at the top) to `path`; the extension picks the format.
#[pyfunction]
#[pyo3(signature = (path, width, height, pixels, exposure=0.0, tonemap="aces"))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    width: u32,
    height: u32,
    pixels: &[u8],
    exposure: f32,
    tonemap: &str,
) -> PyResult<()> {
    if !exposure.is_finite() {
        return Err(invalid(format!("exposure must be a finite number of stops, got {exposure}")));
    }
    let tonemap = match tonemap {
        "aces" => Tonemap::Aces,
        "clamp" => Tonemap::Clamp,
        other => return Err(invalid(format!("unknown tonemap {other:?}: choose aces or clamp"))),
    };
    let pixels = from_bytes(pixels, width as usize * height as usize, "image")?;
    let style = PngStyle { encoding: PngEncoding::Srgb, exposure, tonemap };
    py.detach(|| write(&path, width, height, &pixels, style)).or_py()
}
