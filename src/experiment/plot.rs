//! Figures of an experiment: log-log convergence curves with a band over runs, bias² and
//! variance against time, and a contact sheet of final images with false-colour error maps.
//!
//! Data in, files out. Each plot is written as `STEM.png` and `STEM.svg` (the extension is
//! appended to the stem, so `results/cbox/convergence` gives `convergence.png` and
//! `convergence.svg`); the contact sheet is written as `STEM.png` only, since a sheet of
//! full-resolution images stored as SVG would be large and gain nothing. Files are written
//! atomically (`io::atomic`), and the parent directory must exist.
//!
//! Text is set in DejaVu Sans, embedded in the binary (`assets/fonts/`, with its licence):
//! plotters is built without its system-font features (no font-kit, no fontconfig), lays text
//! out with the embedded font through its `ab_glyph` backend, and the PNG glyphs are
//! rasterised here with ab_glyph (`text::BitmapWithText`). The PNGs therefore come out the same
//! on a machine with no fonts installed. The SVGs name the family `sans-serif` and leave the
//! glyphs to the viewer, as SVG text always does.
//!
//! Bad data never panics: points that are not finite, or not positive on a log axis, are
//! left out (the plot says how many); an empty series list gives a valid plot that says
//! there is no data.

mod log_axis;
mod loglog;
mod pyramid;
mod sheet;
mod text;
mod viridis;

pub use loglog::{bias_variance_plot, convergence_plot};
pub use pyramid::{PyramidCell, strategy_pyramid};
pub use sheet::{check_crops, contact_sheet};
pub use viridis::viridis;

use std::path::{Path, PathBuf};

use plotters::prelude::{DrawingAreaErrorKind, DrawingBackend};

use crate::error::{Error, Result};
use crate::image::Image;

/// Mean and confidence band of one quantity at a series of abscissae (e.g. relMSE over runs
/// at each checkpoint). The four vectors are read in step; a point whose x or mean is not
/// finite and positive is left out, a missing or unusable `lo`/`hi` collapses the band to
/// the mean there, and a `lo` ≤ 0 draws the band down to the bottom of the axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Band {
    pub x: Vec<f64>,
    pub mean: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
}

/// One labelled curve: an estimator's mean with its band.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    pub label: String,
    pub band: Band,
}

/// One estimator's row on the contact sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetEntry {
    pub label: String,
    /// The final image, the same size as the reference.
    pub image: Image,
    /// Per-pixel relative error against the reference, row-major, width × height values.
    pub error_map: Vec<f32>,
}

/// A region of interest shown zoomed on the contact sheet (pixel coordinates, row 0 at top).
#[derive(Clone, Debug, PartialEq)]
pub struct Crop {
    pub label: String,
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Non-finite values in an error map (and, through `io::tonemap`, in an image).
const INVALID_COLOR: [u8; 3] = [255, 0, 255];

/// What drawing on a plotters backend returns.
type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn with_extension(stem: &Path, extension: &str) -> PathBuf {
    let mut name = stem.as_os_str().to_owned();
    name.push(".");
    name.push(extension);
    PathBuf::from(name)
}

fn draw_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::io(
        path,
        std::io::Error::other(format!("cannot draw the figure: {e}")),
    )
}

/// 8-bit RGB pixels as an sRGB PNG file's bytes.
fn encode_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let png_error = |e: png::EncodingError| draw_error(path, e);
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(png_error)?;
    writer.write_image_data(rgb).map_err(png_error)?;
    writer.finish().map_err(png_error)?;
    Ok(out)
}
