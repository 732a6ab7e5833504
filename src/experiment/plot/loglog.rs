//! Log-log plots: convergence curves (relMSE against time or passes) and bias² and variance
//! against time, each a line through the means with a band over runs.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::{DashedPathElement, EmptyElement, PathElement, Polygon, Rectangle, Text};
use plotters::prelude::{
    BitMapBackend, ChartBuilder, Circle, DrawingArea, DrawingBackend, IntoDrawingArea, SVGBackend,
    SeriesLabelPosition,
};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{BLACK, Color, RGBColor, WHITE};

use super::log_axis::{LogAxis, tick_label};
use super::text::{BitmapWithText, dejavu_sans, ensure_font, font};
use super::{Band, DrawResult, Series, draw_error, encode_png, with_extension};
use crate::error::Result;
use crate::io::atomic::write_file_atomically;

/// The size of the convergence and bias/variance plots, in pixels.
const PLOT_SIZE: (u32, u32) = (960, 640);

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
