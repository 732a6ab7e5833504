//! Lens samples from the sample patterns (`--set sampler=NAME` on a `thinlens` scene): the
//! second 2D sample of each pixel sample keeps the pattern's structure within each pixel, is
//! paired with the pixel positions at random, and a pinhole camera never draws it.

mod eyelight_support;

use eyelight_support::{eyelight, shipped_scene};

use std::sync::Arc;

use glam::Vec2;
use mltbench::experiment::metrics::metrics;
use mltbench::sampler::pattern::{Pattern, cell_index, grid_side, points, toroidal_distance};
use mltbench::sampler::pixel_samples::{CameraSampler, PixelSamples};
use mltbench::sampler::{IndependentSampler, Sampler, poisson};
use mltbench::scene::Scene;
use statrs::distribution::{ChiSquared, ContinuousCDF};

const SEED: u64 = 77;
const PIXELS: [(u32, u32); 5] = [(0, 0), (1, 0), (17, 3), (255, 255), (40, 1000)];

/// The lens samples `first..first + count` of `pixel`, as the camera draws them: the second
/// 2D sample of each pixel sample of a `CameraSampler` with lens samples on.
fn lens_samples(ps: &Arc<PixelSamples>, pixel: (u32, u32), first: u64, count: u64) -> Vec<Vec2> {
    let mut sampler = CameraSampler::new(SEED, ps.clone()).with_lens_samples(true);
    (first..first + count)
        .map(|i| {
            sampler.start_pixel_sample(pixel, i);
            let _pixel_position = sampler.next_2d();
            sampler.next_2d()
        })
        .collect()
}

fn in_unit_square(p: Vec2) -> bool {
    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)
}

#[test]
fn a_pinhole_draws_no_lens_sample_and_a_lens_draws_exactly_one() {
    for pattern in [Pattern::Independent, Pattern::Stratified, Pattern::Sobol] {
        let ps = Arc::new(PixelSamples::new(pattern, 16, SEED));
        for (pixel, index) in [((3, 4), 0u64), ((9, 1), 5), ((0, 7), 21)] {
            // What the independent stream of this pixel sample gives.
            let mut reference = IndependentSampler::new(SEED);
            reference.start_pixel_sample(pixel, index);
            let stream: Vec<f32> = (0..8).map(|_| reference.next_1d()).collect();
            // A pattern hands out its own positions and leaves the stream alone; independent
            // positions come from the stream.
            let skip = |n: usize| {
                if pattern == Pattern::Independent {
                    n
                } else {
                    0
                }
            };

            let mut pinhole = CameraSampler::new(SEED, ps.clone());
            pinhole.start_pixel_sample(pixel, index);
            let position = pinhole.next_2d();
            if let Some(p) = ps.offset(SEED, pixel, index) {
                assert_eq!(position, p);
            }
            let rest: Vec<f32> = (0..4).map(|_| pinhole.next_1d()).collect();
            assert_eq!(rest, stream[skip(2)..skip(2) + 4], "{pattern}: pinhole");

            let mut lens = CameraSampler::new(SEED, ps.clone()).with_lens_samples(true);
            lens.start_pixel_sample(pixel, index);
            assert_eq!(lens.next_2d(), position, "{pattern}: same pixel position");
            let u = lens.next_2d();
            if let Some(p) = ps.lens(SEED, pixel, index) {
                assert_eq!(u, p);
            }
            let rest: Vec<f32> = (0..4).map(|_| lens.next_1d()).collect();
            assert_eq!(rest, stream[skip(4)..skip(4) + 4], "{pattern}: lens");
        }
    }
}

#[test]
fn stratified_lens_samples_fill_every_stratum_once_per_block() {
    for m in [16usize, 64, 100] {
        let k = grid_side(m);
        let ps = Arc::new(PixelSamples::new(Pattern::Stratified, m, SEED));
        for pixel in PIXELS {
            for block in 0..3u64 {
                let lens = lens_samples(&ps, pixel, block * m as u64, m as u64);
                let mut hits = vec![0u32; k * k];
                for &u in &lens {
                    assert!(in_unit_square(u), "{u}");
                    hits[cell_index(u.y, k) * k + cell_index(u.x, k)] += 1;
                }
                assert!(
                    hits.iter().all(|&h| h == 1),
                    "M = {m}, pixel {pixel:?}, block {block}: {hits:?}"
                );
            }
        }
    }
}

#[test]
fn lens_strata_are_paired_with_samples_at_random() {
    // Sample 0's lens stratum over 4096 pixels: uniform over the 16 strata (χ² at 1e-3), and
    // the order of strata differs between pixels and between blocks of one pixel.
    let m = 16;
    let ps = Arc::new(PixelSamples::new(Pattern::Stratified, m, SEED));
    let stratum = |u: Vec2| cell_index(u.y, 4) * 4 + cell_index(u.x, 4);
    let mut counts = [0u32; 16];
    for y in 0..64 {
        for x in 0..64 {
            counts[stratum(lens_samples(&ps, (x, y), 0, 1)[0])] += 1;
        }
    }
    let expected = 4096.0 / 16.0;
    let chi2: f64 = counts
        .iter()
        .map(|&c| (c as f64 - expected).powi(2) / expected)
        .sum();
    let p = 1.0 - ChiSquared::new(15.0).unwrap().cdf(chi2);
    assert!(p > 1e-3, "χ² = {chi2:.1}, p = {p:.2e}: {counts:?}");

    let order = |pixel, block: u64| -> Vec<usize> {
        lens_samples(&ps, pixel, block * m as u64, m as u64)
            .into_iter()
            .map(stratum)
            .collect()
    };
    assert_ne!(order((0, 0), 0), order((1, 0), 0));
    assert_ne!(order((0, 0), 0), order((0, 0), 1));
}

#[test]
fn shifted_patterns_keep_their_points_on_the_lens() {
    // Regular, Poisson disk and CCVT: the first M lens samples of a pixel are the pattern's
    // points, each once, under one toroidal shift; Poisson disk keeps its minimum distance.
    for pattern in [Pattern::Regular, Pattern::Poisson, Pattern::Ccvt] {
        let m = 64;
        let base = points(pattern, m, SEED);
        let ps = Arc::new(PixelSamples::new(pattern, m, SEED));
        for pixel in PIXELS {
            let lens = lens_samples(&ps, pixel, 0, base.len() as u64);
            assert!(lens.iter().all(|&u| in_unit_square(u)));
            // The shift that maps some pattern point onto the first lens sample must map
            // every point onto a distinct lens sample.
            let matches_with = |shift: Vec2| {
                let mut used = vec![false; lens.len()];
                base.iter().all(|&p| {
                    let q = p + shift;
                    let q = Vec2::new(q.x.rem_euclid(1.0), q.y.rem_euclid(1.0));
                    let found = lens
                        .iter()
                        .enumerate()
                        .find(|&(j, &u)| !used[j] && toroidal_distance(q, u) < 1e-5);
                    found.map(|(j, _)| used[j] = true).is_some()
                })
            };
            let ok = base.iter().any(|&p| matches_with(lens[0] - p));
            assert!(ok, "{pattern}, pixel {pixel:?}: not a shifted copy");
            if pattern == Pattern::Poisson {
                let min = mltbench::sampler::pattern::min_toroidal_distance(&lens);
                assert!(min >= poisson::radius(m) - 1e-6, "{min}");
            }
        }
        // Different pixels see different shifts.
        assert_ne!(
            lens_samples(&ps, (0, 0), 0, 1),
            lens_samples(&ps, (1, 0), 0, 1)
        );
    }
}

/// The t of the (t, m, 2)-net `pts` (2^m points): the smallest t such that every
/// elementary interval of area 2^(t−m) holds 2^t points.
fn net_quality(pts: &[Vec2], m: u32) -> u32 {
    (0..=m)
        .find(|&t| {
            (0..=m - t).all(|a| {
                let b = m - t - a;
                let mut cells = vec![0u32; 1 << (m - t)];
                for p in pts {
                    let i = cell_index(p.x, 1 << a);
                    let j = cell_index(p.y, 1 << b);
                    cells[(j << a) | i] += 1;
                }
                cells.iter().all(|&c| c == 1 << t)
            })
        })
        .unwrap()
}

#[test]
fn sobol_lens_samples_are_dimensions_two_and_three_of_the_same_points() {
    // x² + x + 1 and x³ + x + 1 together: t = 0 for m = 1 and 4, t = 2 for m = 3 and
    // m ≥ 11, t = 1 otherwise, for every pixel and block: Owen scrambling per pixel keeps
    // the net.
    let expected = |m: u32| match m {
        1 | 4 => 0,
        3 | 11.. => 2,
        _ => 1,
    };
    for m in 1..=12u32 {
        let n = 1u64 << m;
        let ps = Arc::new(PixelSamples::new(Pattern::Sobol, n as usize, SEED));
        for pixel in PIXELS {
            for block in 0..2 {
                let lens = lens_samples(&ps, pixel, block * n, n);
                assert!(lens.iter().all(|&u| in_unit_square(u)));
                assert_eq!(
                    net_quality(&lens, m),
                    expected(m),
                    "m = {m}, pixel {pixel:?}, block {block}"
                );
            }
        }
    }
}

fn dof_scene() -> Scene {
    shipped_scene("cbox-dof.xml", 32)
}

#[test]
fn structured_lens_samples_beat_independent_ones_and_agree_with_them() {
    // `eyelight` through the thin lens of cbox-dof.xml: its randomness is the pixel position
    // and the lens point. Mean relMSE over 4 seeds at 64 spp against a 4096-spp Sobol'
    // reference; then, at 1024 spp, as close to the reference as independent samples.
    // (Measured with 8 seeds: independent 4.4e-3; with the lens samples drawn independently
    // instead of from the pattern (a throwaway build), stratified 3.3e-3, Poisson 3.4e-3, CCVT 2.9e-3, Sobol'
    // 3.1e-3; from the pattern, 2.2e-3, 2.5e-3, 2.8e-3 and 1.2e-3. At 16 spp the gains are
    // smaller: 1.65e-2 against 1.29e-2, 1.18e-2, 1.00e-2 and 0.91e-2.)
    let scene = dof_scene();
    assert!(scene.camera.has_lens());
    let reference = eyelight(&scene, "sobol", 4096, 1);
    let error = |sampler: &str, spp: u32, seeds: u64| {
        (0..seeds)
            .map(|s| {
                metrics(&eyelight(&scene, sampler, spp, 10 + s), &reference)
                    .unwrap()
                    .relmse
            })
            .sum::<f64>()
            / seeds as f64
    };
    let independent = error("independent", 64, 4);
    for sampler in ["stratified", "poisson", "ccvt", "sobol"] {
        let e = error(sampler, 64, 4);
        eprintln!("{sampler}: relMSE {e:.3e} (independent {independent:.3e})");
        assert!(e < 0.75 * independent, "{sampler}: {e} vs {independent}");
    }
    let far = error("independent", 1024, 1);
    for sampler in ["stratified", "poisson", "ccvt"] {
        let e = error(sampler, 1024, 1);
        assert!(e < 2.0 * far, "{sampler}: {e} vs independent {far}");
    }
}
