//! The strategy pyramid of a bidirectional estimator (Veach 1997, fig. 10.4): one image per
//! strategy (s, t), a row per path length L = s + t − 1 and a column per s, so that a
//! researcher sees at a glance which strategy carries which light.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::Text;
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingBackend, IntoDrawingArea};
use plotters::style::RGBColor;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::sheet::{Canvas, exposure_like, fit, luminance, resample};
use super::text::{BitmapWithText, dejavu_sans, ensure_font, font};
use super::{DrawResult, draw_error, encode_png, with_extension};
use crate::error::{Error, Result};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::png::srgb_to_u8;

/// One cell of the pyramid.
pub struct PyramidCell<'a> {
    pub s: usize,
    pub t: usize,
    pub image: &'a Image,
}

/// The longest side of a cell's image, in pixels.
const CELL: u32 = 160;
const MARGIN: u32 = 16;
const GAP: u32 = 8;
const LABEL: u32 = 20;
const ROW_LABEL_WIDTH: u32 = 64;
const TEXT_LINE: u32 = 22;

/// Draws `cells` as a pyramid into `STEM.png`: rows by path length, columns by s, every
/// image tone mapped (Reinhard) with the exposure of `whole` (the estimator's image) so that
/// brightness compares across cells and with the whole. Each cell is labelled with its
/// (s, t) and the share of `whole`'s mean luminance it holds. `title` goes on top. Every
/// image must have `whole`'s size.
pub fn strategy_pyramid(
    stem: &Path,
    title: &str,
    whole: &Image,
    cells: &[PyramidCell],
) -> Result<()> {
    ensure_font()?;
    let png_path = with_extension(stem, "png");
    let (w, h) = (whole.width, whole.height);
    if w == 0 || h == 0 {
        return Err(Error::usage("an empty image has no strategy pyramid"));
    }
    for c in cells {
        if (c.image.width, c.image.height) != (w, h) || c.t == 0 {
            return Err(Error::usage(format!(
                "strategy ({}, {}): a {}×{} image for a {w}×{h} pyramid",
                c.s, c.t, c.image.width, c.image.height
            )));
        }
    }
    let max_length = cells
        .iter()
        .map(|c| c.s + c.t - 1)
        .max()
        .unwrap_or(1)
        .max(1);
    let (tw, th) = fit(w, h, CELL, CELL);
    let columns = max_length as u32 + 1;
    let width = 2 * MARGIN + ROW_LABEL_WIDTH + columns * (tw + GAP);
    let rows_top = MARGIN + 2 * TEXT_LINE;
    let row_height = th + LABEL + GAP;
    let height = rows_top + max_length as u32 * row_height + TEXT_LINE + MARGIN;
    let cell_x = |s: usize| MARGIN + ROW_LABEL_WIDTH + s as u32 * (tw + GAP);
    let cell_y = |length: usize| rows_top + (length as u32 - 1) * row_height + LABEL;

    let mean_luminance = |image: &Image| image.pixels.iter().map(|c| luminance(c.0)).sum::<f64>();
    let total = mean_luminance(whole);
    let tonemap = exposure_like(whole);
    let mut canvas = Canvas {
        width,
        rgb: vec![255; width as usize * height as usize * 3],
    };
    let mut labels = Vec::with_capacity(cells.len());
    for c in cells {
        let length = c.s + c.t - 1;
        let display = tonemap(c.image);
        let linear: Vec<[f32; 3]> = display.pixels.iter().map(|p| p.0).collect();
        let tile = resample(
            &linear,
            w as usize,
            (0, 0, w as usize, h as usize),
            (tw as usize, th as usize),
        );
        let rgb: Vec<[u8; 3]> = tile.iter().map(|p| p.map(srgb_to_u8)).collect();
        canvas.put(cell_x(c.s), cell_y(length), tw, &rgb);
        let share = if total > 0.0 {
            format!(" {:.1}%", 100.0 * mean_luminance(c.image) / total)
        } else {
            String::new()
        };
        labels.push((
            cell_x(c.s),
            cell_y(length) - LABEL,
            format!("s={} t={}{share}", c.s, c.t),
        ));
    }
    {
        let backend = BitmapWithText {
            inner: BitMapBackend::with_buffer(&mut canvas.rgb, (width, height)),
            font: dejavu_sans()?,
        };
        let root = backend.into_drawing_area();
        let layout = Layout {
            title,
            columns,
            max_length,
            tile_height: th,
            height,
            labels: &labels,
        };
        draw_text(&root, &layout, cell_x, cell_y).map_err(|e| draw_error(&png_path, e))?;
    }
    let png = encode_png(&png_path, &canvas.rgb, width, height)?;
    write_file_atomically(&png_path, &png)
}

/// What the text of a pyramid needs to know.
struct Layout<'a> {
    title: &'a str,
    columns: u32,
    max_length: usize,
    tile_height: u32,
    height: u32,
    /// (x, y, text) of each cell's label.
    labels: &'a [(u32, u32, String)],
}

fn draw_text<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    l: &Layout,
    cell_x: impl Fn(usize) -> u32,
    cell_y: impl Fn(usize) -> u32,
) -> DrawResult<DB> {
    let top_left = Pos::new(HPos::Left, VPos::Top);
    let at = |x: u32, y: u32| (x as i32, y as i32);
    root.draw(&Text::new(
        l.title.to_string(),
        at(MARGIN, MARGIN),
        font(17.0).pos(top_left),
    ))?;
    for s in 0..l.columns as usize {
        root.draw(&Text::new(
            format!("s = {s}"),
            at(cell_x(s), MARGIN + TEXT_LINE + 2),
            font(15.0).pos(top_left),
        ))?;
    }
    for length in 1..=l.max_length {
        root.draw(&Text::new(
            format!("L = {length}"),
            at(MARGIN, cell_y(length) + l.tile_height / 2),
            font(15.0).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    for (x, y, text) in l.labels {
        root.draw(&Text::new(
            text.clone(),
            at(*x, *y + 3),
            font(13.0).pos(top_left),
        ))?;
    }
    root.draw(&Text::new(
        "L: path length (segments); s light and t camera vertices; %: share of the whole \
         image's mean luminance. Tone mapped with the whole image's exposure."
            .to_string(),
        at(MARGIN, l.height - MARGIN - TEXT_LINE + 4),
        font(13.0).color(&RGBColor(60, 60, 60)).pos(top_left),
    ))?;
    root.present()
}
