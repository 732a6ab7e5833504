//! Ray casting throughput: closest-hit queries per second, with full surface data
//! (`Geometry::intersect`) and from the kernel alone (`Geometry::closest_hit`: distance and
//! surface ids, what a ray-casting kernel reports), on one and two threads, coherent camera
//! rays and incoherent rays, one query per ray and as a stream (`Geometry::intersect_stream`,
//! several traversals in flight), plus the any-hit query and the build time, on two scenes:
//! 1. the Cornell box (556 units) with a ~100k-triangle UV sphere,
//! 2. a smooth displaced sphere of ~1M triangles.
//!
//! `flat_crossover/*` times closest and any hits (one thread, incoherent rays) with the
//! tree and without it (`geometry::flat`) on the Cornell box plus spheres of a few dozen
//! to a few hundred triangles: where the two cross sets `flat::FLAT_LIMIT`.
//!
//! `rays/cornell_box/*` times `Geometry`'s queries on the Cornell box alone (one thread,
//! incoherent rays), to compare with `experiments/tools/mitsuba_ray_rate.py`;
//! `RAYS_SCENE=scene.xml cargo bench --bench rays -- rays/scene` runs them on any scene.
//!
//! `cargo bench --bench rays` (criterion prints rays/s as "elem/s"). Figures depend on the
//! CPU features the build targets (`.cargo/config.toml`: target-cpu=native); state them
//! with every figure (`rustc --print cfg -C target-cpu=native | grep feature`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use mltbench::geometry::bvh::{TraversalRay, TriangleBvh, TriangleList};
use mltbench::geometry::packet::{ClosestLanes, RayLanes};
use mltbench::geometry::procedural::{
    cornell_box, cornell_box_with_sphere, displaced_sphere_1m, mesh_shape, uv_sphere,
};
use mltbench::geometry::{Geometry, Ray};
use mltbench::math::lanes::{F32x16, Mask16, V3};
use mltbench::scene::ShapeDesc;
use rayon::prelude::*;

/// Rays per batch: a 512×512 image of camera rays, or as many incoherent rays.
const WIDTH: u32 = 512;
const HEIGHT: u32 = 512;
/// Rays per parallel work item (8 image rows: keeps coherent rays together).
const CHUNK: usize = 8 * WIDTH as usize;

#[path = "support/split_mix.rs"]
mod split_mix;
use split_mix::SplitMix;

/// Camera rays of a pinhole at `eye` looking at `target` (vertical field of view `fov_y`
/// degrees), one jittered ray per pixel, in scanline order.
fn camera_rays(eye: Vec3, target: Vec3, fov_y: f32, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix(seed);
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let h = (fov_y.to_radians() * 0.5).tan();
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let mut rays = Vec::with_capacity((WIDTH * HEIGHT) as usize);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let sx = (2.0 * (x as f32 + rng.next_f32()) / WIDTH as f32 - 1.0) * h * aspect;
            let sy = (1.0 - 2.0 * (y as f32 + rng.next_f32()) / HEIGHT as f32) * h;
            rays.push(Ray::new(eye, (forward + right * sx + up * sy).normalize()));
        }
    }
    rays
}

/// Rays with origins uniform in the scene's bounding box and directions uniform on the
/// sphere.
fn incoherent_rays(geometry: &Geometry, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix(seed);
    let b = geometry.bounds();
    (0..count)
        .map(|_| {
            let o =
                b.min + b.diagonal() * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let z = 1.0 - 2.0 * rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect()
}

/// How many of `rays` `hits` says hit something, the rays split over the pool's threads.
fn count_hits(pool: &rayon::ThreadPool, rays: &[Ray], hits: impl Fn(&Ray) -> bool + Sync) -> usize {
    pool.install(|| {
        rays.par_chunks(CHUNK)
            .map(|chunk| chunk.iter().filter(|r| hits(r)).count())
            .sum()
    })
}

/// Closest hits with their surface data (`Geometry::intersect`).
fn trace_all(pool: &rayon::ThreadPool, geometry: &Geometry, rays: &[Ray]) -> usize {
    count_hits(pool, rays, |r| black_box(geometry.intersect(r)).is_some())
}

/// Closest hits from the kernel alone (`Geometry::closest_hit`: distance and surface ids).
fn trace_kernel(pool: &rayon::ThreadPool, geometry: &Geometry, rays: &[Ray]) -> usize {
    count_hits(pool, rays, |r| black_box(geometry.closest_hit(r)).is_some())
}

/// `trace_all` through `Geometry::intersect_stream` (several traversals in flight).
fn trace_stream(pool: &rayon::ThreadPool, geometry: &Geometry, rays: &[Ray]) -> usize {
    pool.install(|| {
        rays.par_chunks(CHUNK)
            .map_init(Vec::new, |out, chunk| {
                geometry.intersect_stream(chunk, out);
                black_box(&*out).iter().filter(|h| h.is_some()).count()
            })
            .sum()
    })
}

fn occluded_all(pool: &rayon::ThreadPool, geometry: &Geometry, rays: &[Ray]) -> usize {
    count_hits(pool, rays, |r| black_box(geometry.occluded(r)))
}

struct BenchScene {
    name: &'static str,
    shapes: Vec<ShapeDesc>,
    eye: Vec3,
    target: Vec3,
}

fn scenes() -> Vec<BenchScene> {
    vec![
        BenchScene {
            name: "cornell_uvsphere_100k",
            shapes: cornell_box_with_sphere(556.0),
            eye: Vec3::new(278.0, 278.0, -780.0),
            target: Vec3::new(278.0, 278.0, 278.0),
        },
        BenchScene {
            name: "displaced_sphere_1m",
            shapes: vec![mesh_shape(
                "displaced",
                displaced_sphere_1m(Vec3::ZERO, 1.0),
            )],
            eye: Vec3::new(0.4, 0.6, -3.6),
            target: Vec3::ZERO,
        },
    ]
}

fn bench_rays(c: &mut Criterion) {
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, 2]
        .into_iter()
        .map(|n| {
            (
                n,
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap(),
            )
        })
        .collect();
    for scene in scenes() {
        let geometry = Geometry::build(&scene.shapes);
        let coherent = camera_rays(scene.eye, scene.target, 40.0, 1);
        let incoherent = incoherent_rays(&geometry, coherent.len(), 2);
        let mut group = c.benchmark_group(format!("rays/{}", scene.name));
        group
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3))
            .throughput(Throughput::Elements(coherent.len() as u64));
        for (threads, pool) in &pools {
            group.bench_function(format!("closest_coherent/{threads}t"), |b| {
                b.iter(|| trace_all(pool, &geometry, &coherent))
            });
            group.bench_function(format!("closest_incoherent/{threads}t"), |b| {
                b.iter(|| trace_all(pool, &geometry, &incoherent))
            });
            group.bench_function(format!("kernel_coherent/{threads}t"), |b| {
                b.iter(|| trace_kernel(pool, &geometry, &coherent))
            });
            group.bench_function(format!("kernel_incoherent/{threads}t"), |b| {
                b.iter(|| trace_kernel(pool, &geometry, &incoherent))
            });
            group.bench_function(format!("stream_coherent/{threads}t"), |b| {
                b.iter(|| trace_stream(pool, &geometry, &coherent))
            });
            group.bench_function(format!("stream_incoherent/{threads}t"), |b| {
                b.iter(|| trace_stream(pool, &geometry, &incoherent))
            });
        }
        group.bench_function("anyhit_incoherent/1t", |b| {
            b.iter(|| occluded_all(&pools[0].1, &geometry, &incoherent))
        });
        group.finish();

        let mut group = c.benchmark_group(format!("build/{}", scene.name));
        group
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(5))
            .throughput(Throughput::Elements(geometry.triangle_count() as u64));
        group.bench_function("geometry_build", |b| {
            b.iter(|| Geometry::build(black_box(&scene.shapes)))
        });
        group.finish();
    }
}

/// The triangles of `shapes` (meshes only) as a plain list.
fn triangles_of(shapes: &[ShapeDesc]) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for shape in shapes {
        if let mltbench::scene::ShapeGeometry::Mesh(m) = &shape.geometry {
            for t in &m.indices {
                out.push(t.map(|i| m.positions[i as usize]));
            }
        }
    }
    out
}

fn bench_flat_crossover(c: &mut Criterion) {
    let mut group = c.benchmark_group("flat_crossover");
    group.measurement_time(Duration::from_secs(3));
    // Sphere rings × segments: 0, 32, 96 and 224 triangles beside the box's 36.
    for (rings, segments) in [(0u32, 0u32), (3, 8), (5, 12), (8, 16)] {
        let mut shapes = cornell_box(556.0);
        if rings > 0 {
            let sphere = uv_sphere(Vec3::new(278.0, 150.0, 278.0), 120.0, rings, segments);
            shapes.push(mesh_shape("sphere", sphere));
        }
        let vertices = triangles_of(&shapes);
        let ids: Vec<[u32; 2]> = (0..vertices.len() as u32).map(|i| [0, i]).collect();
        let list = TriangleList {
            vertices: &vertices,
            ids: &ids,
        };
        let n = vertices.len();
        let geometry = Geometry::build(&shapes);
        let rays: Vec<(TraversalRay, f32)> = incoherent_rays(&geometry, 1 << 16, 7)
            .iter()
            .map(|r| (TraversalRay::new(r.o, r.d), r.t_max))
            .collect();
        // The shadow-ray case: segments ending halfway to the closest hit.
        let tree = TriangleBvh::build_with_flat_limit(&list, 0);
        let flat = TriangleBvh::build_with_flat_limit(&list, usize::MAX);
        let shadow: Vec<f32> = rays
            .iter()
            .map(|(r, t)| tree.closest(r, *t).map_or(*t, |(_, h)| 0.5 * h.t))
            .collect();
        group.throughput(Throughput::Elements(rays.len() as u64));
        for (name, bvh) in [("tree", &tree), ("flat", &flat)] {
            group.bench_function(format!("{n}/closest_{name}"), |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|(r, t)| bvh.closest(r, *t).is_some())
                        .count()
                })
            });
            group.bench_function(format!("{n}/any_{name}"), |b| {
                b.iter(|| {
                    rays.iter()
                        .zip(&shadow)
                        .filter(|((r, _), t)| bvh.any(r, **t))
                        .count()
                })
            });
        }
    }
    group.finish();
}

/// The Cornell box alone (36 triangles, answered without the tree) through `Geometry`'s
/// queries, one thread: the figures to set beside another renderer's ray casting on the
/// same scene (`experiments/tools/mitsuba_ray_rate.py` casts the same kind of rays). With
/// `RAYS_SCENE=path/to/scene.xml` in the environment, the same queries on that scene's
/// geometry instead (group `rays/scene`).
fn bench_cornell_queries(c: &mut Criterion) {
    let (name, geometry) = match std::env::var_os("RAYS_SCENE") {
        Some(path) => {
            let scene = mltbench::scene::Scene::load(std::path::Path::new(&path))
                .unwrap_or_else(|e| panic!("RAYS_SCENE={}: {e}", path.to_string_lossy()));
            ("scene", scene.geometry)
        }
        None => ("cornell_box", Geometry::build(&cornell_box(556.0))),
    };
    let rays = incoherent_rays(&geometry, 1 << 18, 11);
    // Segments ending halfway to the closest hit (rays that escape stay unbounded).
    let shadow: Vec<Ray> = rays
        .iter()
        .map(|r| {
            let t_max = geometry.closest_hit(r).map_or(r.t_max, |h| 0.5 * h.t);
            Ray { t_max, ..*r }
        })
        .collect();
    let mut group = c.benchmark_group(format!("rays/{name}"));
    group
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("kernel_incoherent/1t", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| black_box(geometry.closest_hit(r)).is_some())
                .count()
        })
    });
    group.bench_function("closest_incoherent/1t", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| black_box(geometry.intersect(r)).is_some())
                .count()
        })
    });
    group.bench_function("anyhit_half_segments/1t", |b| {
        b.iter(|| shadow.iter().filter(|r| geometry.occluded(r)).count())
    });
    // The same rays sixteen at a time (`geometry::packet`), as `pt`'s wavefront casts them.
    let (packets, shadow_packets) = (to_packets(&rays), to_packets(&shadow));
    group.bench_function("packet_kernel_incoherent/1t", |b| {
        let mut hits = ClosestLanes::default();
        b.iter(|| {
            packets
                .iter()
                .map(|p| {
                    geometry.closest_hits_lanes(p, Mask16::ALL, &mut hits);
                    black_box(&hits).hit.count() as usize
                })
                .sum::<usize>()
        })
    });
    group.bench_function("packet_anyhit_half_segments/1t", |b| {
        b.iter(|| {
            shadow_packets
                .iter()
                .map(|p| geometry.occluded_lanes(p, Mask16::ALL).count() as usize)
                .sum::<usize>()
        })
    });
    group.finish();
}

/// `rays` in packets of sixteen (the count must be a multiple of 16).
fn to_packets(rays: &[Ray]) -> Vec<RayLanes> {
    rays.chunks_exact(16)
        .map(|c| {
            let lanes =
                |f: &dyn Fn(&Ray) -> f32| F32x16::from_array(std::array::from_fn(|i| f(&c[i])));
            RayLanes {
                o: V3::new(lanes(&|r| r.o.x), lanes(&|r| r.o.y), lanes(&|r| r.o.z)),
                d: V3::new(lanes(&|r| r.d.x), lanes(&|r| r.d.y), lanes(&|r| r.d.z)),
                t_max: lanes(&|r| r.t_max),
            }
        })
        .collect()
}

criterion_group! {
    name = benches;
    // No HTML plots: mltbench builds plotters without system-font lookup (its plots embed a
    // font), and criterion's report plots would need one.
    config = Criterion::default().without_plots();
    targets = bench_rays, bench_flat_crossover, bench_cornell_queries
}
criterion_main!(benches);
