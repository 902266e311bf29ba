//! Pictures of a run without ParaView: `polydem render` (shaded 3-D snapshots of the `.vtp`
//! output) and `polydem plot` (the CSV time series).
//!
//! The 3-D view is a small software rasteriser, one idea per file: `camera` (orthographic views
//! fitted to the scene), `raster` (z-buffer, Lambert shading, spheres traced per pixel, polygons,
//! lines, outlines), `colormap`, `cut` (half-spaces that cut walls away), `run_files` (which
//! files of a run folder make a frame), `overlay` (title and colour bar), `render` (one frame
//! from all that). Text and plots go through `plotters` with an embedded font (`font`), the text
//! drawn by `text`; PNG files are written by `png`, atomically like every output of polydem; a
//! series can also go into an animated GIF (`animation`).

pub mod animation;
pub mod camera;
pub mod colormap;
pub mod cut;
pub mod font;
pub mod overlay;
pub mod plot;
pub mod png;
pub mod raster;
pub mod render;
pub mod run_files;
pub mod text;

use std::path::PathBuf;

use crate::io::vtk_read::VtkReadError;

/// Why a picture could not be made; every message says which file or option is at fault.
#[derive(Debug, thiserror::Error)]
pub enum PictureError {
    #[error("{0}")]
    Read(#[from] VtkReadError),
    /// A file that is missing, or read but not usable for a picture.
    #[error("{}: {message}", path.display())]
    File { path: PathBuf, message: String },
    /// A CSV series that cannot be read (the message names the file and line).
    #[error("{0}")]
    Table(String),
    /// A command-line option that cannot be honoured.
    #[error("{0}")]
    Option(String),
    #[error("drawing failed: {0}")]
    Draw(String),
}

impl PictureError {
    pub(crate) fn file(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::File {
            path: path.into(),
            message: message.into(),
        }
    }
}
