//! OpenEXR (float32 RGB) writing and reading through the exr crate.
//!
//! Written files hold one layer with the channels R, G, B as 32-bit floats, ZIP
//! compressed (lossless: a round trip is bit exact). Reading accepts any file whose first
//! valid layer has R, G and B channels (any order, any sample type: f16, f32 or u32 are
//! converted to f32; other channels such as A are ignored). Everything runs on the calling
//! thread: the exr crate's own thread pool would ignore mltbench's `--threads`.

use std::path::Path;

use exr::prelude::{
    Encoding, LayerAttributes, ReadChannels, ReadLayers, ReadSpecificChannel, SpecificChannels,
    Vec2, WritableImage,
};

use crate::error::{Error, Location, Result};
use crate::image::{Image, MAX_PIXELS};
use crate::io::atomic::write_atomically;
use crate::math::Rgb;

fn exr_error(path: &Path, what: &str, e: exr::error::Error) -> Error {
    match e {
        exr::error::Error::Io(io) => Error::io(path, io),
        other => Error::input(
            Location::file(path),
            format!("{what} OpenEXR image: {other}"),
        ),
    }
}

/// Writes `image` as a float32 RGB OpenEXR file (atomically: a temporary file, then a
/// rename).
pub fn write_exr(path: &Path, image: &Image) -> Result<()> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w == 0 || h == 0 || image.pixels.len() != w * h {
        return Err(Error::input(
            Location::file(path),
            format!(
                "cannot write a {}×{} image with {} pixels as OpenEXR",
                image.width,
                image.height,
                image.pixels.len()
            ),
        ));
    }
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = image.pixels[p.y() * w + p.x()];
        (c.r(), c.g(), c.b())
    });
    let layer = exr::prelude::Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS, // ZIP, scan lines: lossless for f32
        channels,
    );
    let exr_image = exr::prelude::Image::from_layer(layer);
    write_atomically(path, |writer| {
        exr_image
            .write()
            .non_parallel()
            .to_buffered(writer)
            .map_err(|e| exr_error(path, "cannot write", e))
    })
}

/// Reads the first RGB layer of an OpenEXR file as linear RGB, row 0 at the top.
pub fn read_exr(path: &Path) -> Result<Image> {
    let read = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("R")
        .required("G")
        .required("B")
        .collect_pixels(
            |size: Vec2<usize>, _| Image {
                width: size.width() as u32,
                height: size.height() as u32,
                pixels: vec![Rgb::BLACK; size.area()],
            },
            |image: &mut Image, p: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                let w = image.width as usize;
                image.pixels[p.y() * w + p.x()] = Rgb::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel();
    // Check the sizes the header claims before anything is allocated for them.
    crate::io::check_input_file(path)?;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
        .map_err(|e| exr_error(path, "not a readable", e))?;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.width(), header.layer_size.height());
        if w.checked_mul(h).is_none_or(|n| n as u64 > MAX_PIXELS) {
            return Err(Error::input(
                Location::file(path),
                format!("OpenEXR layer of {w}×{h} pixels is larger than mltbench reads"),
            ));
        }
    }
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let exr_image = read
        .from_buffered(std::io::BufReader::new(file))
        .map_err(|e| exr_error(path, "not a readable RGB", e))?;
    let image = exr_image.layer_data.channel_data.pixels;
    if image.width == 0 || image.height == 0 || u32::try_from(image.pixels.len()).is_err() {
        return Err(Error::input(
            Location::file(path),
            "OpenEXR image is empty or too large",
        ));
    }
    Ok(image)
}
