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
//! rasterised here with ab_glyph (`BitmapWithText`). The PNGs therefore come out the same
//! on a machine with no fonts installed. The SVGs name the family `sans-serif` and leave the
//! glyphs to the viewer, as SVG text always does.
//!
//! Bad data never panics: points that are not finite, or not positive on a log axis, are
//! left out (the plot says how many); an empty series list gives a valid plot that says
//! there is no data.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::element::{DashedPathElement, EmptyElement, PathElement, Polygon, Rectangle, Text};
use plotters::prelude::{
    BitMapBackend, ChartBuilder, Circle, DrawingArea, DrawingAreaErrorKind, DrawingBackend,
    IntoDrawingArea, SVGBackend, SeriesLabelPosition,
};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{
    BLACK, Color, FontStyle, IntoFont, RGBColor, TextStyle, WHITE, register_font,
};
use plotters_backend::{BackendColor, BackendCoord, BackendTextStyle, DrawingErrorKind};

use crate::error::{Error, Result};
use crate::image::Image;
use crate::io::atomic::write_file_atomically;
use crate::io::png::srgb_to_u8;
use crate::io::tonemap::Reinhard;

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

/// The size of the convergence and bias/variance plots, in pixels.
const PLOT_SIZE: (u32, u32) = (960, 640);
/// The font family every label is drawn in; registered with the embedded DejaVu Sans.
const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Okabe & Ito (2008), "Color Universal Design": colours told apart with every common
/// colour-vision deficiency; yellow last, as it is faint on white.
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
    RGBColor(240, 228, 66),  // yellow
];
const GUIDE_COLOR: RGBColor = RGBColor(90, 90, 90);
const NOTE_COLOR: RGBColor = RGBColor(150, 40, 40);
/// Non-finite values in an error map (and, through `io::tonemap`, in an image).
const INVALID_COLOR: [u8; 3] = [255, 0, 255];

/// Registers the embedded font once per process.
fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok {
        Ok(())
    } else {
        Err(Error::usage(
            "the embedded font DejaVu Sans could not be read",
        ))
    }
}

fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().color(&BLACK)
}

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

// ---------------------------------------------------------------------------------------
// Text on bitmaps
// ---------------------------------------------------------------------------------------

/// The embedded font, parsed once.
fn dejavu_sans() -> Result<&'static FontRef<'static>> {
    static FONT_REF: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT_REF
        .get_or_init(|| FontRef::try_from_slice(DEJAVU_SANS).ok())
        .as_ref()
        .ok_or_else(|| Error::usage("the embedded font DejaVu Sans could not be read"))
}

/// plotters' bitmap backend with text drawn by mltbench: plotters 0.3.7's own ab_glyph text
/// drops each glyph's left side bearing, which leaves gaps inside words ("th e"). Here every
/// glyph is placed at its pen position plus bearing, with kerning, and blended by coverage.
/// All other drawing goes straight to the bitmap backend.
struct BitmapWithText<'a> {
    inner: BitMapBackend<'a>,
    font: &'static FontRef<'static>,
}

type BitmapError<'a> = DrawingErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>;

impl BitmapWithText<'_> {
    /// Width, height (ascent − descent) and ascent of `text` at `size` pixels.
    fn measure(&self, text: &str, size: f64) -> (f32, f32, f32) {
        let font = self.font.as_scaled(PxScale::from(size as f32));
        let mut width = 0.0;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                width += font.kern(p, id);
            }
            width += font.h_advance(id);
            prev = Some(id);
        }
        (width, font.ascent() - font.descent(), font.ascent())
    }
}

impl<'a> DrawingBackend for BitmapWithText<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: plotters_backend::BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: plotters_backend::BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> std::result::Result<(), BitmapError<'a>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> std::result::Result<(u32, u32), BitmapError<'a>> {
        let (w, h, _) = self.measure(text, style.size());
        Ok((w.ceil() as u32, h.ceil() as u32))
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> std::result::Result<(), BitmapError<'a>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let (width, height, ascent) = self.measure(text, style.size());
        // The anchor is a point of the text's box (advance width × ascent−descent).
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0.0,
            HPos::Center => -0.5 * width,
            HPos::Right => -width,
        };
        let dy = match anchor.v_pos {
            VPos::Top => 0.0,
            VPos::Center => -0.5 * height,
            VPos::Bottom => -height,
        };
        let transform = style.transform();
        let font = self.font.as_scaled(PxScale::from(style.size() as f32));
        let mut pen = dx.round();
        let mut prev = None;
        let mut result = Ok(());
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                pen += font.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(font.scale(), point(pen, (ascent + dy).round()));
            pen += font.h_advance(id);
            let Some(outline) = font.outline_glyph(glyph) else {
                continue; // a space
            };
            let bounds = outline.px_bounds();
            let inner = &mut self.inner;
            outline.draw(|x, y, coverage| {
                if result.is_err() || coverage <= 0.0 {
                    return;
                }
                let (gx, gy) = (
                    bounds.min.x as i32 + x as i32,
                    bounds.min.y as i32 + y as i32,
                );
                let (tx, ty) = transform.transform(gx, gy);
                let pixel = BackendColor {
                    alpha: color.alpha * coverage.min(1.0) as f64,
                    rgb: color.rgb,
                };
                result = inner.draw_pixel((pos.0 + tx, pos.1 + ty), pixel);
            });
            if result.is_err() {
                break;
            }
        }
        result
    }
}

// ---------------------------------------------------------------------------------------
// Log-log plots
// ---------------------------------------------------------------------------------------

/// A point of a curve in log10 coordinates; `lo`/`hi` are None where the band is unknown,
/// and `lo` is −∞ where the band reaches zero.
#[derive(Clone, Copy, Debug)]
struct LogPoint {
    x: f64,
    mean: f64,
    lo: Option<f64>,
    hi: Option<f64>,
}

struct Curve {
    label: Option<String>,
    color: RGBColor,
    dashed: bool,
    points: Vec<LogPoint>,
}

/// The points of `band` that can go on log-log axes, sorted by x, and how many were left out.
fn log_points(band: &Band) -> (Vec<LogPoint>, usize) {
    let n = band.x.len().max(band.mean.len());
    let usable = |v: f64| v.is_finite() && v > 0.0;
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        let (Some(&x), Some(&mean)) = (band.x.get(i), band.mean.get(i)) else {
            continue;
        };
        if !usable(x) || !usable(mean) {
            continue;
        }
        let lo = band.lo.get(i).copied().and_then(|v| {
            if usable(v) {
                Some(v.log10().min(mean.log10()))
            } else if v.is_finite() {
                Some(f64::NEG_INFINITY) // the band reaches zero
            } else {
                None
            }
        });
        let hi = band
            .hi
            .get(i)
            .copied()
            .filter(|&v| usable(v))
            .map(|v| v.log10().max(mean.log10()));
        points.push(LogPoint {
            x: x.log10(),
            mean: mean.log10(),
            lo,
            hi,
        });
    }
    points.sort_by(|a, b| a.x.total_cmp(&b.x));
    let left_out = n - points.len();
    (points, left_out)
}

/// One axis in log10 units: its range, the decades (or 1-2-5 steps) that carry a label and
/// a grid line, and the light grid lines between them.
#[derive(Clone, Debug)]
struct LogAxis {
    lo: f64,
    hi: f64,
    bold: Vec<f64>,
    light: Vec<f64>,
    /// Label ticks as plain numbers (0.2, 0.5, 1) rather than powers of ten: for axes
    /// spanning less than two decades within 10⁻³…10⁴.
    plain: bool,
}

impl LogAxis {
    /// An axis covering `[min, max]` (log10) with a little room on both sides, or
    /// `[empty.0, empty.1]` when there is nothing to cover.
    fn covering(min: f64, max: f64, empty: (f64, f64)) -> LogAxis {
        let (mut lo, mut hi) = if min.is_finite() && max.is_finite() && min <= max {
            (min, max)
        } else {
            empty
        };
        // At least 0.3 decade, so that there is always a tick (1..9 × 10ⁿ are ≤ 0.3 apart).
        if hi - lo < 0.3 {
            let mid = 0.5 * (lo + hi);
            lo = mid - 0.15;
            hi = mid + 0.15;
        }
        let pad = 0.04 * (hi - lo);
        let (lo, hi) = (lo - pad, hi + pad);
        let (bold, light, decades) = log_ticks(lo, hi);
        LogAxis {
            lo,
            hi,
            bold,
            light,
            plain: !decades && lo >= -3.5 && hi <= 4.5,
        }
    }

    fn clamp(&self, v: f64) -> f64 {
        v.clamp(self.lo, self.hi)
    }
}

/// A log axis is a linear plotters axis over log10 values, with our own tick positions.
impl Ranged for LogAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value - self.lo) / (self.hi - self.lo);
        if !t.is_finite() {
            return if t > 0.0 { limit.1 } else { limit.0 };
        }
        limit.0 + ((limit.1 - limit.0) as f64 * t).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Labelled and light tick positions (log10) for a log axis over `[lo, hi]`: every decade
/// labelled when there are two or more (every second, third… when there are many), else
/// 1, 2 and 5 × 10ⁿ, else every integer mantissa. The flag says whether the labels are
/// decades only.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>, bool) {
    let inside = |v: f64| v >= lo - 1e-9 && v <= hi + 1e-9;
    let first = lo.floor() as i64;
    let last = hi.ceil() as i64;
    let decades: Vec<i64> = (first..=last).filter(|&n| inside(n as f64)).collect();
    let mantissa_ticks = |mantissas: &[u32]| -> Vec<f64> {
        (first..=last)
            .flat_map(|n| {
                mantissas
                    .iter()
                    .map(move |&m| n as f64 + (m as f64).log10())
            })
            .filter(|&v| inside(v))
            .collect()
    };
    if decades.len() >= 2 {
        let step = decades.len().div_ceil(8) as i64;
        let bold: Vec<f64> = decades
            .iter()
            .filter(|&&n| n.rem_euclid(step) == 0)
            .map(|&n| n as f64)
            .collect();
        let light = if step == 1 {
            mantissa_ticks(&[2, 3, 4, 5, 6, 7, 8, 9])
        } else {
            decades
                .iter()
                .filter(|&&n| n.rem_euclid(step) != 0)
                .map(|&n| n as f64)
                .collect()
        };
        return (bold, light, true);
    }
    let bold = mantissa_ticks(&[1, 2, 5]);
    if bold.len() >= 2 {
        return (bold, mantissa_ticks(&[3, 4, 6, 7, 8, 9]), false);
    }
    (
        mantissa_ticks(&[1, 2, 3, 4, 5, 6, 7, 8, 9]),
        Vec::new(),
        false,
    )
}

/// An integer as Unicode superscript digits (DejaVu Sans has all of them).
fn superscript(n: i64) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// The label of a tick at log10 value `v` (always m × 10ⁿ with a whole mantissa m):
/// "10ⁿ" on a decade and "m×10ⁿ" between, or the plain decimal ("0.02", "5", "300").
fn tick_label(v: f64, plain: bool) -> String {
    let mut n = v.floor();
    let mut m = 10f64.powf(v - n).round() as i64;
    if m >= 10 {
        (m, n) = (1, n + 1.0);
    }
    let n = n as i64;
    if plain {
        return if n >= 0 {
            format!("{m}{}", "0".repeat(n as usize))
        } else {
            format!("0.{}{m}", "0".repeat((-n - 1) as usize))
        };
    }
    if m == 1 {
        format!("10{}", superscript(n))
    } else {
        format!("{m}×10{}", superscript(n))
    }
}

/// A guide line from one point to another (log10 coordinates), with its label.
type GuideSegment<'a> = ((f64, f64), (f64, f64), &'a str);

/// Everything a log-log figure shows.
struct LogLogFigure {
    title: String,
    x_label: String,
    y_label: String,
    curves: Vec<Curve>,
    /// Slope and label of each guide line.
    guides: Vec<(f64, String)>,
    /// Extra legend entries explaining line styles: (text, dashed).
    styles: Vec<(String, bool)>,
    /// Points left out because they were not finite and positive.
    left_out: usize,
    x_axis: LogAxis,
    y_axis: LogAxis,
}

impl LogLogFigure {
    fn new(
        title: &str,
        x_label: &str,
        y_label: &str,
        curves: Vec<Curve>,
        guides: Vec<(f64, String)>,
        styles: Vec<(String, bool)>,
        left_out: usize,
    ) -> Self {
        let points = || curves.iter().flat_map(|c| c.points.iter());
        let (x_min, x_max) = min_max(points().map(|p| p.x));
        let (mean_min, mean_max) = min_max(points().map(|p| p.mean));
        // The band widens the axis by at most a decade: a confidence bound that nearly
        // touches zero would otherwise squash every curve into the top of the plot.
        let (lo_min, _) = min_max(points().filter_map(|p| p.lo).filter(|v| v.is_finite()));
        let (_, hi_max) = min_max(points().filter_map(|p| p.hi));
        let y_min = if lo_min.is_finite() {
            lo_min.max(mean_min - 1.0).min(mean_min)
        } else {
            mean_min
        };
        let y_max = if hi_max.is_finite() {
            hi_max.min(mean_max + 1.0).max(mean_max)
        } else {
            mean_max
        };
        LogLogFigure {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            x_axis: LogAxis::covering(x_min, x_max, (0.0, 2.0)),
            y_axis: LogAxis::covering(y_min, y_max, (-3.0, 0.0)),
            curves,
            guides,
            styles,
            left_out,
        }
    }

    fn is_empty(&self) -> bool {
        self.curves.iter().all(|c| c.points.is_empty())
    }

    /// The guide lines as segments in log10 coordinates, clipped to the axes: each goes
    /// through the first point of the first curve with data, to the right.
    fn guide_segments(&self) -> Vec<GuideSegment<'_>> {
        let Some(anchor) = self.curves.iter().find_map(|c| c.points.first()) else {
            return Vec::new();
        };
        let (x0, y0) = (anchor.x, anchor.mean);
        let (ylo, yhi) = (self.y_axis.lo, self.y_axis.hi);
        let mut out = Vec::new();
        for (slope, label) in &self.guides {
            if !slope.is_finite() {
                continue;
            }
            let mut x1 = self.x_axis.hi;
            if *slope < 0.0 {
                x1 = x1.min(x0 + (ylo - y0) / slope);
            } else if *slope > 0.0 {
                x1 = x1.min(x0 + (yhi - y0) / slope);
            }
            if x1 > x0 {
                out.push(((x0, y0), (x1, y0 + slope * (x1 - x0)), label.as_str()));
            }
        }
        out
    }

    /// The corner of the plot with the fewest data and guide points, for the legend.
    fn legend_corner(&self) -> SeriesLabelPosition {
        let (xa, ya) = (&self.x_axis, &self.y_axis);
        let mut samples: Vec<(f64, f64)> = Vec::new();
        for c in &self.curves {
            for p in &c.points {
                samples.push((
                    (p.x - xa.lo) / (xa.hi - xa.lo),
                    (p.mean - ya.lo) / (ya.hi - ya.lo),
                ));
            }
        }
        for ((x0, y0), (x1, y1), _) in self.guide_segments() {
            for i in 0..=20 {
                let t = i as f64 / 20.0;
                let (x, y) = (x0 + t * (x1 - x0), y0 + t * (y1 - y0));
                samples.push(((x - xa.lo) / (xa.hi - xa.lo), (y - ya.lo) / (ya.hi - ya.lo)));
            }
        }
        // (position, right side?, top side?), in order of preference.
        let corners = [
            (SeriesLabelPosition::UpperRight, true, true),
            (SeriesLabelPosition::LowerLeft, false, false),
            (SeriesLabelPosition::LowerRight, true, false),
            (SeriesLabelPosition::UpperLeft, false, true),
        ];
        let count = |right: bool, top: bool| {
            samples
                .iter()
                .filter(|&&(u, v)| {
                    (if right { u > 0.55 } else { u < 0.45 })
                        && (if top { v > 0.6 } else { v < 0.4 })
                })
                .count()
        };
        let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
        for (pos, right, top) in corners {
            let n = count(right, top);
            if n < best.0 {
                best = (n, pos);
            }
        }
        best.1
    }
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Draws `fig` on `root` (the same code for the bitmap and the SVG backend).
fn draw_loglog<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &LogLogFigure,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (xa, ya) = (&fig.x_axis, &fig.y_axis);
    let mut chart = ChartBuilder::on(root)
        .caption(&fig.title, font(24.0))
        .margin(18)
        .x_label_area_size(58)
        .y_label_area_size(84)
        .build_cartesian_2d(xa.clone(), ya.clone())?;
    let x_fmt = |v: &f64| tick_label(*v, xa.plain);
    let y_fmt = |v: &f64| tick_label(*v, ya.plain);
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(font(17.0))
        .axis_desc_style(font(18.0))
        .bold_line_style(RGBColor(205, 205, 205).stroke_width(1))
        .light_line_style(RGBColor(236, 236, 236).stroke_width(1))
        .axis_style(BLACK.mix(0.8).stroke_width(1))
        .draw()?;

    // Bands first, so that every line lies on top of every band.
    for curve in &fig.curves {
        if let [p] = curve.points[..] {
            // One point: its band as a bar.
            let bar = vec![
                (p.x, ya.clamp(p.lo.unwrap_or(p.mean))),
                (p.x, ya.clamp(p.hi.unwrap_or(p.mean))),
            ];
            chart.draw_series(std::iter::once(PathElement::new(
                bar,
                curve.color.mix(0.3).stroke_width(8),
            )))?;
        }
        if curve.points.len() < 2 {
            continue;
        }
        let upper = curve
            .points
            .iter()
            .map(|p| (p.x, ya.clamp(p.hi.unwrap_or(p.mean))));
        let lower = curve
            .points
            .iter()
            .rev()
            .map(|p| (p.x, ya.clamp(p.lo.unwrap_or(p.mean))));
        let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
        chart.draw_series(std::iter::once(Polygon::new(
            outline,
            curve.color.mix(0.18).filled(),
        )))?;
    }

    let guides = fig.guide_segments();
    for &((x0, y0), (x1, y1), _) in &guides {
        chart.draw_series(std::iter::once(DashedPathElement::new(
            vec![(x0, y0), (x1, y1)],
            9,
            6,
            GUIDE_COLOR.stroke_width(2),
        )))?;
    }

    for curve in &fig.curves {
        if curve.points.is_empty() {
            // Still named in the legend, so that a missing estimator does not go unnoticed.
            if let Some(label) = &curve.label {
                let color = curve.color;
                chart
                    .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
                    .label(format!("{label} (no data)"))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], color.mix(0.4).stroke_width(3))
                    });
            }
            continue;
        }
        let line: Vec<(f64, f64)> = curve.points.iter().map(|p| (p.x, p.mean)).collect();
        let style = curve.color.stroke_width(3);
        let annotation = if curve.dashed {
            chart.draw_series(std::iter::once(DashedPathElement::new(
                line.clone(),
                12,
                7,
                style,
            )))?
        } else {
            chart.draw_series(std::iter::once(PathElement::new(line.clone(), style)))?
        };
        if let Some(label) = &curve.label {
            let color = curve.color;
            annotation.label(label.as_str()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(3))
            });
        }
        chart.draw_series(
            line.iter()
                .map(|&p| Circle::new(p, 3, curve.color.filled())),
        )?;
    }

    // Guide labels on top of the curves, on a light patch: on the line 70% of the way along
    // (in log space), just above it.
    for &((x0, y0), (x1, y1), label) in &guides {
        let t = 0.7;
        let at = chart.backend_coord(&(x0 + t * (x1 - x0), y0 + t * (y1 - y0)));
        let style = font(16.0)
            .color(&GUIDE_COLOR)
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        let (w, h) = root.estimate_text_size(label, &style)?;
        let (x, y) = (at.0 + 6, at.1 - 5);
        root.draw(&Rectangle::new(
            [(x - 3, y - h as i32 - 2), (x + w as i32 + 3, y + 2)],
            WHITE.mix(0.8).filled(),
        ))?;
        root.draw(&Text::new(label.to_string(), (x, y), style))?;
    }

    for (text, dashed) in &fig.styles {
        let dashed = *dashed;
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
            .label(text.as_str())
            .legend(move |(x, y)| {
                // Three pieces: touching for a solid line, with gaps for a dashed one.
                let pieces = if dashed {
                    [(0, 6), (9, 15), (18, 24)]
                } else {
                    [(0, 8), (8, 16), (16, 24)]
                };
                let piece = |(a, b): (i32, i32)| {
                    PathElement::new(vec![(a, 0), (b, 0)], BLACK.stroke_width(2))
                };
                EmptyElement::at((x, y)) + piece(pieces[0]) + piece(pieces[1]) + piece(pieces[2])
            });
    }

    let has_legend = fig
        .curves
        .iter()
        .any(|c| c.label.is_some() && !c.points.is_empty())
        || !fig.styles.is_empty();
    if has_legend {
        chart
            .configure_series_labels()
            .position(fig.legend_corner())
            .margin(12)
            .label_font(font(17.0))
            .background_style(WHITE.mix(0.88))
            .border_style(BLACK.mix(0.35))
            .draw()?;
    }

    if fig.is_empty() {
        let style = font(18.0)
            .color(&NOTE_COLOR)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let centre = (0.5 * (xa.lo + xa.hi), 0.5 * (ya.lo + ya.hi));
        chart.draw_series(std::iter::once(Text::new("no data to plot", centre, style)))?;
    }
    if fig.left_out > 0 {
        // Under the plot, at the right, beside the x axis label.
        let s = if fig.left_out == 1 { "" } else { "s" };
        let text = format!("{} point{s} not finite or ≤ 0 left out", fig.left_out);
        let style = font(15.0)
            .color(&NOTE_COLOR)
            .pos(Pos::new(HPos::Right, VPos::Bottom));
        let (w, h) = root.dim_in_pixel();
        root.draw(&Text::new(text, (w as i32 - 18, h as i32 - 10), style))?;
    }
    root.present()
}

/// Renders `fig` to `STEM.png` and `STEM.svg`.
fn write_loglog(stem: &Path, fig: &LogLogFigure) -> Result<()> {
    ensure_font()?;
    let (png_path, svg_path) = (with_extension(stem, "png"), with_extension(stem, "svg"));
    let (w, h) = PLOT_SIZE;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let backend = BitmapWithText {
            inner: BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE),
            font: dejavu_sans()?,
        };
        let root = backend.into_drawing_area();
        draw_loglog(&root, fig).map_err(|e| draw_error(&png_path, e))?;
    }
    let png = encode_png(&png_path, &rgb, w, h)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, PLOT_SIZE).into_drawing_area();
        draw_loglog(&root, fig).map_err(|e| draw_error(&svg_path, e))?;
    }
    write_file_atomically(&png_path, &png)?;
    write_file_atomically(&svg_path, svg.as_bytes())
}

/// A log-log plot of one or more series (e.g. relMSE against seconds or passes), written to
/// `STEM.png` and `STEM.svg`: one coloured line per series through its means, with its band
/// `lo..hi` shaded, a legend, and a dashed guide line for each `(slope, label)` in `guides`
/// (e.g. `(-1.0, "slope −1")`), drawn through the first point of the first series so that it
/// sits beside the data. Axes are labelled at powers of ten.
pub fn convergence_plot(
    stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    guides: &[(f64, &str)],
) -> Result<()> {
    let mut left_out = 0;
    let curves = series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (points, n) = log_points(&s.band);
            left_out += n;
            Curve {
                label: Some(s.label.clone()),
                color: PALETTE[i % PALETTE.len()],
                dashed: false,
                points,
            }
        })
        .collect();
    let guides = guides.iter().map(|&(s, l)| (s, l.to_string())).collect();
    let fig = LogLogFigure::new(
        title,
        x_label,
        y_label,
        curves,
        guides,
        Vec::new(),
        left_out,
    );
    write_loglog(stem, &fig)
}

/// Bias² and variance of each estimator against time (or passes), on log-log axes, written
/// to `STEM.png` and `STEM.svg`: variance solid, bias² dashed, both with their bands, one
/// colour per estimator (series with the same label share it; the legend names each
/// estimator once and explains the two line styles). A bias² estimate ≤ 0 (the bias is
/// below what the runs can resolve) cannot go on a log axis: such points are left out and
/// the plot says how many.
pub fn bias_variance_plot(
    stem: &Path,
    title: &str,
    x_label: &str,
    series_bias: &[Series],
    series_var: &[Series],
) -> Result<()> {
    let mut labels: Vec<&str> = Vec::new();
    for s in series_var.iter().chain(series_bias) {
        if !labels.contains(&s.label.as_str()) {
            labels.push(&s.label);
        }
    }
    let color_of = |label: &str| {
        let i = labels.iter().position(|&l| l == label).unwrap_or(0);
        PALETTE[i % PALETTE.len()]
    };
    let mut left_out = 0;
    let mut named: Vec<&str> = Vec::new();
    let mut curves = Vec::new();
    for (s, dashed) in series_var
        .iter()
        .map(|s| (s, false))
        .chain(series_bias.iter().map(|s| (s, true)))
    {
        let (points, n) = log_points(&s.band);
        left_out += n;
        // Name each estimator once in the legend, on the first of its curves with data.
        let label = if !points.is_empty() && !named.contains(&s.label.as_str()) {
            named.push(&s.label);
            Some(s.label.clone())
        } else {
            None
        };
        curves.push(Curve {
            label,
            color: color_of(&s.label),
            dashed,
            points,
        });
    }
    let styles = vec![("variance".to_string(), false), ("bias²".to_string(), true)];
    let fig = LogLogFigure::new(
        title,
        x_label,
        "bias² (dashed), variance (solid)",
        curves,
        Vec::new(),
        styles,
        left_out,
    );
    write_loglog(stem, &fig)
}

// ---------------------------------------------------------------------------------------
// Contact sheet
// ---------------------------------------------------------------------------------------

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

/// Viridis (van der Walt & Smith, matplotlib, 2015; released under CC0): every 8th of its
/// 256 published sRGB entries and the last, as (entry, colour). Linear interpolation between
/// them stays within 1.7/255 of the full table.
const VIRIDIS: [(u8, [f32; 3]); 33] = [
    (0, [0.267004, 0.004874, 0.329415]),
    (8, [0.277018, 0.050344, 0.375715]),
    (16, [0.282327, 0.094955, 0.417331]),
    (24, [0.282884, 0.135920, 0.453427]),
    (32, [0.278826, 0.175490, 0.483397]),
    (40, [0.270595, 0.214069, 0.507052]),
    (48, [0.258965, 0.251537, 0.524736]),
    (56, [0.244972, 0.287675, 0.537260]),
    (64, [0.229739, 0.322361, 0.545706]),
    (72, [0.214298, 0.355619, 0.551184]),
    (80, [0.199430, 0.387607, 0.554642]),
    (88, [0.185556, 0.418570, 0.556753]),
    (96, [0.172719, 0.448791, 0.557885]),
    (104, [0.160665, 0.478540, 0.558115]),
    (112, [0.149039, 0.508051, 0.557250]),
    (120, [0.137770, 0.537492, 0.554906]),
    (128, [0.127568, 0.566949, 0.550556]),
    (136, [0.120565, 0.596422, 0.543611]),
    (144, [0.120638, 0.625828, 0.533488]),
    (152, [0.134692, 0.658636, 0.517649]),
    (160, [0.157851, 0.683765, 0.501686]),
    (168, [0.196571, 0.711827, 0.479221]),
    (176, [0.246070, 0.738910, 0.452024]),
    (184, [0.304148, 0.764704, 0.419943]),
    (192, [0.369214, 0.788888, 0.382914]),
    (200, [0.440137, 0.811138, 0.340967]),
    (208, [0.515992, 0.831158, 0.294279]),
    (216, [0.595839, 0.848717, 0.243329]),
    (224, [0.678489, 0.863742, 0.189503]),
    (232, [0.762373, 0.876424, 0.137064]),
    (240, [0.845561, 0.887322, 0.099702]),
    (248, [0.926106, 0.897330, 0.104071]),
    (255, [0.993248, 0.906157, 0.143936]),
];

/// The viridis colour at `t` ∈ [0, 1] (clamped), 8-bit sRGB.
pub fn viridis(t: f32) -> [u8; 3] {
    let pos = if t.is_nan() {
        0.0
    } else {
        t.clamp(0.0, 1.0) * 255.0
    };
    let k = VIRIDIS
        .windows(2)
        .position(|w| pos <= w[1].0 as f32)
        .unwrap_or(VIRIDIS.len() - 2);
    let ((i0, c0), (i1, c1)) = (VIRIDIS[k], VIRIDIS[k + 1]);
    let u = ((pos - i0 as f32) / (i1 - i0) as f32).clamp(0.0, 1.0);
    [0, 1, 2].map(|c| ((c0[c] + u * (c1[c] - c0[c])) * 255.0).round() as u8)
}

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
fn luminance(c: [f32; 3]) -> f64 {
    (0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64).max(0.0)
}

/// Reinhard's operator with the reference's exposure: the scale a/L̄w and L_white are those
/// the default operator picks for the reference, so that every image on the sheet is mapped
/// by the same curve and differences in brightness stay visible.
fn exposure_like(reference: &Image) -> impl Fn(&Image) -> Image {
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
fn resample<const N: usize>(
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
fn fit(w: u32, h: u32, box_w: u32, box_h: u32) -> (u32, u32) {
    let s = (box_w as f64 / w as f64).min(box_h as f64 / h as f64);
    let s = if s >= 1.0 { s.floor() } else { s };
    (
        ((w as f64 * s).round() as u32).max(1),
        ((h as f64 * s).round() as u32).max(1),
    )
}

/// An 8-bit RGB canvas the tiles are copied into before plotters adds text and outlines.
struct Canvas {
    width: u32,
    rgb: Vec<u8>,
}

impl Canvas {
    fn put(&mut self, x: u32, y: u32, w: u32, pixels: &[[u8; 3]]) {
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
