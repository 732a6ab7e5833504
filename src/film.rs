//! Accumulating samples into pixels: filtered per-pixel sums, a splat buffer for light
//! tracing, and a merge order that does not depend on the thread count.

use glam::Vec2;

use crate::image::Image;
use crate::math::Rgb;
use crate::scene::FilterDesc;

/// A rectangle of pixels [x0, x1) × [y0, y1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

/// The whole image's accumulators.
pub struct Film {}

/// The accumulators a tile writes to (its pixels plus the filter's margin), merged into
/// the `Film` in tile order.
pub struct FilmTile {}

impl Film {
    pub fn new(width: u32, height: u32, filter: FilterDesc) -> Film {
        let _ = (width, height, filter);
        todo!("film")
    }

    /// An empty tile covering `rect` (and the filter margin around it).
    pub fn tile(&self, rect: PixelRect) -> FilmTile {
        let _ = rect;
        todo!("film")
    }

    /// Adds a finished tile. Call in a fixed tile order for bit-identical results.
    pub fn merge_tile(&mut self, tile: &FilmTile) {
        let _ = tile;
        todo!("film")
    }

    /// Adds a light-tracing splat at raster position `raster` (box-filtered, unnormalised).
    pub fn splat(&mut self, raster: Vec2, value: Rgb) {
        let _ = (raster, value);
        todo!("film")
    }

    /// The current estimate: filtered pixel values plus the splats times `splat_scale`.
    pub fn image(&self, splat_scale: f64) -> Image {
        let _ = splat_scale;
        todo!("film")
    }
}

impl FilmTile {
    /// Adds a camera sample taken at raster position `raster`, weighted by the filter.
    pub fn add_sample(&mut self, raster: Vec2, value: Rgb) {
        let _ = (raster, value);
        todo!("film")
    }
}
