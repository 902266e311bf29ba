//! PNG files, written atomically like every other output (a killed `polydem render` never leaves
//! a half-written picture).

use std::path::Path;

use image::codecs::png::PngEncoder;
use image::{ColorType, ImageEncoder};

use super::PictureError;
use crate::io::write_atomic_bytes;

/// Writes 8-bit RGB pixels (`width` × `height`, rows top to bottom) as a PNG file.
pub fn write_rgb(path: &Path, width: usize, height: usize, rgb: &[u8]) -> Result<(), PictureError> {
    let mut bytes = Vec::new();
    PngEncoder::new(&mut bytes)
        .write_image(rgb, width as u32, height as u32, ColorType::Rgb8)
        .map_err(|e| PictureError::file(path, format!("encoding PNG: {e}")))?;
    write_atomic_bytes(path, &bytes).map_err(|e| PictureError::file(path, e.to_string()))
}
