//! The photon kd-tree (`estimator::ppm::kd_tree`) against brute force and the `kiddo`
//! crate's immutable tree: build time, radius queries returning about 50 points, and
//! 16-nearest queries, from 10⁴ to 10⁷ points, uniform in the unit cube and clustered
//! (five tight clusters, as photons gather in caustics). Brute force runs up to 10⁵ points.
//!
//! `cargo bench --bench kd_tree` (criterion prints points or queries per second as
//! "elem/s"); `KD_TREE_MAX=1000000` stops at 10⁶ points.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use mltbench::estimator::ppm::kd_tree::{KdTree, distance_squared};

#[path = "support/split_mix.rs"]
mod split_mix;
use split_mix::SplitMix;

/// A uniform point in the unit cube.
fn point(rng: &mut SplitMix) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
}

fn uniform(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = SplitMix(seed);
    (0..n).map(|_| point(&mut rng)).collect()
}

fn clustered(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = SplitMix(seed);
    let centres: Vec<Vec3> = (0..5).map(|_| point(&mut rng)).collect();
    (0..n)
        .map(|i| {
            let mut j = || (rng.next_f32() + rng.next_f32() - 1.0) * 0.02;
            centres[i % 5] + Vec3::new(j(), j(), j())
        })
        .collect()
}

const QUERIES: usize = 1000;

/// Query points: stored points moved a little (queries land where the data is).
fn queries(points: &[Vec3], seed: u64) -> Vec<Vec3> {
    let mut rng = SplitMix(seed);
    (0..QUERIES)
        .map(|i| {
            let p = points[(i * 7919) % points.len()];
            p + (point(&mut rng) - 0.5) * 1e-3
        })
        .collect()
}

/// The radius whose balls hold about 50 points: the median 50th-nearest distance.
fn radius_for_50(tree: &KdTree, queries: &[Vec3]) -> f32 {
    let mut out = Vec::new();
    let mut r: Vec<f32> = queries
        .iter()
        .take(101)
        .map(|&q| {
            tree.nearest(q, 50, &mut out);
            out.last().unwrap().0.sqrt()
        })
        .collect();
    r.sort_by(f32::total_cmp);
    r[r.len() / 2]
}

fn bench(c: &mut Criterion) {
    let max: usize = std::env::var("KD_TREE_MAX")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000_000);
    let mut group = c.benchmark_group("kd_tree");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    for (name, make) in [
        ("uniform", uniform as fn(usize, u64) -> Vec<Vec3>),
        ("clustered", clustered),
    ] {
        let mut n = 10_000;
        while n <= max {
            let points = make(n, 1);
            let arrays: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
            let id = |what: &str| BenchmarkId::new(format!("{name}/{what}"), n);

            group.throughput(Throughput::Elements(n as u64));
            group.bench_function(id("build/mltbench"), |b| {
                b.iter(|| KdTree::build(black_box(&points)).unwrap())
            });
            group.bench_function(id("build/kiddo"), |b| {
                b.iter(|| ImmutableKdTree::<f32, u32, 3, 32>::new_from_slice(black_box(&arrays)))
            });

            let ours = KdTree::build(&points).unwrap();
            let theirs = ImmutableKdTree::<f32, u32, 3, 32>::new_from_slice(&arrays);
            let qs = queries(&points, 2);
            let r = radius_for_50(&ours, &qs);
            group.throughput(Throughput::Elements(QUERIES as u64));
            group.bench_function(id("radius50/mltbench"), |b| {
                b.iter(|| {
                    let mut found = 0usize;
                    for &q in &qs {
                        ours.within_radius(q, r, |_, _| found += 1);
                    }
                    found
                })
            });
            group.bench_function(id("radius50/kiddo"), |b| {
                b.iter(|| {
                    qs.iter()
                        .map(|q| {
                            theirs
                                .within_unsorted::<SquaredEuclidean>(&q.to_array(), r * r)
                                .len()
                        })
                        .sum::<usize>()
                })
            });
            let mut out = Vec::new();
            group.bench_function(id("nearest16/mltbench"), |b| {
                b.iter(|| {
                    for &q in &qs {
                        ours.nearest(q, 16, &mut out);
                    }
                    out.len()
                })
            });
            group.bench_function(id("nearest16/kiddo"), |b| {
                b.iter(|| {
                    qs.iter()
                        .map(|q| {
                            theirs
                                .nearest_n::<SquaredEuclidean>(
                                    &q.to_array(),
                                    std::num::NonZero::new(16).unwrap(),
                                )
                                .len()
                        })
                        .sum::<usize>()
                })
            });
            if n <= 100_000 {
                group.bench_function(id("radius50/brute_force"), |b| {
                    b.iter(|| {
                        qs.iter()
                            .map(|&q| {
                                points
                                    .iter()
                                    .filter(|&&p| distance_squared(q, p) <= r * r)
                                    .count()
                            })
                            .sum::<usize>()
                    })
                });
            }
            n *= 10;
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
