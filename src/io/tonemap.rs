//! Tone mapping for previews: Reinhard et al. 2002, "Photographic Tone Reproduction for
//! Digital Images" (SIGGRAPH), the global operator.
//!
//! With Lw the world luminance of a pixel (BT.709 weights of linear sRGB):
//! - eq. 1, the log-average ("key") of the scene: L̄w = exp(mean(log(δ + Lw)));
//! - eq. 2, scaling to the key value a: L = a / L̄w · Lw;
//! - eq. 4, compression that burns out only above L_white: Ld = L (1 + L / L_white²) / (1 + L).
//!
//! Each pixel's RGB is multiplied by Ld / Lw, which keeps its chromaticity; channels may
//! exceed 1 for saturated colours and are clipped by the 8-bit encoding. By default a = 0.18
//! and L_white is the largest scaled luminance L in the image, so the brightest pixel maps
//! to Ld = 1.
//!
//! Pixels with a NaN or infinite channel are left out of L̄w and L_white and come out
//! magenta (1, 0, 1), so that a numerical problem shows in the preview instead of
//! poisoning it or hiding as black. Negative luminances count as 0 and come out black.
//! An all-black image stays black.

use crate::image::Image;
use crate::math::Rgb;

/// The colour a non-finite pixel gets in a preview.
pub const INVALID_PIXEL: Rgb = Rgb::new(1.0, 0.0, 1.0);

/// The parameters of Reinhard's global operator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reinhard {
    /// The key value a (eq. 2).
    pub key: f64,
    /// L_white in scaled luminance units (eq. 4); None = the image's largest L.
    pub white: Option<f64>,
    /// δ in eq. 1, keeping log(δ + Lw) finite for black pixels.
    pub delta: f64,
}

impl Default for Reinhard {
    fn default() -> Self {
        Reinhard {
            key: 0.18,
            white: None,
            delta: 1e-4,
        }
    }
}

fn is_finite(c: Rgb) -> bool {
    c.0.iter().all(|v| v.is_finite())
}

/// The world luminance Lw of a pixel, in f64, negative values clamped to 0.
fn luminance(c: Rgb) -> f64 {
    (0.2126 * c.r() as f64 + 0.7152 * c.g() as f64 + 0.0722 * c.b() as f64).max(0.0)
}

impl Reinhard {
    /// L̄w of eq. 1 over the finite pixels (δ when there are none).
    pub fn log_average_luminance(&self, image: &Image) -> f64 {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for &c in image.pixels.iter().filter(|&&c| is_finite(c)) {
            sum += (self.delta + luminance(c)).ln();
            n += 1;
        }
        if n == 0 {
            self.delta
        } else {
            (sum / n as f64).exp()
        }
    }

    /// The tone mapped image: display values, mostly in [0, 1], still linear.
    pub fn apply(&self, image: &Image) -> Image {
        let log_average = self.log_average_luminance(image);
        let scale = self.key / log_average; // eq. 2: L = scale · Lw
        let white = self.white.unwrap_or_else(|| {
            image
                .pixels
                .iter()
                .filter(|&&c| is_finite(c))
                .map(|&c| scale * luminance(c))
                .fold(0.0, f64::max)
        });
        let inv_white2 = if white > 0.0 {
            1.0 / (white * white)
        } else {
            0.0
        };
        let mut out = image.clone();
        for c in &mut out.pixels {
            if !is_finite(*c) {
                *c = INVALID_PIXEL;
                continue;
            }
            let lw = luminance(*c);
            if lw <= 0.0 {
                *c = Rgb::BLACK;
                continue;
            }
            let l = scale * lw;
            let ld = l * (1.0 + l * inv_white2) / (1.0 + l); // eq. 4
            let k = ld / lw;
            *c = c.map(|v| (v as f64 * k) as f32);
        }
        out
    }
}

/// Reinhard's operator with the default parameters (a = 0.18, L_white = the image's
/// largest scaled luminance).
pub fn reinhard(image: &Image) -> Image {
    Reinhard::default().apply(image)
}
