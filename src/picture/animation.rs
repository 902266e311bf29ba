//! An animated GIF of a frame series (`polydem render DIR --frame all --out run.gif`): every
//! frame quantised to its own 256 colours (NeuQuant, which keeps the colour scale's gradients),
//! looping forever, written atomically at the end.

use std::path::{Path, PathBuf};

use gif::{Encoder, Frame, Repeat};

use super::PictureError;
use crate::io::write_atomic_bytes;

/// A GIF being built in memory, one frame at a time.
pub struct Animation {
    path: PathBuf,
    encoder: Encoder<Vec<u8>>,
    width: u16,
    height: u16,
    /// Delay between frames [1/100 s].
    delay: u16,
}

impl Animation {
    /// Starts a GIF of `width` × `height` pixels showing `fps` frames per second.
    pub fn new(path: &Path, width: usize, height: usize, fps: f64) -> Result<Self, PictureError> {
        let fail = |e: gif::EncodingError| PictureError::file(path, format!("encoding GIF: {e}"));
        let (Ok(w), Ok(h)) = (u16::try_from(width), u16::try_from(height)) else {
            return Err(PictureError::Option(format!(
                "a GIF is at most 65535 pixels wide and high, not {width}x{height}"
            )));
        };
        if !(fps.is_finite() && fps > 0.0) {
            return Err(PictureError::Option(format!(
                "--fps {fps}: give a positive number of frames per second"
            )));
        }
        let mut encoder = Encoder::new(Vec::new(), w, h, &[]).map_err(fail)?;
        encoder.set_repeat(Repeat::Infinite).map_err(fail)?;
        Ok(Self {
            path: path.to_path_buf(),
            encoder,
            width: w,
            height: h,
            delay: (100.0 / fps).round().clamp(2.0, 65535.0) as u16,
        })
    }

    /// Adds a frame of 8-bit RGB pixels of the animation's size.
    pub fn push(&mut self, rgb: &[u8]) -> Result<(), PictureError> {
        if rgb.len() != 3 * usize::from(self.width) * usize::from(self.height) {
            return Err(PictureError::Draw("GIF frame of the wrong size".into()));
        }
        // Speed 10 of 1–30: a good palette at a fraction of the slowest setting's time.
        let mut frame = Frame::from_rgb_speed(self.width, self.height, rgb, 10);
        frame.delay = self.delay;
        self.encoder
            .write_frame(&frame)
            .map_err(|e| PictureError::file(&self.path, format!("encoding GIF: {e}")))
    }

    /// Writes the file.
    pub fn finish(self) -> Result<PathBuf, PictureError> {
        let path = self.path;
        let bytes = self
            .encoder
            .into_inner()
            .map_err(|e| PictureError::file(&path, format!("encoding GIF: {e}")))?;
        write_atomic_bytes(&path, &bytes).map_err(|e| PictureError::file(&path, e.to_string()))?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_make_a_looping_gif() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let mut animation = Animation::new(&path, 4, 2, 5.0).unwrap();
        animation.push(&[255; 24]).unwrap();
        animation.push(&[0; 24]).unwrap();
        assert!(animation.push(&[0; 3]).is_err());
        animation.finish().unwrap();
        let mut decoder = gif::DecodeOptions::new()
            .read_info(std::fs::File::open(&path).unwrap())
            .unwrap();
        let mut frames = 0;
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!((frame.width, frame.height, frame.delay), (4, 2, 20));
            frames += 1;
        }
        assert_eq!(frames, 2);
        assert!(Animation::new(&path, 4, 2, 0.0).is_err());
    }
}
