//! An RGB float image (linear radiance), row-major with row 0 at the top.

use crate::math::Rgb;

/// The most pixels an image may have, read (OpenEXR) or rendered (a scene's film):
/// 2^28, e.g. 16384 × 16384, 3 GiB as f32 RGB.
pub const MAX_PIXELS: u64 = 1 << 28;

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![Rgb::BLACK; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    pub fn set(&mut self, x: u32, y: u32, value: Rgb) {
        self.pixels[y as usize * self.width as usize + x as usize] = value;
    }
}
