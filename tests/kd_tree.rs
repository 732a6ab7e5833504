//! The photon kd-tree against brute force: radius and k-nearest queries return exactly the
//! points a linear scan finds (the same squared-distance formula, `distance_squared`), on
//! uniform, clustered, duplicated and planar point sets, and on empty and one-point trees.

use glam::Vec3;
use mltbench::estimator::ppm::kd_tree::{KdTree, LEAF_SIZE, distance_squared};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn uniform(n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<Vec3> {
    (0..n)
        .map(|_| Vec3::new(rng.random(), rng.random(), rng.random()))
        .collect()
}

/// Tight Gaussian-like clusters around a few centres (sums of uniforms).
fn clustered(n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<Vec3> {
    let centres = uniform(5, rng);
    (0..n)
        .map(|i| {
            let c = centres[i % centres.len()];
            let mut jitter = || (rng.random::<f32>() + rng.random::<f32>() - 1.0) * 0.01;
            c + Vec3::new(jitter(), jitter(), jitter())
        })
        .collect()
}

/// Few distinct points, each many times.
fn duplicated(n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<Vec3> {
    let distinct = uniform(7, rng);
    (0..n).map(|i| distinct[(i * 31) % 7]).collect()
}

/// Points on the plane y = 0.5 (one axis has no extent), on a grid so distances tie.
fn planar(n: usize, _: &mut Xoshiro256PlusPlus) -> Vec<Vec3> {
    (0..n)
        .map(|i| Vec3::new((i % 37) as f32 / 37.0, 0.5, (i / 37) as f32 / 37.0))
        .collect()
}

fn brute_radius(points: &[Vec3], q: Vec3, r: f32) -> Vec<u32> {
    let mut ids: Vec<u32> = (0..points.len() as u32)
        .filter(|&i| distance_squared(q, points[i as usize]) <= r * r)
        .collect();
    ids.sort_unstable();
    ids
}

fn brute_nearest(points: &[Vec3], q: Vec3, k: usize) -> Vec<(f32, u32)> {
    let mut all: Vec<(f32, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (distance_squared(q, p), i as u32))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    all.truncate(k);
    all
}

#[test]
fn queries_equal_brute_force_on_every_kind_of_point_set() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    type Maker = fn(usize, &mut Xoshiro256PlusPlus) -> Vec<Vec3>;
    let makers: [(&str, Maker); 4] = [
        ("uniform", uniform),
        ("clustered", clustered),
        ("duplicated", duplicated),
        ("planar", planar),
    ];
    for (name, make) in makers {
        for n in [1usize, LEAF_SIZE, LEAF_SIZE + 1, 100, 5000] {
            let points = make(n, &mut rng);
            let tree = KdTree::build(&points).unwrap();
            assert_eq!(tree.len(), n);
            let mut nearest = Vec::new();
            for query in 0..60 {
                // Queries at stored points (exact ties at distance 0) and anywhere.
                let q = if query % 3 == 0 {
                    points[query % n]
                } else {
                    Vec3::new(rng.random(), rng.random(), rng.random()) * 1.2 - 0.1
                };
                for r in [0.0f32, 0.01, 0.05, 0.3] {
                    let mut found = Vec::new();
                    tree.within_radius(q, r, |id, d2| {
                        assert_eq!(d2, distance_squared(q, points[id as usize]));
                        found.push(id);
                    });
                    found.sort_unstable();
                    assert_eq!(found, brute_radius(&points, q, r), "{name} n {n} r {r}");
                }
                for k in [1usize, 16, 50] {
                    tree.nearest(q, k, &mut nearest);
                    assert_eq!(nearest, brute_nearest(&points, q, k), "{name} n {n} k {k}");
                }
            }
        }
    }
}

#[test]
fn empty_and_one_point_trees_answer() {
    let empty = KdTree::build(&[]).unwrap();
    assert!(empty.is_empty());
    let mut out = vec![(1.0, 1)];
    empty.nearest(Vec3::ZERO, 4, &mut out);
    assert!(out.is_empty());
    empty.within_radius(Vec3::ZERO, 10.0, |_, _| {
        panic!("an empty tree found a point")
    });

    let one = KdTree::build(&[Vec3::new(1.0, 2.0, 3.0)]).unwrap();
    one.nearest(Vec3::ZERO, 4, &mut out);
    assert_eq!(out, vec![(14.0, 0)]);
    let mut hits = 0;
    one.within_radius(Vec3::new(1.0, 2.0, 3.5), 0.5, |id, _| {
        assert_eq!(id, 0);
        hits += 1;
    });
    assert_eq!(hits, 1);
    one.within_radius(Vec3::ZERO, 3.0, |_, _| panic!("3 < √14"));
}

#[test]
fn non_finite_points_are_refused_by_index() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let points = [Vec3::ZERO, Vec3::ONE, Vec3::new(0.0, bad, 0.0)];
        let err = KdTree::build(&points).unwrap_err();
        assert_eq!(err.index, 2);
        assert!(err.to_string().contains("point 2"));
    }
}

/// A hundred thousand equal points: the median split still halves every node (no deep
/// recursion, no quadratic build), and a query around them returns all of them.
#[test]
fn all_equal_points_build_and_query() {
    let points = vec![Vec3::splat(0.25); 100_000];
    let tree = KdTree::build(&points).unwrap();
    let mut count = 0;
    tree.within_radius(Vec3::splat(0.25), 0.0, |_, _| count += 1);
    assert_eq!(count, points.len());
    let mut out = Vec::new();
    tree.nearest(Vec3::ZERO, 3, &mut out);
    // Ties broken by index.
    assert_eq!(out.iter().map(|e| e.1).collect::<Vec<_>>(), vec![0, 1, 2]);
}
