//! Texture images in: PNG (8 or 16 bits), JPEG and OpenEXR, as linear RGB, row 0 at the top.
//!
//! Integer formats hold sRGB-encoded values and are decoded to linear, as Mitsuba 3's
//! `bitmap` texture does unless `raw` is set; OpenEXR is linear already. Grey images give
//! three equal channels; alpha is dropped (Mitsuba's RGB variants drop it too).

use std::path::Path;

use crate::error::{Error, Location, Result};
use crate::image::{Image, MAX_PIXELS};
use crate::io::check_input_file;
use crate::io::exr::read_exr;
use crate::math::Rgb;

/// The sRGB transfer function's inverse (IEC 61966-2-1): encoded [0, 1] to linear.
pub fn srgb_decode(encoded: f32) -> f32 {
    let c = encoded as f64;
    let v = if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    };
    v as f32
}

/// Reads a texture image; `raw` keeps integer codes linear (code / max) instead of decoding
/// sRGB. The format follows the file's first bytes, not its name.
pub fn read_texture_image(path: &Path, raw: bool) -> Result<Image> {
    check_input_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.starts_with(b"\x89PNG") {
        read_png(path, &bytes, raw)
    } else if bytes.starts_with(&[0xff, 0xd8]) {
        read_jpeg(path, &bytes, raw)
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        read_exr(path)
    } else {
        Err(Error::input(
            Location::file(path),
            "not a PNG, JPEG or OpenEXR file (the texture formats mltbench reads)",
        ))
    }
}

fn bad(path: &Path, message: impl Into<String>) -> Error {
    Error::input(Location::file(path), message)
}

/// Refuses images too large to hold before their pixels are allocated.
fn check_size(path: &Path, width: usize, height: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(bad(path, "the image is empty"));
    }
    if width
        .checked_mul(height)
        .is_none_or(|n| n as u64 > MAX_PIXELS)
    {
        return Err(bad(
            path,
            format!("an image of {width}×{height} pixels is larger than mltbench reads"),
        ));
    }
    Ok(())
}

/// Builds the linear image from integer codes: `channels` per pixel (1 grey, 2 grey + alpha,
/// 3 RGB, 4 RGBA), each code out of `max`.
fn from_codes(
    width: usize,
    height: usize,
    channels: usize,
    codes: impl Iterator<Item = u32>,
    max: f32,
    raw: bool,
) -> Image {
    // One table entry per code would be 65536 entries for 16 bits; decoding per value is fine
    // at load time.
    let to_linear = |c: u32| {
        let v = c as f32 / max;
        if raw { v } else { srgb_decode(v) }
    };
    let codes: Vec<f32> = codes.map(to_linear).collect();
    let pixels = codes
        .chunks_exact(channels)
        .map(|p| match channels {
            1 | 2 => Rgb::splat(p[0]),
            _ => Rgb::new(p[0], p[1], p[2]),
        })
        .collect();
    Image {
        width: width as u32,
        height: height as u32,
        pixels,
    }
}

fn read_png(path: &Path, bytes: &[u8], raw: bool) -> Result<Image> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    // Palettes and grey below 8 bits become 8-bit grey or RGB(A); 16 bits stay 16.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder
        .read_info()
        .map_err(|e| bad(path, format!("not a readable PNG: {e}")))?;
    let (width, height) = {
        let info = reader.info();
        (info.width as usize, info.height as usize)
    };
    check_size(path, width, height)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| bad(path, "the PNG's size overflows"))?;
    let mut buffer = vec![0; size];
    let frame = reader
        .next_frame(&mut buffer)
        .map_err(|e| bad(path, format!("not a readable PNG: {e}")))?;
    let channels = frame.color_type.samples();
    let data = &buffer[..frame.buffer_size()];
    let image = match frame.bit_depth {
        png::BitDepth::Eight => {
            let codes = data.iter().map(|&b| b as u32);
            from_codes(width, height, channels, codes, 255.0, raw)
        }
        png::BitDepth::Sixteen => {
            let codes = data
                .chunks_exact(2)
                .map(|b| u16::from_be_bytes([b[0], b[1]]) as u32);
            from_codes(width, height, channels, codes, 65535.0, raw)
        }
        depth => {
            return Err(bad(
                path,
                format!("PNG bit depth {depth:?} after expansion: not read"),
            ));
        }
    };
    check_pixel_count(path, image)
}

fn read_jpeg(path: &Path, bytes: &[u8], raw: bool) -> Result<Image> {
    use zune_jpeg::zune_core::bytestream::ZCursor;
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder
        .decode_headers()
        .map_err(|e| bad(path, format!("not a readable JPEG: {e:?}")))?;
    let (width, height) = decoder
        .dimensions()
        .ok_or_else(|| bad(path, "the JPEG has no dimensions"))?;
    check_size(path, width, height)?;
    let pixels = decoder
        .decode()
        .map_err(|e| bad(path, format!("not a readable JPEG: {e:?}")))?;
    let codes = pixels.iter().map(|&b| b as u32);
    let image = from_codes(width, height, 3, codes, 255.0, raw);
    check_pixel_count(path, image)
}

/// A decoder that returned fewer values than its header promised is a broken file.
fn check_pixel_count(path: &Path, image: Image) -> Result<Image> {
    if image.pixels.len() != image.width as usize * image.height as usize {
        return Err(bad(
            path,
            format!(
                "the file holds {} pixels where its header says {}×{}",
                image.pixels.len(),
                image.width,
                image.height
            ),
        ));
    }
    Ok(image)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_decode_inverts_the_encoding() {
        for i in 0..=255 {
            let v = i as f32 / 255.0;
            let back = crate::io::png::srgb_encode(srgb_decode(v));
            assert!((back - v).abs() < 1e-5, "{v} -> {back}");
        }
        assert_eq!(srgb_decode(0.0), 0.0);
        assert_eq!(srgb_decode(1.0), 1.0);
    }
}
