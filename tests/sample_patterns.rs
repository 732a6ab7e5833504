//! The 2D sample patterns: domain, strata, minimum distances, capacities, uniformity and
//! the (0,2)-net property. Fixed seeds throughout, so every run tests the same sets.

mod chi2_support;

use std::collections::HashSet;
use std::time::Instant;

use chi2_support::pearson_uniform;
use glam::Vec2;
use mltbench::sampler::pattern::{
    Pattern, cell_index, grid_side, max_packing_radius, min_toroidal_distance, points,
    toroidal_distance,
};
use mltbench::sampler::{ccvt, poisson, sobol};

fn in_unit_square(p: Vec2) -> bool {
    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)
}

/// The strata (cell pairs of a k×k grid) the points fall in; panics on a repeat.
fn assert_one_per_stratum(points: &[Vec2], k: usize, what: &str) {
    assert_eq!(points.len(), k * k, "{what}: point count");
    let mut seen = HashSet::new();
    for p in points {
        let cell = (cell_index(p.x, k), cell_index(p.y, k));
        assert!(cell.0 < k && cell.1 < k, "{what}: {p} outside the grid");
        assert!(seen.insert(cell), "{what}: two points in stratum {cell:?}");
    }
}

#[test]
fn names_round_trip() {
    for p in Pattern::ALL {
        assert_eq!(p.name().parse::<Pattern>(), Ok(p));
        assert_eq!(p.to_string(), p.name());
    }
    let err = "halton".parse::<Pattern>().unwrap_err();
    assert!(err.contains("sobol"), "{err}");
}

#[test]
fn every_pattern_lies_in_the_unit_square_and_is_deterministic() {
    for pattern in Pattern::ALL {
        for n in [0, 1, 2, 3, 7, 64, 100, 257, 1000] {
            if pattern == Pattern::Ccvt && n > 257 {
                continue; // the larger CCVT runs have their own test
            }
            for seed in [0, 1, 0xDEAD_BEEF] {
                let a = points(pattern, n, seed);
                if pattern == Pattern::Poisson {
                    assert!(a.len() <= n, "{pattern} n={n}: {} points", a.len());
                } else {
                    assert_eq!(a.len(), n, "{pattern} n={n}");
                }
                for p in &a {
                    assert!(in_unit_square(*p), "{pattern} n={n} seed={seed}: {p}");
                }
                assert_eq!(
                    a,
                    points(pattern, n, seed),
                    "{pattern} n={n} not deterministic"
                );
            }
            // Seeds matter, except for a pure grid.
            let random = !(pattern == Pattern::Regular && grid_side(n).pow(2) == n);
            if random && n >= 2 {
                assert_ne!(
                    points(pattern, n, 1),
                    points(pattern, n, 2),
                    "{pattern} n={n}"
                );
            }
        }
    }
}

#[test]
fn regular_grid_is_one_point_per_cell_at_the_centres() {
    for k in [1, 2, 3, 10, 32, 100] {
        let pts = points(Pattern::Regular, k * k, 7);
        assert_one_per_stratum(&pts, k, &format!("regular k={k}"));
        for p in &pts {
            for c in [p.x, p.y] {
                let centre = (cell_index(c, k) as f64 + 0.5) / k as f64;
                assert!((c as f64 - centre).abs() < 1e-6, "regular k={k}: {p}");
            }
        }
    }
    // Not a square: the largest grid first, then random points.
    let pts = points(Pattern::Regular, 1000, 7);
    assert_one_per_stratum(&pts[..961], 31, "regular n=1000");
}

#[test]
fn stratified_is_one_point_per_stratum() {
    for k in [1, 2, 5, 16, 31, 64, 200] {
        for seed in 0..4 {
            let pts = points(Pattern::Stratified, k * k, seed);
            assert_one_per_stratum(&pts, k, &format!("stratified k={k} seed={seed}"));
        }
    }
    for n in [2, 10, 1000, 4097] {
        let k = grid_side(n);
        let pts = points(Pattern::Stratified, n, 3);
        assert_one_per_stratum(&pts[..k * k], k, &format!("stratified n={n}"));
    }
}

/// P-value of Pearson's χ² for counts on a `cells`×`cells` grid against uniform.
fn chi2_uniform_p(pattern: Pattern, n: usize, seeds: u64, cells: usize) -> (f64, usize) {
    let mut counts = vec![0u64; cells * cells];
    let mut total = 0;
    for seed in 0..seeds {
        for p in points(pattern, n, 1000 + seed) {
            counts[cell_index(p.y, cells) * cells + cell_index(p.x, cells)] += 1;
            total += 1;
        }
    }
    let (_, _, p) = pearson_uniform(&counts, total as f64);
    (p, total)
}

#[test]
fn independent_and_stratified_pass_chi2_uniformity() {
    // 10×10 cells do not line up with the 31×31 or 32×32 strata.
    for (pattern, n) in [
        (Pattern::Independent, 1000),
        (Pattern::Independent, 1024),
        (Pattern::Stratified, 1000),
        (Pattern::Stratified, 1024),
    ] {
        for cells in [10, 17] {
            let (p, total) = chi2_uniform_p(pattern, n, 200, cells);
            eprintln!("chi2 {pattern} n={n} {cells}x{cells} cells, {total} points: p = {p:.4}");
            assert!(total >= 100_000);
            assert!(p >= 1e-3, "{pattern} n={n}: χ² p-value {p}");
        }
    }
}

#[test]
fn poisson_disk_respects_its_radius_and_fills_the_square() {
    for n in [16, 100, 1000, 4096] {
        for seed in 0..3 {
            let t = Instant::now();
            let pts = points(Pattern::Poisson, n, seed);
            let elapsed = t.elapsed();
            let r = poisson::radius(n);
            let d = min_toroidal_distance(&pts);
            eprintln!(
                "poisson n={n} seed={seed}: {} points, r = {r:.5}, min distance {d:.5} ({:.3} of r_max), {elapsed:.2?}",
                pts.len(),
                d / max_packing_radius(n)
            );
            assert!(d >= r, "poisson n={n} seed={seed}: pair at {d} < r = {r}");
            assert!(
                pts.len() as f64 >= 0.95 * n as f64,
                "poisson n={n} seed={seed}: only {} points",
                pts.len()
            );
        }
    }
}

/// The mean over points of the toroidal distance to the nearest other point.
fn mean_nearest_neighbour(points: &[Vec2]) -> f64 {
    let sum: f64 = points
        .iter()
        .enumerate()
        .map(|(i, &a)| {
            points
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, &b)| toroidal_distance(a, b))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    sum / points.len() as f64
}

#[test]
fn ccvt_is_well_spread_with_equal_capacities() {
    for (n, seed) in [(64, 1), (256, 2), (1000, 3), (1024, 4)] {
        let t = Instant::now();
        let run = ccvt::ccvt(n, seed, ccvt::POINTS_PER_SITE);
        let elapsed = t.elapsed();
        let rel = min_toroidal_distance(&run.sites) / max_packing_radius(n);
        let mean_nn = mean_nearest_neighbour(&run.sites) / max_packing_radius(n);
        eprintln!(
            "ccvt n={n}: {} sweeps, {} swaps, stable {}, min distance {rel:.3} and mean nearest neighbour {mean_nn:.3} of r_max, {elapsed:.2?}",
            run.sweeps, run.swaps, run.stable
        );
        assert!(run.stable, "ccvt n={n}: did not converge");
        assert_eq!(run.sites.len(), n);
        assert!(run.sites.iter().all(|p| in_unit_square(*p)));
        assert!(
            run.capacities.iter().all(|&c| c == ccvt::POINTS_PER_SITE),
            "ccvt n={n}: unequal capacities"
        );
        assert!(rel >= 0.5, "ccvt n={n}: min distance {rel} of r_max");
        // Uniform random points average about 0.47 of r_max.
        assert!(
            mean_nn >= 0.75,
            "ccvt n={n}: mean nearest neighbour {mean_nn} of r_max"
        );
    }
}

/// Every elementary interval of area 2^-m (2^p × 2^(m−p) cells) holds exactly one point.
fn assert_02_net(pts: &[Vec2], m: u32, what: &str) {
    assert_eq!(pts.len(), 1 << m);
    for p in 0..=m {
        let (kx, ky) = (1usize << p, 1usize << (m - p));
        let mut seen = vec![false; 1 << m];
        for q in pts {
            let cell = cell_index(q.y, ky) * kx + cell_index(q.x, kx);
            assert!(!seen[cell], "{what}: two points in a {kx}×{ky} interval");
            seen[cell] = true;
        }
    }
}

#[test]
fn sobol_power_of_two_prefixes_are_02_nets() {
    for m in 0..=14 {
        let n = 1 << m;
        assert_02_net(&sobol::unscrambled_points(n), m, &format!("sobol m={m}"));
        for seed in 0..3 {
            let pts = points(Pattern::Sobol, n, seed);
            assert_02_net(&pts, m, &format!("scrambled sobol m={m} seed={seed}"));
        }
    }
    // The scramble moves points, differently for each seed.
    let plain = sobol::unscrambled_points(256);
    assert_ne!(points(Pattern::Sobol, 256, 0), plain);
    assert_ne!(
        points(Pattern::Sobol, 256, 0),
        points(Pattern::Sobol, 256, 1)
    );
}

#[test]
fn owen_scramble_is_a_bijection_on_every_digit_prefix() {
    // Scrambling the 2^12 values that differ only in their top 12 digits permutes them.
    let seed = 0x1234_5678_9ABC_DEF0;
    let mut seen = HashSet::new();
    for i in 0u32..1 << 12 {
        let x = i << 20;
        assert!(seen.insert(sobol::owen_scramble(x, seed) >> 20));
    }
}
