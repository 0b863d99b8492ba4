//! Writing images with the CLI's writers (`.png` tone mapped and sRGB-encoded, `.exr` and `.pfm`
//! linear), atomically, so a file written from Python has the bytes `lumiere render -o` writes;
//! and the checks of an output that a long render (`lumiere.distributed`) makes before it starts.

use std::path::PathBuf;

use lumiere::image_io::{
    ExrLayer, NOISY_LAYER, PngEncoding, PngStyle, RGB_CHANNELS, Tonemap, check_output_path, encode_image,
    write_exr_with_layers,
};
use lumiere::render::checkpoint::Checkpoint;
use lumiere::util::write::{check_writable, write_atomically};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::errors::{OrPyErr, invalid};
use crate::files;
use crate::pixels::from_bytes;
use crate::{pools, watch};

/// Writes float32 RGB `pixels` (row 0 at the top) to `path`; the extension picks the format.
/// AOVs, `(name, float32 RGB bytes)`, become the EXR's extra channels, as `lumiere render --aov`
/// writes them (and `noisy`, as `--denoise` does).
#[pyfunction]
#[pyo3(signature = (path, width, height, pixels, exposure=0.0, tonemap="aces", aovs=Vec::new()))]
#[expect(clippy::too_many_arguments, reason = "Python's arguments, one each")]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    width: u32,
    height: u32,
    pixels: &[u8],
    exposure: f32,
    tonemap: &str,
    aovs: Vec<(String, Bound<'_, PyBytes>)>,
) -> PyResult<()> {
    let style = png_style(exposure, tonemap)?;
    let count = width as usize * height as usize;
    let pixels = from_bytes(pixels, count, "image")?;
    if !aovs.is_empty() {
        let channels = aovs.iter().map(|(name, _)| layer_channels(name)).collect::<PyResult<Vec<_>>>()?;
        let buffers =
            aovs.iter().map(|(name, bytes)| from_bytes(bytes.as_bytes(), count, name)).collect::<PyResult<Vec<_>>>()?;
        let layers: Vec<ExrLayer> = aovs
            .iter()
            .zip(channels)
            .zip(&buffers)
            .map(|(((name, _), channels), pixels)| ExrLayer { name, channels, pixels })
            .collect();
        return py
            .detach(|| {
                files::tidy_beside(&path);
                write_exr_with_layers(&path, width, height, &pixels, &layers)
            })
            .or_py();
    }
    let pool = pools::for_background(py)?;
    // Encoding a large image takes seconds: Ctrl-C gives it up, as it gives up a load, and the
    // file stays as it was (the encoding ends in the background, its bytes dropped).
    let target = path.clone();
    let bytes = watch::abandonable(py, "an image's encoding", move || {
        pool.install(|| encode_image(&target, width, height, &pixels, style))
    })?
    .or_py()?;
    py.detach(|| {
        files::tidy_beside(&path);
        write_atomically(&path, &bytes)
    })
    .or_py()
}

/// The EXR channels of the layer `name`: an AOV's, or RGB for `noisy`, the image before
/// denoising that `lumiere render --denoise` keeps beside the denoised one.
fn layer_channels(name: &str) -> PyResult<&'static [&'static str]> {
    if name == NOISY_LAYER {
        return Ok(RGB_CHANNELS);
    }
    Ok(crate::aovs::parse(&[name.to_string()])?[0].exr_channels())
}

/// Refuses, before a long render, an image output that [`write_image`] would refuse after it: a
/// format it does not write, a folder that is missing or not writable, an exposure out of range
/// or an unknown tone mapping.
#[pyfunction]
#[pyo3(signature = (path, exposure=0.0, tonemap="aces"))]
pub fn check_image_output(path: PathBuf, exposure: f32, tonemap: &str) -> PyResult<()> {
    png_style(exposure, tonemap)?;
    check_output_path(&path).or_py()
}

/// Refuses, before a long render, a checkpoint that could not be written at `path`, or that
/// would replace a file other than a checkpoint.
#[pyfunction]
pub fn check_checkpoint_output(path: PathBuf) -> PyResult<()> {
    check_writable(&path).or_py()?;
    Checkpoint::check_replaceable(&path).or_py()
}

/// The PNG style of `exposure` (the CLI's range) and `tonemap`, or the refusal.
fn png_style(exposure: f32, tonemap: &str) -> PyResult<PngStyle> {
    if exposure.is_nan() || exposure.abs() > PngStyle::MAX_EXPOSURE {
        let max = PngStyle::MAX_EXPOSURE;
        return Err(invalid(format!("exposure must be between -{max} and {max} stops, got {exposure}")));
    }
    let tonemap = match tonemap {
        "aces" => Tonemap::Aces,
        "clamp" => Tonemap::Clamp,
        other => return Err(invalid(format!("unknown tonemap {other:?}: choose aces or clamp"))),
    };
    Ok(PngStyle { encoding: PngEncoding::Srgb, exposure, tonemap })
}
