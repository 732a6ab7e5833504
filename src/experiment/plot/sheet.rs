//! The contact sheet: final images of every estimator beside the reference, their
//! false-colour error maps, and regions of interest zoomed.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::{PathElement, Rectangle, Text};
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingBackend, IntoDrawingArea};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{BLACK, Color, RGBColor, TextStyle};

use super::log_axis::superscript;
use super::text::{BitmapWithText, dejavu_sans, ensure_font, font};
use super::viridis::viridis;
use super::{Crop, DrawResult, INVALID_COLOR, SheetEntry, draw_error, encode_png, with_extension};
use crate::error::{Error, Result};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::png::srgb_to_u8;
use crate::io::tonemap::Reinhard;

/// The longest side of an image tile on the contact sheet, in pixels.
const TILE: u32 = 320;
const MARGIN: u32 = 16;
const GAP: u32 = 12;
const HEADER_HEIGHT: u32 = 28;
const ROW_LABEL_HEIGHT: u32 = 26;
const BAR_HEIGHT: u32 = 16;
const TEXT_LINE: u32 = 22;
/// Crop outlines, from the Okabe–Ito palette (bright ones first: they sit on images).
const CROP_COLORS: [RGBColor; 6] = [
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(213, 94, 0),
    RGBColor(204, 121, 167),
    RGBColor(0, 158, 115),
    RGBColor(240, 228, 66),
];

/// Checks that every crop is non-empty and lies inside a `width` × `height` image, so that a
/// runner can reject a bad experiment spec before rendering anything.
pub fn check_crops(crops: &[Crop], width: u32, height: u32) -> Result<()> {
    for c in crops {
        let inside = c.width > 0
            && c.height > 0
            && c.x as u64 + c.width as u64 <= width as u64
            && c.y as u64 + c.height as u64 <= height as u64;
        if !inside {
            return Err(Error::usage(format!(
                "crop \"{}\" ({}×{} at {}, {}) does not lie inside the {width}×{height} image",
                c.label, c.width, c.height, c.x, c.y
            )));
        }
    }
    Ok(())
}

fn check_image(what: &str, image: &Image) -> Result<()> {
    let n = image.width as u64 * image.height as u64;
    if image.width == 0 || image.height == 0 || image.pixels.len() as u64 != n {
        return Err(Error::usage(format!(
            "{what}: a {}×{} image with {} pixels cannot go on a contact sheet",
            image.width,
            image.height,
            image.pixels.len()
        )));
    }
    Ok(())
}

/// BT.709 luminance of linear sRGB, as `io::tonemap` measures it (negative counts as 0).
pub(super) fn luminance(c: [f32; 3]) -> f64 {
    (0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64).max(0.0)
}

/// Reinhard's operator with the reference's exposure: the scale a/L̄w and L_white are those
/// the default operator picks for the reference, so that every image on the sheet is mapped
/// by the same curve and differences in brightness stay visible.
pub(super) fn exposure_like(reference: &Image) -> impl Fn(&Image) -> Image {
    let base = Reinhard::default();
    let ref_average = base.log_average_luminance(reference);
    let scale = base.key / ref_average;
    let white = reference
        .pixels
        .iter()
        .filter(|c| c.0.iter().all(|v| v.is_finite()))
        .map(|c| scale * luminance(c.0))
        .fold(0.0, f64::max);
    move |image: &Image| {
        // `apply` scales by key / L̄w(image): choose the key that makes it `scale`.
        let average = base.log_average_luminance(image);
        Reinhard {
            key: scale * average,
            white: Some(white),
            ..base
        }
        .apply(image)
    }
}

/// Resamples the region `(x0, y0, w, h)` of a row-major grid of width `stride` to `ow` × `oh`:
/// each output pixel averages the source pixels it covers when shrinking, and repeats the
/// nearest one when enlarging. NaN stays NaN.
pub(super) fn resample<const N: usize>(
    src: &[[f32; N]],
    stride: usize,
    (x0, y0, w, h): (usize, usize, usize, usize),
    (ow, oh): (usize, usize),
) -> Vec<[f32; N]> {
    let span = |o: usize, n: usize, out: usize| {
        let a = o * n / out;
        (a, ((o + 1) * n / out).max(a + 1))
    };
    let mut out = Vec::with_capacity(ow * oh);
    for oy in 0..oh {
        let (sy0, sy1) = span(oy, h, oh);
        for ox in 0..ow {
            let (sx0, sx1) = span(ox, w, ow);
            let mut sum = [0f32; N];
            for sy in sy0..sy1 {
                let row = (y0 + sy) * stride + x0;
                for p in &src[row + sx0..row + sx1] {
                    for c in 0..N {
                        sum[c] += p[c];
                    }
                }
            }
            let n = ((sy1 - sy0) * (sx1 - sx0)) as f32;
            out.push(sum.map(|v| v / n));
        }
    }
    out
}

/// The size of a `w` × `h` region scaled to fit a `box_w` × `box_h` box: by a whole factor
/// when enlarging (crisp nearest-neighbour pixels), by the exact ratio when shrinking.
pub(super) fn fit(w: u32, h: u32, box_w: u32, box_h: u32) -> (u32, u32) {
    let s = (box_w as f64 / w as f64).min(box_h as f64 / h as f64);
    let s = if s >= 1.0 { s.floor() } else { s };
    (
        ((w as f64 * s).round() as u32).max(1),
        ((h as f64 * s).round() as u32).max(1),
    )
}

/// An 8-bit RGB canvas the tiles are copied into before plotters adds text and outlines.
pub(super) struct Canvas {
    pub(super) width: u32,
    pub(super) rgb: Vec<u8>,
}

impl Canvas {
    pub(super) fn put(&mut self, x: u32, y: u32, w: u32, pixels: &[[u8; 3]]) {
        for (i, p) in pixels.iter().enumerate() {
            let (px, py) = (x + i as u32 % w, y + i as u32 / w);
            let at = 3 * (py as usize * self.width as usize + px as usize);
            self.rgb[at..at + 3].copy_from_slice(p);
        }
    }
}

/// The decades the error colour scale spans: from the 1st to the 99.5th percentile of the
/// finite positive errors, widened to whole decades, at most six of them.
fn error_decades<'a>(maps: impl Iterator<Item = &'a [f32]>) -> (i32, i32) {
    let mut values: Vec<f32> = maps
        .flatten()
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    if values.is_empty() {
        return (-3, 0);
    }
    let mut quantile = |q: f64| {
        let k = ((values.len() - 1) as f64 * q).round() as usize;
        *values.select_nth_unstable_by(k, f32::total_cmp).1 as f64
    };
    let (p_lo, p_hi) = (quantile(0.01), quantile(0.995));
    let hi = p_hi.log10().ceil() as i32;
    let lo = (p_lo.log10().floor() as i32).clamp(hi - 6, hi - 1);
    (lo, hi)
}

fn error_color(e: f32, (lo, hi): (i32, i32)) -> [u8; 3] {
    if !e.is_finite() {
        return INVALID_COLOR;
    }
    if e <= 0.0 {
        return viridis(0.0);
    }
    viridis(((e.log10() - lo as f32) / (hi - lo) as f32).clamp(0.0, 1.0))
}

/// One row of the sheet: a label, a display image (tone mapped, linear) and an error map.
struct SheetRow<'a> {
    label: &'a str,
    display: Image,
    error_map: Option<&'a [f32]>,
}

/// A contact sheet of final images, written to `STEM.png` (PNG only: the tiles are bitmaps,
/// which an SVG would only wrap, at many times the size).
///
/// One row for the reference, then one per entry: the image tone mapped (Reinhard, through
/// `io::tonemap`) with the reference's exposure so that brightness compares across rows, its
/// relative-error map in false colour (viridis, log scale over whole decades shared by all
/// rows, with a colour bar), and each crop zoomed with nearest-neighbour pixels, its outline
/// drawn on the full image and error map. Images are shown with their longest side near
/// 320 pixels (enlarged by a whole factor, or shrunk by averaging). Non-finite pixels show
/// magenta. Every image must have the reference's size and every error map width × height
/// values; crops must lie inside the image (see [`check_crops`]).
pub fn contact_sheet(
    stem: &Path,
    reference: &Image,
    entries: &[SheetEntry],
    crops: &[Crop],
) -> Result<()> {
    ensure_font()?;
    let png_path = with_extension(stem, "png");
    check_image("the reference", reference)?;
    let (w, h) = (reference.width, reference.height);
    for e in entries {
        check_image(&e.label, &e.image)?;
        if (e.image.width, e.image.height) != (w, h) {
            return Err(Error::usage(format!(
                "{}: the image is {}×{}, the reference {w}×{h}",
                e.label, e.image.width, e.image.height
            )));
        }
        if e.error_map.len() as u64 != w as u64 * h as u64 {
            return Err(Error::usage(format!(
                "{}: the error map has {} values for a {w}×{h} image",
                e.label,
                e.error_map.len()
            )));
        }
    }
    check_crops(crops, w, h)?;

    let tonemap = exposure_like(reference);
    let mut rows = vec![SheetRow {
        label: "reference",
        display: tonemap(reference),
        error_map: None,
    }];
    rows.extend(entries.iter().map(|e| SheetRow {
        label: &e.label,
        display: tonemap(&e.image),
        error_map: Some(&e.error_map),
    }));
    let decades = error_decades(entries.iter().map(|e| e.error_map.as_slice()));

    // Layout: columns image | error map | crops…, each row a label line over its tiles.
    let (tw, th) = fit(w, h, TILE, TILE);
    let header_font = font(17.0);
    let text_width =
        |text: &str, style: &TextStyle| style.font.box_size(text).map(|(x, _)| x).unwrap_or(0);
    let crop_tiles: Vec<(u32, u32)> = crops
        .iter()
        .map(|c| fit(c.width, c.height, TILE, th))
        .collect();
    let crop_titles: Vec<String> = crops
        .iter()
        .zip(&crop_tiles)
        .map(|(c, &(cw, _))| format!("{} (×{})", c.label, fmt_zoom(cw as f64 / c.width as f64)))
        .collect();
    let mut columns = vec![(
        tw.max(text_width("image", &header_font)),
        "image".to_string(),
    )];
    // No error map column on a sheet of the reference alone.
    if !entries.is_empty() {
        let title = "relative error";
        columns.push((tw.max(text_width(title, &header_font)), title.to_string()));
    }
    let first_crop = columns.len();
    for (title, &(cw, _)) in crop_titles.iter().zip(&crop_tiles) {
        columns.push((cw.max(text_width(title, &header_font) + 4), title.clone()));
    }
    let mut col_x = Vec::with_capacity(columns.len());
    let mut x = MARGIN;
    for (cw, _) in &columns {
        col_x.push(x);
        x += cw + GAP;
    }
    let caption_font = font(15.0);
    let captions = sheet_captions(decades, !entries.is_empty(), !crops.is_empty());
    let caption_width = captions
        .iter()
        .map(|c| text_width(c, &caption_font))
        .max()
        .unwrap_or(0);
    let width = (x - GAP + MARGIN).max(caption_width + 2 * MARGIN);
    let row_height = ROW_LABEL_HEIGHT + th + GAP;
    let rows_top = MARGIN + HEADER_HEIGHT;
    let footer_top = rows_top + rows.len() as u32 * row_height;
    let bar_block = if entries.is_empty() {
        0
    } else {
        BAR_HEIGHT + TEXT_LINE + 8
    };
    let height = footer_top + bar_block + captions.len() as u32 * TEXT_LINE + MARGIN;

    // Tiles, as raw pixels.
    let mut canvas = Canvas {
        width,
        rgb: vec![255; width as usize * height as usize * 3],
    };
    let to_u8 = |p: &[f32; 3]| p.map(srgb_to_u8);
    for (r, row) in rows.iter().enumerate() {
        let y = rows_top + r as u32 * row_height + ROW_LABEL_HEIGHT;
        let linear: Vec<[f32; 3]> = row.display.pixels.iter().map(|c| c.0).collect();
        let full = (0, 0, w as usize, h as usize);
        let tile = resample(&linear, w as usize, full, (tw as usize, th as usize));
        canvas.put(col_x[0], y, tw, &tile.iter().map(to_u8).collect::<Vec<_>>());
        if let Some(map) = row.error_map {
            let values: Vec<[f32; 1]> = map.iter().map(|&e| [e]).collect();
            let tile = resample(&values, w as usize, full, (tw as usize, th as usize));
            let colors: Vec<[u8; 3]> = tile.iter().map(|e| error_color(e[0], decades)).collect();
            canvas.put(col_x[1], y, tw, &colors);
        }
        for (k, (c, &(cw, ch))) in crops.iter().zip(&crop_tiles).enumerate() {
            let region = (
                c.x as usize,
                c.y as usize,
                c.width as usize,
                c.height as usize,
            );
            let tile = resample(&linear, w as usize, region, (cw as usize, ch as usize));
            canvas.put(
                col_x[first_crop + k],
                y,
                cw,
                &tile.iter().map(to_u8).collect::<Vec<_>>(),
            );
        }
    }
    if !entries.is_empty() {
        let bar: Vec<[u8; 3]> = (0..BAR_HEIGHT)
            .flat_map(|_| (0..tw).map(|i| viridis(i as f32 / (tw - 1).max(1) as f32)))
            .collect();
        canvas.put(col_x[1], footer_top, tw, &bar);
    }

    // Text and outlines, through plotters with the embedded font.
    let layout = SheetLayout {
        tile: (tw, th),
        image: (w, h),
        columns,
        col_x,
        first_crop,
        rows_top,
        row_height,
        footer_top,
        decades,
        crop_tiles,
    };
    {
        let backend = BitmapWithText {
            inner: BitMapBackend::with_buffer(&mut canvas.rgb, (width, height)),
            font: dejavu_sans()?,
        };
        let root = backend.into_drawing_area();
        draw_sheet_text(&root, &layout, &rows, crops, &captions)
            .map_err(|e| draw_error(&png_path, e))?;
    }
    let png = encode_png(&png_path, &canvas.rgb, width, height)?;
    write_file_atomically(&png_path, &png)
}

/// A zoom factor for a crop title: whole when it is, else one decimal.
fn fmt_zoom(z: f64) -> String {
    if (z - z.round()).abs() < 1e-9 {
        format!("{}", z.round())
    } else {
        format!("{z:.1}")
    }
}

/// The lines under the sheet that say how to read it.
fn sheet_captions((lo, hi): (i32, i32), errors: bool, crops: bool) -> Vec<String> {
    let mut lines = Vec::new();
    if errors {
        lines.push(format!(
            "Relative error per pixel, log colour scale from 10{} to 10{} (viridis; values beyond \
             the ends clamped; magenta: not finite).",
            superscript(lo as i64),
            superscript(hi as i64)
        ));
    }
    let mut images = "Images tone mapped (Reinhard) with the reference's exposure".to_string();
    if crops {
        images.push_str("; crops enlarged with nearest-neighbour pixels, outlined in the images");
    }
    images.push('.');
    lines.push(images);
    lines
}

struct SheetLayout {
    tile: (u32, u32),
    image: (u32, u32),
    /// (width, title) of each column: image, error map, crops.
    columns: Vec<(u32, String)>,
    col_x: Vec<u32>,
    /// The column of the first crop.
    first_crop: usize,
    rows_top: u32,
    row_height: u32,
    footer_top: u32,
    decades: (i32, i32),
    crop_tiles: Vec<(u32, u32)>,
}

fn draw_sheet_text<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    l: &SheetLayout,
    rows: &[SheetRow],
    crops: &[Crop],
    captions: &[String],
) -> DrawResult<DB> {
    let top_left = Pos::new(HPos::Left, VPos::Top);
    let (tw, th) = l.tile;
    let (w, h) = l.image;
    let p = |x: u32, y: u32| (x as i32, y as i32);
    for ((_, title), &x) in l.columns.iter().zip(&l.col_x) {
        root.draw(&Text::new(
            title.clone(),
            p(x, MARGIN),
            font(17.0).pos(top_left),
        ))?;
    }
    let outline = |x0: u32, y0: u32, x1: u32, y1: u32, color: RGBColor, width: u32| {
        // Just outside the pixels it frames, so that it hides none of them.
        Rectangle::new(
            [(x0 as i32 - 1, y0 as i32 - 1), (x1 as i32, y1 as i32)],
            color.stroke_width(width),
        )
    };
    for (r, row) in rows.iter().enumerate() {
        let y_label = l.rows_top + r as u32 * l.row_height;
        let y = y_label + ROW_LABEL_HEIGHT;
        root.draw(&Text::new(
            row.label.to_string(),
            p(l.col_x[0], y_label + 3),
            font(18.0).pos(top_left),
        ))?;
        if row.error_map.is_none() && rows.len() > 1 {
            let x = l.col_x[1];
            root.draw(&outline(x, y, x + tw, y + th, RGBColor(200, 200, 200), 1))?;
            root.draw(&Text::new(
                "reference: no error map",
                p(x + tw / 2, y + th / 2),
                font(15.0)
                    .color(&RGBColor(120, 120, 120))
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))?;
        }
        for (k, (c, &(cw, ch))) in crops.iter().zip(&l.crop_tiles).enumerate() {
            let color = CROP_COLORS[k % CROP_COLORS.len()];
            // The crop's outline on the image and on the error map, scaled to the tile.
            for col in [0, 1] {
                if col == 1 && row.error_map.is_none() {
                    continue;
                }
                let sx = |v: u32| l.col_x[col] + (v as u64 * tw as u64 / w as u64) as u32;
                let sy = |v: u32| y + (v as u64 * th as u64 / h as u64) as u32;
                root.draw(&outline(
                    sx(c.x),
                    sy(c.y),
                    sx(c.x + c.width),
                    sy(c.y + c.height),
                    color,
                    2,
                ))?;
            }
            let x = l.col_x[l.first_crop + k];
            root.draw(&outline(x, y, x + cw, y + ch, color, 2))?;
        }
    }
    let mut y = l.footer_top;
    if rows.len() > 1 {
        // Ticks and labels of the colour bar, one per decade.
        let (lo, hi) = l.decades;
        let x0 = l.col_x[1];
        root.draw(&outline(
            x0,
            y,
            x0 + tw,
            y + BAR_HEIGHT,
            RGBColor(90, 90, 90),
            1,
        ))?;
        for n in lo..=hi {
            let x = x0 + ((n - lo) as f64 / (hi - lo) as f64 * (tw - 1) as f64).round() as u32;
            let (x, ytick) = (x as i32, (y + BAR_HEIGHT) as i32);
            root.draw(&PathElement::new(
                vec![(x, ytick), (x, ytick + 5)],
                BLACK.stroke_width(1),
            ))?;
            root.draw(&Text::new(
                format!("10{}", superscript(n as i64)),
                (x, ytick + 6),
                font(15.0).pos(Pos::new(HPos::Center, VPos::Top)),
            ))?;
        }
        y += BAR_HEIGHT + TEXT_LINE + 8;
    }
    for line in captions {
        root.draw(&Text::new(
            line.clone(),
            p(MARGIN, y + 2),
            font(15.0).color(&RGBColor(60, 60, 60)).pos(top_left),
        ))?;
        y += TEXT_LINE;
    }
    root.present()
}
