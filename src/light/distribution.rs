//! Piecewise-constant distributions sampled by inverting their cumulative distribution:
//! a 1D one over n equal intervals of [0, 1) (or, read discretely, over n items), and a 2D
//! one over an image's cells as a marginal distribution over rows times a conditional
//! distribution within the chosen row ("inverse transform sampling for images"; Pharr,
//! Jakob & Humphreys, *Physically Based Rendering*, 3rd ed., §13.6.5–13.6.7).
//!
//! The cumulative sums are kept in f64: with a million cells an f32 sum would round small
//! cells to zero width, so they could never be drawn although their pdf is positive.

use glam::Vec2;

use crate::math::lanes::{F32x16, F64x8, Mask16, U32x16};

/// The largest f32 below one: sampled positions stay in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// `v.clamp(0.0, ONE_MINUS_EPSILON)` per lane.
#[inline(always)]
fn clamp_unit(v: F32x16) -> F32x16 {
    let v = F32x16::select(v.lt(F32x16::splat(0.0)), F32x16::splat(0.0), v);
    F32x16::select(
        v.gt(F32x16::splat(ONE_MINUS_EPSILON)),
        F32x16::splat(ONE_MINUS_EPSILON),
        v,
    )
}

/// Up to this many items `find` counts instead of searching.
const SMALL: usize = 16;

/// The most items `sample_discrete_lanes` samples in lanes (a light's triangles, a scene's
/// lights: one compare per item and lane).
pub const LANE_ITEMS: usize = 16;

/// A piecewise-constant density on [0, 1) with `n` equal intervals, proportional to the
/// weights it was built from; equally the discrete distribution with probabilities
/// weight_i / Σ weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// The weights, as given.
    func: Vec<f32>,
    /// cdf[i] = Σ_{k<i} func[k] / Σ func; cdf[0] = 0, cdf[n] = 1.
    cdf: Vec<f64>,
    /// Σ func (the integral of the step function over [0, 1) is sum / n).
    sum: f64,
    /// pmf[i] = func[i] / sum, rounded once to f32 (looked up by every light sample).
    pmf: Vec<f32>,
    /// For more than `SMALL` items, a guide table (Chen and Asau 1974): guide[g] is the
    /// number of cdf entries ≤ g / n, where a search for u in [g/n, (g+1)/n) starts.
    guide: Vec<u32>,
}

impl Distribution1D {
    /// None when there are no weights, a weight is negative or not finite, or all are zero.
    pub fn new(weights: &[f32]) -> Option<Distribution1D> {
        if weights.is_empty() || weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return None;
        }
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &w in weights {
            acc += w as f64;
            cdf.push(acc);
        }
        if !(acc > 0.0 && acc.is_finite()) {
            return None;
        }
        for c in &mut cdf {
            *c /= acc;
        }
        cdf[weights.len()] = 1.0;
        let n = weights.len();
        let guide = if n > SMALL {
            let mut count = 0usize;
            (0..n)
                .map(|g| {
                    let at = g as f64 / n as f64;
                    while count < cdf.len() && cdf[count] <= at {
                        count += 1;
                    }
                    count as u32
                })
                .collect()
        } else {
            Vec::new()
        };
        Some(Distribution1D {
            func: weights.to_vec(),
            cdf,
            sum: acc,
            pmf: weights.iter().map(|&w| (w as f64 / acc) as f32).collect(),
            guide,
        })
    }

    /// Equal weights over `n` ≥ 1 items.
    pub fn uniform(n: usize) -> Distribution1D {
        Distribution1D::new(&vec![1.0; n.max(1)]).expect("positive weights")
    }

    /// Number of intervals (items).
    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// The weight of item `i` as given.
    pub fn weight(&self, i: usize) -> f32 {
        self.func[i]
    }

    /// Σ weights.
    pub fn sum(&self) -> f64 {
        self.sum
    }

    /// This distribution as a `Row` (what sampling reads).
    #[inline(always)]
    fn row(&self) -> Row<'_> {
        Row {
            cdf: &self.cdf,
            guide: &self.guide,
            func: &self.func,
            sum: self.sum,
        }
    }

    /// Draws an item: (index, its probability, `u` rescaled to [0, 1) within the item's cdf
    /// interval, fresh for reuse).
    #[inline(always)]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let (i, remapped) = self.row().sample_discrete(u);
        // The probability as `pmf` computes it, so MIS weights see identical values.
        (i, self.pmf(i), remapped)
    }

    /// `sample_discrete` for the lanes of `m`, lane by lane the same bits (other lanes:
    /// index 0, pmf and remapped 0). For at most `LANE_ITEMS` items; more are sampled one
    /// lane at a time by `sample_discrete` itself.
    #[inline]
    pub fn sample_discrete_lanes(&self, u: F32x16, m: Mask16) -> (U32x16, F32x16, F32x16) {
        if self.func.len() > LANE_ITEMS {
            return self.sample_discrete_one_by_one(u, m);
        }
        let (index, u_lo, u_hi) = self.find_lanes(u);
        // cdf[index] and cdf[index + 1].
        let (mut lo, mut hi) = ([F64x8::splat(0.0); 2], [F64x8::splat(1.0); 2]);
        for k in 0..self.func.len() {
            let (at_lo, at_hi) = index.eq(U32x16::splat(k as u32)).halves();
            for (h, at) in [at_lo, at_hi].into_iter().enumerate() {
                lo[h] = F64x8::select(at, F64x8::splat(self.cdf[k]), lo[h]);
                hi[h] = F64x8::select(at, F64x8::splat(self.cdf[k + 1]), hi[h]);
            }
        }
        let zero = F64x8::splat(0.0);
        let remap = |u: F64x8, lo: F64x8, hi: F64x8| {
            let width = hi - lo;
            let positive = width.gt(zero);
            (F64x8::select(positive, (u - lo) / width, zero), positive)
        };
        let (r_lo, pos_lo) = remap(u_lo, lo[0], hi[0]);
        let (r_hi, pos_hi) = remap(u_hi, lo[1], hi[1]);
        let remapped = F32x16::select(
            Mask16::from_halves(pos_lo, pos_hi),
            F32x16::from_f64_halves(r_lo, r_hi),
            F32x16::splat(0.0),
        );
        let pmf = F32x16::gather(&self.pmf, index, m);
        let index = U32x16::select(m, index, U32x16::splat(0));
        let remapped = F32x16::select(m, clamp_unit(remapped), F32x16::splat(0.0));
        (index, pmf, remapped)
    }

    /// The item and its probability of `sample_discrete_lanes`, without the remapped `u`.
    #[inline]
    pub fn pick_lanes(&self, u: F32x16, m: Mask16) -> (U32x16, F32x16) {
        if self.func.len() > LANE_ITEMS {
            let (index, pmf, _) = self.sample_discrete_one_by_one(u, m);
            return (index, pmf);
        }
        let index = if self.func.len() == 1 {
            U32x16::splat(0)
        } else {
            self.find_lanes(u).0
        };
        let pmf = F32x16::gather(&self.pmf, index, m);
        (U32x16::select(m, index, U32x16::splat(0)), pmf)
    }

    /// `find` per lane for `u` clamped as `sample_discrete` clamps it; with that `u` in f64
    /// (lanes 0–7, 8–15).
    #[inline(always)]
    fn find_lanes(&self, u: F32x16) -> (U32x16, F64x8, F64x8) {
        let (u_lo, u_hi) = clamp_unit(u).to_f64_halves();
        // The number of cdf entries <= u, minus one, at most n − 1.
        let one = U32x16::splat(1);
        let mut count = U32x16::splat(0);
        for &c in &self.cdf {
            let c = F64x8::splat(c);
            let below = Mask16::from_halves(c.le(u_lo), c.le(u_hi));
            count = count + U32x16::select(below, one, U32x16::splat(0));
        }
        let index = U32x16::select(count.eq(U32x16::splat(0)), count, count - one);
        let last = U32x16::splat(self.func.len() as u32 - 1);
        (U32x16::select(last.lt(index), last, index), u_lo, u_hi)
    }

    /// `sample_discrete` lane after lane (for more than `LANE_ITEMS` items).
    fn sample_discrete_one_by_one(&self, u: F32x16, m: Mask16) -> (U32x16, F32x16, F32x16) {
        let u = u.to_array();
        let (mut index, mut pmf, mut remapped) = ([0u32; 16], [0.0f32; 16], [0.0f32; 16]);
        for i in m.lanes() {
            let (k, p, r) = self.sample_discrete(u[i]);
            (index[i], pmf[i], remapped[i]) = (k as u32, p, r);
        }
        (
            U32x16::from_array(index),
            F32x16::from_array(pmf),
            F32x16::from_array(remapped),
        )
    }

    /// Probability of item `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Draws x in [0, 1) with the step density: (x, density at x, interval index).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        self.row().sample_continuous(u)
    }

    /// `sample_continuous` for the lanes of `m`: (x, interval index), lane by lane the
    /// scalar bits (other lanes: 0).
    #[inline]
    pub fn sample_continuous_lanes(&self, u: F32x16, m: Mask16) -> (F32x16, U32x16) {
        let zero = U32x16::splat(0);
        let rows = StackedRows {
            cdf: &self.cdf,
            guide: &self.guide,
            n: self.func.len(),
        };
        rows.sample_continuous_lanes(zero, zero, u, m)
    }

    /// The density of interval `i`: n · weight_i / Σ weight.
    fn density(&self, i: usize) -> f32 {
        self.row().density(i)
    }

    /// The density at x (0 outside [0, 1)).
    pub fn pdf(&self, x: f32) -> f32 {
        if !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        let n = self.func.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        self.density(i)
    }
}

/// One distribution over n items as `find` and sampling read it: its cdf (n + 1 entries),
/// its guide table (n entries, none for at most `SMALL` items), its weights and their sum.
/// `Distribution1D` is one; `Distribution2D` keeps its rows' side by side.
#[derive(Clone, Copy)]
struct Row<'a> {
    cdf: &'a [f64],
    guide: &'a [u32],
    func: &'a [f32],
    sum: f64,
}

impl Row<'_> {
    /// The item whose cdf interval [cdf[i], cdf[i+1]) holds `u`. Never an item of weight 0
    /// (its interval is empty).
    #[inline(always)]
    fn find(&self, u: f64) -> usize {
        // Largest i with cdf[i] <= u, among 0..n: the number of cdf entries <= u, minus one
        // (the cdf does not decrease). A few items (a light's triangles, a scene's lights)
        // are counted without branches: a binary search there mispredicts half its steps.
        let n = self.func.len();
        let i = if n <= SMALL {
            self.cdf.iter().map(|&c| (c <= u) as usize).sum()
        } else {
            // The count of entries ≤ u, walked to from the guide's start for u's bucket:
            // exact whatever the rounding of the bucket's index, and a step or two on
            // average (a binary search over an environment map's rows and columns was
            // 6% of `pt`'s time there).
            let bucket = ((u * n as f64) as usize).min(n - 1);
            let mut i = self.guide[bucket] as usize;
            while i > 0 && self.cdf[i - 1] > u {
                i -= 1;
            }
            while i < self.cdf.len() && self.cdf[i] <= u {
                i += 1;
            }
            i
        };
        i.saturating_sub(1).min(n - 1)
    }

    /// Draws an item: (index, `u` rescaled to [0, 1) within the item's cdf interval).
    #[inline(always)]
    fn sample_discrete(&self, u: f32) -> (usize, f32) {
        let u = (u.clamp(0.0, ONE_MINUS_EPSILON)) as f64;
        let i = self.find(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let remapped = if width > 0.0 {
            ((u - self.cdf[i]) / width) as f32
        } else {
            0.0
        };
        (i, remapped.clamp(0.0, ONE_MINUS_EPSILON))
    }

    /// Draws x in [0, 1) with the step density: (x, density at x, interval index).
    #[inline(always)]
    fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, du) = self.sample_discrete(u);
        let n = self.func.len();
        let x = ((i as f32 + du) / n as f32).min(ONE_MINUS_EPSILON);
        (x, self.density(i), i)
    }

    /// The density of interval `i`: n · weight_i / Σ weight.
    #[inline(always)]
    fn density(&self, i: usize) -> f32 {
        (self.func[i] as f64 * self.func.len() as f64 / self.sum) as f32
    }
}

/// Rows of n items each side by side, as `Row::sample_continuous` reads them, for lanes
/// that each sample their own row: a row's cdf starts at a multiple of n + 1 in `cdf`, its
/// guide at a multiple of n in `guide`.
struct StackedRows<'a> {
    cdf: &'a [f64],
    guide: &'a [u32],
    n: usize,
}

impl StackedRows<'_> {
    /// `Row::sample_continuous` per lane of `m`, lane i in the row whose cdf starts at
    /// `cdf_start[i]` and guide at `guide_start[i]`: (x, interval index), the scalar bits
    /// (other lanes: 0).
    #[inline(always)]
    fn sample_continuous_lanes(
        &self,
        cdf_start: U32x16,
        guide_start: U32x16,
        u: F32x16,
        m: Mask16,
    ) -> (F32x16, U32x16) {
        let u = clamp_unit(u);
        let (u_lo, u_hi) = u.to_f64_halves();
        let i = self.find_lanes(cdf_start, guide_start, u, (u_lo, u_hi), m);
        // `Row::sample_discrete`'s remapping within the item's interval.
        let (lo_lo, lo_hi) = self.cdf_at(cdf_start + i, m);
        let (hi_lo, hi_hi) = self.cdf_at(cdf_start + i + U32x16::splat(1), m);
        let zero = F64x8::splat(0.0);
        let remap = |u: F64x8, lo: F64x8, hi: F64x8| {
            let width = hi - lo;
            let positive = width.gt(zero);
            (F64x8::select(positive, (u - lo) / width, zero), positive)
        };
        let (r_lo, pos_lo) = remap(u_lo, lo_lo, hi_lo);
        let (r_hi, pos_hi) = remap(u_hi, lo_hi, hi_hi);
        let du = F32x16::select(
            Mask16::from_halves(pos_lo, pos_hi),
            F32x16::from_f64_halves(r_lo, r_hi),
            F32x16::splat(0.0),
        );
        let du = clamp_unit(du);
        // `Row::sample_continuous`'s x.
        let n = F32x16::splat(self.n as f32);
        let x = ((i.to_f32() + du) / n).min_lt(F32x16::splat(ONE_MINUS_EPSILON));
        (
            F32x16::select(m, x, F32x16::splat(0.0)),
            U32x16::select(m, i, U32x16::splat(0)),
        )
    }

    /// `Row::find` per lane for `u` (clamped, in f32 and in f64 halves).
    #[inline(always)]
    fn find_lanes(
        &self,
        cdf_start: U32x16,
        guide_start: U32x16,
        u: F32x16,
        (u_lo, u_hi): (F64x8, F64x8),
        m: Mask16,
    ) -> U32x16 {
        let n = self.n as u32;
        let one = U32x16::splat(1);
        let at_most_u = |lo: F64x8, hi: F64x8| Mask16::from_halves(lo.le(u_lo), hi.le(u_hi));
        let above_u = |lo: F64x8, hi: F64x8| Mask16::from_halves(lo.gt(u_lo), hi.gt(u_hi));
        let count = if self.n <= SMALL {
            // Every entry counted, as the scalar code counts them.
            let mut count = U32x16::splat(0);
            for k in 0..=n {
                let (lo, hi) = self.cdf_at(cdf_start + U32x16::splat(k), m);
                count = count + U32x16::select(at_most_u(lo, hi), one, U32x16::splat(0));
            }
            count
        } else {
            // The walk from the guide's bucket. The bucket is found in f32 here, where the
            // scalar code uses f64: the walk ends at the same count from any start.
            let bucket = (u * F32x16::splat(self.n as f32))
                .to_u32()
                .min(U32x16::splat(n - 1));
            let mut i = U32x16::gather(self.guide, guide_start + bucket, m);
            loop {
                let previous = i - one;
                let (lo, hi) = self.cdf_at(cdf_start + previous, m);
                let down = m & !i.eq(U32x16::splat(0)) & above_u(lo, hi);
                if down.none() {
                    break;
                }
                i = U32x16::select(down, previous, i);
            }
            loop {
                let (lo, hi) = self.cdf_at(cdf_start + i, m);
                let up = m & i.lt(U32x16::splat(n + 1)) & at_most_u(lo, hi);
                if up.none() {
                    break;
                }
                i = U32x16::select(up, i + one, i);
            }
            i
        };
        // count.saturating_sub(1).min(n − 1)
        let index = U32x16::select(count.eq(U32x16::splat(0)), count, count - one);
        index.min(U32x16::splat(n - 1))
    }

    /// cdf[idx] in the lanes of `m`, as f64 halves (lanes 0–7, 8–15).
    #[inline(always)]
    fn cdf_at(&self, idx: U32x16, m: Mask16) -> (F64x8, F64x8) {
        let (idx_lo, idx_hi) = idx.to_u64_halves();
        let (m_lo, m_hi) = m.halves();
        (
            F64x8::gather(self.cdf, idx_lo, m_lo),
            F64x8::gather(self.cdf, idx_hi, m_hi),
        )
    }
}

/// A piecewise-constant density on [0, 1)² over an `nu` × `nv` grid of cells (row-major,
/// row index along v), proportional to the cell weights.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    /// Over rows, by row sums.
    marginal: Distribution1D,
    /// Each row's distribution over u, side by side (`StackedRows`): row v's cdf is
    /// `row_cdf[v·(nu + 1)..][..nu + 1]`, its guide `row_guide[v·nu..][..nu]` (none for
    /// nu ≤ `SMALL`), its weights `row_func[v·nu..][..nu]`, their sum `row_sum[v]`. A row of
    /// zero weight holds a uniform distribution (never drawn).
    row_cdf: Vec<f64>,
    row_guide: Vec<u32>,
    row_func: Vec<f32>,
    row_sum: Vec<f64>,
    nu: usize,
    nv: usize,
}

impl Distribution2D {
    /// `weights[v * nu + u]`. None when the sizes disagree, a weight is negative or not
    /// finite, or all are zero.
    pub fn new(weights: &[f32], nu: usize, nv: usize) -> Option<Distribution2D> {
        if nu == 0 || nv == 0 || weights.len() != nu.checked_mul(nv)? {
            return None;
        }
        if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return None;
        }
        let mut row_sums = Vec::with_capacity(nv);
        let (mut row_cdf, mut row_guide) = (Vec::new(), Vec::new());
        let (mut row_func, mut row_sum) = (Vec::with_capacity(nu * nv), Vec::with_capacity(nv));
        for row in weights.chunks_exact(nu) {
            let (d, sum) = match Distribution1D::new(row) {
                Some(d) => {
                    let sum = d.sum() as f32;
                    (d, sum)
                }
                None => (Distribution1D::uniform(nu), 0.0),
            };
            row_sums.push(sum);
            row_cdf.extend_from_slice(&d.cdf);
            row_guide.extend_from_slice(&d.guide);
            row_func.extend_from_slice(&d.func);
            row_sum.push(d.sum);
        }
        let marginal = Distribution1D::new(&row_sums)?;
        Some(Distribution2D {
            marginal,
            row_cdf,
            row_guide,
            row_func,
            row_sum,
            nu,
            nv,
        })
    }

    pub fn size(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }

    /// Row `v`'s distribution over u.
    #[inline(always)]
    fn row(&self, v: usize) -> Row<'_> {
        let guide = if self.row_guide.is_empty() {
            &self.row_guide[..]
        } else {
            &self.row_guide[v * self.nu..][..self.nu]
        };
        Row {
            cdf: &self.row_cdf[v * (self.nu + 1)..][..self.nu + 1],
            guide,
            func: &self.row_func[v * self.nu..][..self.nu],
            sum: self.row_sum[v],
        }
    }

    /// Draws (u, v) in [0, 1)²: the row by the marginal with `u.y`, then u within the row
    /// with `u.x`. Returns the point, its density on [0, 1)² and the cell (iu, iv).
    pub fn sample(&self, u: Vec2) -> (Vec2, f32, [usize; 2]) {
        let (v, pdf_v, iv) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, iu) = self.row(iv).sample_continuous(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u, [iu, iv])
    }

    /// `sample` for the lanes of `m`, without the density: (u, v, iu, iv), lane by lane
    /// the scalar bits (other lanes: 0).
    #[inline]
    pub fn sample_lanes(
        &self,
        ux: F32x16,
        uy: F32x16,
        m: Mask16,
    ) -> (F32x16, F32x16, U32x16, U32x16) {
        let (v, iv) = self.marginal.sample_continuous_lanes(uy, m);
        let rows = StackedRows {
            cdf: &self.row_cdf,
            guide: &self.row_guide,
            n: self.nu,
        };
        let nu = self.nu as u32;
        let (x, iu) =
            rows.sample_continuous_lanes(iv * U32x16::splat(nu + 1), iv * U32x16::splat(nu), ux, m);
        (x, v, iu, iv)
    }

    /// The density at (u, v) (0 outside [0, 1)²).
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)) {
            return 0.0;
        }
        let iu = ((p.x * self.nu as f32) as usize).min(self.nu - 1);
        let iv = ((p.y * self.nv as f32) as usize).min(self.nv - 1);
        self.cell_pdf(iu, iv)
    }

    /// The density in cell (iu, iv): nu · nv · weight / Σ weights.
    pub fn cell_pdf(&self, iu: usize, iv: usize) -> f32 {
        let w = self.row_func[iv * self.nu + iu] as f64;
        if self.marginal.weight(iv) == 0.0 {
            return 0.0;
        }
        (w * (self.nu * self.nv) as f64 / self.marginal.sum()) as f32
    }

    /// The probability of drawing a point in cell (iu, iv).
    pub fn cell_probability(&self, iu: usize, iv: usize) -> f32 {
        self.cell_pdf(iu, iv) / (self.nu * self.nv) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_sample_as_the_scalar_code_does() {
        let weights: Vec<Vec<f32>> = vec![
            vec![2.0],
            vec![1.0, 3.0],
            vec![0.0, 1.0, 0.0, 0.5, 1e-30],
            (0..16).map(|i| (i % 5) as f32).collect(),
            (0..40).map(|i| 1.0 + (i % 3) as f32).collect(),
        ];
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        for w in &weights {
            let d = Distribution1D::new(w).unwrap();
            for round in 0..2000 {
                let u: [f32; 16] = std::array::from_fn(|i| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    match (round + i) % 7 {
                        0 => 0.0,
                        1 => 1.0 - f32::EPSILON / 2.0,
                        2 => 1.0,
                        _ => (s >> 40) as f32 / (1u64 << 24) as f32,
                    }
                });
                let m = Mask16(0xffff ^ (1 << (round % 16)));
                let (index, pmf, remapped) = d.sample_discrete_lanes(F32x16::from_array(u), m);
                let picked = d.pick_lanes(F32x16::from_array(u), m);
                assert_eq!(picked.0.to_array(), index.to_array());
                assert_eq!(
                    picked.1.to_array().map(f32::to_bits),
                    pmf.to_array().map(f32::to_bits)
                );
                let (index, pmf, remapped) =
                    (index.to_array(), pmf.to_array(), remapped.to_array());
                for i in 0..16 {
                    let want = if m.get(i) {
                        d.sample_discrete(u[i])
                    } else {
                        (0, 0.0, 0.0)
                    };
                    let got = (index[i] as usize, pmf[i], remapped[i]);
                    assert_eq!(
                        (got.0, got.1.to_bits(), got.2.to_bits()),
                        (want.0, want.1.to_bits(), want.2.to_bits()),
                        "n {} u {}",
                        w.len(),
                        u[i]
                    );
                }
            }
        }
    }

    /// `Distribution2D::sample_lanes` gives each lane the cell and point of `sample`, on
    /// grids with few and many cells per row and rows (counted and walked finds), rows and
    /// cells of zero weight, and u at 0, just below 1, 1 and NaN; masked lanes read 0.
    #[test]
    fn two_d_lanes_sample_as_the_scalar_code_does() {
        let grids: [(usize, usize); 5] = [(1, 1), (2, 3), (16, 17), (40, 5), (33, 70)];
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        for (nu, nv) in grids {
            let weights: Vec<f32> = (0..nu * nv)
                .map(|k| match (k / nu % 4, k % 7) {
                    (1, _) if nv > 2 => 0.0, // whole rows of zero weight
                    (_, 3) => 0.0,
                    _ => 0.1 + next() * next() * 40.0,
                })
                .collect();
            let d = Distribution2D::new(&weights, nu, nv).unwrap();
            for round in 0..500 {
                let special = |k: usize, v: f32| match k % 9 {
                    0 => 0.0,
                    1 => ONE_MINUS_EPSILON,
                    2 => 1.0,
                    3 if round == 7 => f32::NAN,
                    _ => v,
                };
                let ux: [f32; 16] = std::array::from_fn(|i| special(round + i, next()));
                let uy: [f32; 16] = std::array::from_fn(|i| special(round + 2 * i + 1, next()));
                let m = Mask16(0xffff ^ (1 << (round % 16)));
                let (x, v, iu, iv) =
                    d.sample_lanes(F32x16::from_array(ux), F32x16::from_array(uy), m);
                let (x, v, iu, iv) = (x.to_array(), v.to_array(), iu.to_array(), iv.to_array());
                for i in 0..16 {
                    let want = if m.get(i) {
                        let (p, _, [a, b]) = d.sample(Vec2::new(ux[i], uy[i]));
                        (p.x.to_bits(), p.y.to_bits(), a as u32, b as u32)
                    } else {
                        (0, 0, 0, 0)
                    };
                    let got = (x[i].to_bits(), v[i].to_bits(), iu[i], iv[i]);
                    assert_eq!(got, want, "{nu}x{nv}, u ({}, {})", ux[i], uy[i]);
                }
            }
        }
    }

    #[test]
    fn discrete_probabilities_and_remapping() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]).unwrap();
        assert_eq!(d.pmf(0), 0.25);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.pmf(2), 0.75);
        // u in [0, 0.25) → item 0, [0.25, 1) → item 2; never the empty item 1.
        let (i, p, r) = d.sample_discrete(0.125);
        assert_eq!((i, p), (0, 0.25));
        assert!((r - 0.5).abs() < 1e-6);
        let (i, _, r) = d.sample_discrete(0.25);
        assert_eq!(i, 2);
        assert!(r.abs() < 1e-6);
        assert_eq!(d.sample_discrete(0.999_999_9).0, 2);
        assert_eq!(d.sample_discrete(1.0).0, 2);
    }

    #[test]
    fn counted_and_searched_items_agree() {
        // Sizes on both sides of SMALL, zero weights included: every u lands in the interval
        // [cdf[i], cdf[i+1]) of the item drawn, and never on an item of weight 0.
        for n in 1..=2 * SMALL + 1 {
            let weights: Vec<f32> = (0..n).map(|k| ((k * 7 + 3) % 5) as f32).collect();
            let Some(d) = Distribution1D::new(&weights) else {
                continue;
            };
            for j in 0..=1000 {
                let u = j as f32 / 1000.0;
                let (i, pmf, _) = d.sample_discrete(u);
                let uc = (u.clamp(0.0, ONE_MINUS_EPSILON)) as f64;
                assert!(
                    d.cdf[i] <= uc && uc < d.cdf[i + 1],
                    "n {n}, u {u}: item {i}"
                );
                assert!(
                    pmf > 0.0 && weights[i] > 0.0,
                    "n {n}, u {u}: item {i} of weight 0"
                );
            }
        }
    }

    #[test]
    fn the_guide_table_finds_what_a_binary_search_finds() {
        // Skewed weights (one heavy item, runs of zeros) so that buckets hold many items
        // or none; u at every cdf entry, just below and above it, and in between.
        for n in [SMALL + 1, 64, 1000] {
            let weights: Vec<f32> = (0..n)
                .map(|k| match k % 9 {
                    0..=2 => 0.0,
                    3 => 1e-6,
                    _ if k == n / 3 => 1e4,
                    _ => (k % 7) as f32 + 0.5,
                })
                .collect();
            let d = Distribution1D::new(&weights).unwrap();
            let mut us: Vec<f64> = d
                .cdf
                .iter()
                .flat_map(|&c| [c.next_down(), c, c.next_up()])
                .collect();
            us.extend((0..=4000).map(|j| j as f64 / 4000.0));
            for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                let expected = d
                    .cdf
                    .partition_point(|&c| c <= u)
                    .saturating_sub(1)
                    .min(n - 1);
                assert_eq!(d.row().find(u), expected, "n {n}, u {u}");
            }
        }
    }

    #[test]
    fn bad_weights_give_none() {
        assert!(Distribution1D::new(&[]).is_none());
        assert!(Distribution1D::new(&[0.0, 0.0]).is_none());
        assert!(Distribution1D::new(&[1.0, f32::NAN]).is_none());
        assert!(Distribution1D::new(&[1.0, -1.0]).is_none());
        assert!(Distribution1D::new(&[1.0, f32::INFINITY]).is_none());
        assert!(Distribution2D::new(&[1.0; 5], 2, 3).is_none());
        assert!(Distribution2D::new(&[0.0; 6], 2, 3).is_none());
    }

    #[test]
    fn continuous_density_matches_weights() {
        let d = Distribution1D::new(&[1.0, 2.0, 1.0]).unwrap();
        // density n · w / Σ w = 3 · w / 4
        assert!((d.pdf(0.1) - 0.75).abs() < 1e-6);
        assert!((d.pdf(0.5) - 1.5).abs() < 1e-6);
        let (x, pdf, i) = d.sample_continuous(0.5);
        assert_eq!(i, 1);
        assert!((x - 0.5).abs() < 1e-6);
        assert!((pdf - 1.5).abs() < 1e-6);
    }

    #[test]
    fn two_d_rows_of_zero_weight_are_never_drawn() {
        let w = [0.0, 0.0, 1.0, 3.0];
        let d = Distribution2D::new(&w, 2, 2).unwrap();
        for k in 0..100 {
            let u = Vec2::new((k as f32 + 0.5) / 100.0, (k as f32 * 0.37 + 0.1).fract());
            let (p, pdf, [iu, iv]) = d.sample(u);
            assert_eq!(iv, 1);
            assert!((d.pdf(p) - pdf).abs() < 1e-5 * pdf);
            assert!((d.cell_pdf(iu, iv) - pdf).abs() < 1e-5 * pdf);
        }
        assert_eq!(d.cell_pdf(0, 0), 0.0);
        // density nu·nv·w/Σw: 4·1/4 and 4·3/4
        assert!((d.cell_pdf(0, 1) - 1.0).abs() < 1e-6);
        assert!((d.cell_pdf(1, 1) - 3.0).abs() < 1e-6);
    }
}
