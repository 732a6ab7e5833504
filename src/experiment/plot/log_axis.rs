//! Logarithmic axes: a plotters axis over log10 values with ticks at powers of ten (or at
//! 1, 2, 5 × 10ⁿ on short ranges), labelled "10ⁿ" with Unicode superscripts.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

/// One axis in log10 units: its range, the decades (or 1-2-5 steps) that carry a label and
/// a grid line, and the light grid lines between them.
#[derive(Clone, Debug)]
pub(super) struct LogAxis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    bold: Vec<f64>,
    light: Vec<f64>,
    /// Label ticks as plain numbers (0.2, 0.5, 1) rather than powers of ten: for axes
    /// spanning less than two decades within 10⁻³…10⁴.
    pub(super) plain: bool,
}

impl LogAxis {
    /// An axis covering `[min, max]` (log10) with a little room on both sides, or
    /// `[empty.0, empty.1]` when there is nothing to cover.
    pub(super) fn covering(min: f64, max: f64, empty: (f64, f64)) -> LogAxis {
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

    pub(super) fn clamp(&self, v: f64) -> f64 {
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
pub(super) fn superscript(n: i64) -> String {
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
pub(super) fn tick_label(v: f64, plain: bool) -> String {
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
