//! Error metrics of an image against a reference, exactly as docs/DESIGN.md §5 defines them, over
//! all pixels and the three channels, computed in f64:
//!
//! - relMSE = mean((x − y)² / (y² + 0.01))
//! - RMSE   = sqrt(mean((x − y)²))
//! - MAPE   = mean(|x − y| / (y + 0.01))
//!
//! Every function checks its inputs (matching sizes, a pixel buffer that matches the stated
//! size, at least one pixel, finite values) and returns an error naming the culprit.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::image::Image;

/// The constant in the relMSE and MAPE denominators (docs/DESIGN.md §5): keeps black reference
/// pixels from dividing by zero.
pub const EPSILON: f64 = 0.01;

/// The three docs/DESIGN.md §5 errors of one image against a reference.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub relmse: f64,
    pub rmse: f64,
    pub mape: f64,
}

/// A rectangle of pixels (a crop region of interest, e.g. a caustic): `x`, `y` are the
/// top-left pixel (row 0 at the top, as in `Image`), `width` × `height` its size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Region {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl Region {
    /// The whole of a `width` × `height` image.
    pub fn full(width: u32, height: u32) -> Self {
        Region {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// Row-major pixel indices of the region inside an image `image_width` pixels wide.
    pub(crate) fn indices(self, image_width: u32) -> impl Iterator<Item = (u32, u32, usize)> {
        let w = image_width as usize;
        (self.y..self.y + self.height).flat_map(move |py| {
            (self.x..self.x + self.width).map(move |px| (px, py, py as usize * w + px as usize))
        })
    }
}

/// relMSE, RMSE and MAPE of `image` against `reference` over the whole image.
pub fn metrics(image: &Image, reference: &Image) -> Result<Metrics> {
    check_pair(image, reference, "image", "reference")?;
    metrics_over(
        image,
        reference,
        Region::full(reference.width, reference.height),
    )
}

/// relMSE, RMSE and MAPE of `image` against `reference` over the crop `region` only.
pub fn metrics_in(image: &Image, reference: &Image, region: Region) -> Result<Metrics> {
    check_pair(image, reference, "image", "reference")?;
    check_region(region, reference)?;
    metrics_over(image, reference, region)
}

fn metrics_over(image: &Image, reference: &Image, region: Region) -> Result<Metrics> {
    let (mut sq, mut rel_sq, mut abs_rel) = (0.0f64, 0.0f64, 0.0f64);
    let mut n = 0usize;
    for (px, py, i) in region.indices(reference.width) {
        let (x, y) = (image.pixels[i].0, reference.pixels[i].0);
        for c in 0..3 {
            let (xc, yc) = (f64::from(x[c]), f64::from(y[c]));
            check_finite(xc, "image", px, py, c)?;
            check_reference(yc, "reference", px, py, c)?;
            let d = xc - yc;
            sq += d * d;
            rel_sq += d * d / (yc * yc + EPSILON);
            abs_rel += d.abs() / (yc + EPSILON);
            n += 1;
        }
    }
    let n = n as f64;
    Ok(Metrics {
        relmse: rel_sq / n,
        rmse: (sq / n).sqrt(),
        mape: abs_rel / n,
    })
}

/// Per-pixel relative error for false-colour maps: the channel mean of |x − y| / (y + 0.01)
/// (the MAPE term of docs/DESIGN.md §5), row-major like `Image::pixels`.
pub fn relative_error_map(image: &Image, reference: &Image) -> Result<Vec<f32>> {
    check_pair(image, reference, "image", "reference")?;
    let mut map = Vec::with_capacity(reference.pixels.len());
    for (px, py, i) in Region::full(reference.width, reference.height).indices(reference.width) {
        let (x, y) = (image.pixels[i].0, reference.pixels[i].0);
        let mut sum = 0.0f64;
        for c in 0..3 {
            let (xc, yc) = (f64::from(x[c]), f64::from(y[c]));
            check_finite(xc, "image", px, py, c)?;
            check_reference(yc, "reference", px, py, c)?;
            sum += (xc - yc).abs() / (yc + EPSILON);
        }
        map.push((sum / 3.0) as f32);
    }
    Ok(map)
}

/// The estimated relMSE of a reference rendered as two independent halves `half_a`, `half_b`
/// (each with the same expected value μ and per-pixel variance σ²), the reference itself being
/// their mean y = (a + b) / 2.
///
/// Derivation: with a = μ + ε_a and b = μ + ε_b, ε independent with mean 0 and variance σ²,
/// - the reference's own error is y − μ = (ε_a + ε_b) / 2, so E[(y − μ)²] = σ²/2;
/// - a − b = ε_a − ε_b, so E[(a − b)²] = 2σ²;
/// - hence E[(y − μ)²] = E[(a − b)²] / 4, which (a − b)²/4 estimates without bias per
///   pixel-channel.
///
/// Dividing by the relMSE denominator (with the reference y in place of the unknown μ, as
/// relMSE itself does) gives reference relMSE ≈ mean((a − b)²/4 / (y² + 0.01)).
///
/// Pitfalls this avoids: relMSE(a, b), "the relMSE between the halves", estimates
/// E[(a − b)²] = 2σ², four times the reference's own error. The relMSE of a half against y
/// equals the formula above term by term (a − y = (a − b)/2), but only because of the
/// two-half split; read naively as "the noise of a half" (σ²) it would be off by two.
pub fn reference_noise(half_a: &Image, half_b: &Image) -> Result<f64> {
    check_pair(half_a, half_b, "first half", "second half")?;
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for (px, py, i) in Region::full(half_a.width, half_a.height).indices(half_a.width) {
        let (a, b) = (half_a.pixels[i].0, half_b.pixels[i].0);
        for c in 0..3 {
            let (ac, bc) = (f64::from(a[c]), f64::from(b[c]));
            check_finite(ac, "first half", px, py, c)?;
            check_finite(bc, "second half", px, py, c)?;
            let y = 0.5 * (ac + bc);
            let d = ac - bc;
            sum += 0.25 * d * d / (y * y + EPSILON);
            n += 1;
        }
    }
    Ok(sum / n as f64)
}

/// Checks that both images are well formed, non-empty and of the same size.
pub(crate) fn check_pair(a: &Image, b: &Image, a_name: &str, b_name: &str) -> Result<()> {
    check_image(a, a_name)?;
    check_image(b, b_name)?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::usage(format!(
            "{a_name} is {}×{} but {b_name} is {}×{}: images must be the same size",
            a.width, a.height, b.width, b.height
        )));
    }
    Ok(())
}

/// Checks that an image has at least one pixel and a buffer matching its stated size.
pub(crate) fn check_image(image: &Image, name: &str) -> Result<()> {
    if image.width == 0 || image.height == 0 {
        return Err(Error::usage(format!(
            "{name} is {}×{}: it has no pixels to measure",
            image.width, image.height
        )));
    }
    let expected = u64::from(image.width) * u64::from(image.height);
    if image.pixels.len() as u64 != expected {
        return Err(Error::usage(format!(
            "{name} is {}×{} but holds {} pixels",
            image.width,
            image.height,
            image.pixels.len()
        )));
    }
    Ok(())
}

/// Checks that a crop region lies inside the image and is not empty.
pub(crate) fn check_region(region: Region, image: &Image) -> Result<()> {
    let inside = u64::from(region.x) + u64::from(region.width) <= u64::from(image.width)
        && u64::from(region.y) + u64::from(region.height) <= u64::from(image.height);
    if region.width == 0 || region.height == 0 || !inside {
        return Err(Error::usage(format!(
            "region {}×{} at ({}, {}) is empty or not inside the {}×{} image",
            region.width, region.height, region.x, region.y, image.width, image.height
        )));
    }
    Ok(())
}

const CHANNEL: [&str; 3] = ["red", "green", "blue"];

/// A non-finite value makes every mean meaningless: name the pixel instead.
pub(crate) fn check_finite(v: f64, name: &str, x: u32, y: u32, c: usize) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::usage(format!(
            "{name} pixel ({x}, {y}) has a non-finite {} value ({v})",
            CHANNEL[c]
        )))
    }
}

/// A reference value must be finite, and the MAPE denominator y + 0.01 positive (radiance is
/// non-negative; tiny negative values from a reconstruction filter above −0.01 still pass).
pub(crate) fn check_reference(v: f64, name: &str, x: u32, y: u32, c: usize) -> Result<()> {
    check_finite(v, name, x, y, c)?;
    if v + EPSILON > 0.0 {
        Ok(())
    } else {
        Err(Error::usage(format!(
            "{name} pixel ({x}, {y}) has {} value {v}: the MAPE denominator y + {EPSILON} \
             must be positive",
            CHANNEL[c]
        )))
    }
}
