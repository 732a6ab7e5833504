//! Pearson's χ² helpers shared by the statistical tests: the test against the uniform
//! distribution, and equiprobable bins on a grid of cells.
#![allow(dead_code)] // each test binary uses its own part

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Pearson's χ² of `counts` against the equal expected count `total / counts.len()` in
/// every cell: (statistic, degrees of freedom, p-value).
pub fn pearson_uniform(counts: &[u64], total: f64) -> (f64, f64, f64) {
    let expected = total / counts.len() as f64;
    let stat: f64 = counts
        .iter()
        .map(|&c| (c as f64 - expected).powi(2) / expected)
        .sum();
    let dof = (counts.len() - 1) as f64;
    (stat, dof, 1.0 - ChiSquared::new(dof).unwrap().cdf(stat))
}

/// Cuts `0..weights.len()` into consecutive runs `(start, end)` whose weights add up to at
/// least `target` each; a short remainder joins the last run (or is the only run).
fn cut_runs(weights: &[f64], target: f64) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let (mut start, mut acc) = (0, 0.0);
    for (i, w) in weights.iter().enumerate() {
        acc += w;
        if acc >= target {
            runs.push((start, i + 1));
            start = i + 1;
            acc = 0.0;
        }
    }
    if start < weights.len() {
        match runs.last_mut() {
            Some(last) => last.1 = weights.len(),
            None => runs.push((start, weights.len())),
        }
    }
    runs
}

/// Bins for a χ² test on a `rows` × `cols` grid of cells (row-major `expected` counts out of
/// `total`), built from the expected counts only (never from the observed ones), so the
/// test statistic keeps its distribution. Rows are grouped into bands holding about 1/16 of
/// the samples each, and each band is cut along its columns into bins holding about 1/256:
/// nearly equiprobable bins that follow peaked lobes down to the cell size. Returns the bin
/// of each cell and the number of bins.
pub fn make_bins(rows: usize, cols: usize, expected: &[f64], total: f64) -> (Vec<usize>, usize) {
    let row_total: Vec<f64> = (0..rows)
        .map(|i| expected[i * cols..(i + 1) * cols].iter().sum())
        .collect();
    let mut bin_of_cell = vec![0usize; rows * cols];
    let mut n_bins = 0;
    for (r0, r1) in cut_runs(&row_total, total / 16.0) {
        let col_total: Vec<f64> = (0..cols)
            .map(|j| (r0..r1).map(|i| expected[i * cols + j]).sum())
            .collect();
        for (c0, c1) in cut_runs(&col_total, total / 256.0) {
            for i in r0..r1 {
                for j in c0..c1 {
                    bin_of_cell[i * cols + j] = n_bins;
                }
            }
            n_bins += 1;
        }
    }
    (bin_of_cell, n_bins)
}
