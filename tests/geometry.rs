//! Ray casting against independent references: brute force over every triangle, closed
//! forms for spheres and disks; watertightness of closed meshes; self-intersection of
//! spawned rays at several scene scales.

use glam::{DVec3, Mat4, Vec2, Vec3};
use mltbench::geometry::procedural::{
    cornell_box, cube_sphere, mesh_shape, shape, uv_sphere, uv_sphere_with_triangles,
};
use mltbench::geometry::{Geometry, Ray, SurfaceInteraction};
use mltbench::math::Transform;
use mltbench::scene::{ShapeDesc, ShapeGeometry, TriangleMesh};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};

struct Random(Xoshiro256PlusPlus);

impl Random {
    fn new(seed: u64) -> Self {
        Random(Xoshiro256PlusPlus::seed_from_u64(seed))
    }
    fn f32(&mut self) -> f32 {
        (self.0.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32())
    }
    fn below(&mut self, n: usize) -> usize {
        (self.0.next_u64() % n as u64) as usize
    }
    /// Uniform direction on the unit sphere.
    fn direction(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.f32();
        let phi = std::f32::consts::TAU * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
    /// Uniform point in the box.
    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * self.vec3()
    }
}

// ---------------------------------------------------------------------------------------
// Brute force reference: every triangle of every mesh, Möller–Trumbore in f64.

struct RefTriangle {
    v: [DVec3; 3],
    shape: u32,
    primitive: u32,
}

fn reference_triangles(shapes: &[ShapeDesc]) -> Vec<RefTriangle> {
    let mut out = Vec::new();
    for (s, desc) in shapes.iter().enumerate() {
        if let ShapeGeometry::Mesh(m) = &desc.geometry {
            for (p, idx) in m.indices.iter().enumerate() {
                out.push(RefTriangle {
                    v: idx.map(|i| m.positions[i as usize].as_dvec3()),
                    shape: s as u32,
                    primitive: p as u32,
                });
            }
        }
    }
    out
}

/// Möller & Trumbore 1997, in f64: (t, smallest barycentric) of the hit with t > 0.
fn moller_trumbore(tri: &RefTriangle, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let e1 = tri.v[1] - tri.v[0];
    let e2 = tri.v[2] - tri.v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - tri.v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some((t, u.min(v).min(1.0 - u - v)))
}

struct RefHit {
    t: f64,
    shape: u32,
    primitive: u32,
    min_bary: f64,
}

fn brute_force(tris: &[RefTriangle], o: Vec3, d: Vec3, t_max: f64) -> Option<RefHit> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let mut best: Option<RefHit> = None;
    for tri in tris {
        if let Some((t, min_bary)) = moller_trumbore(tri, o, d)
            && t < t_max
            && best.as_ref().is_none_or(|b| t < b.t)
        {
            best = Some(RefHit {
                t,
                shape: tri.shape,
                primitive: tri.primitive,
                min_bary,
            });
        }
    }
    best
}

/// A soup of random triangles of varied sizes and orientations inside [lo, hi].
fn triangle_soup(rng: &mut Random, n: usize, lo: Vec3, hi: Vec3) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    while mesh.indices.len() < n {
        let c = rng.in_box(lo, hi);
        let size = (hi - lo).length() * 0.02 * (1.0 + 9.0 * rng.f32() * rng.f32());
        let v = [0, 1, 2].map(|_| c + (rng.vec3() - 0.5) * size);
        if (v[1] - v[0]).cross(v[2] - v[0]).length() < 1e-6 * size * size {
            continue;
        }
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&v);
        mesh.indices.push([base, base + 1, base + 2]);
    }
    mesh
}

#[test]
fn bvh_agrees_with_brute_force() {
    let mut rng = Random::new(0x5eed_0001);
    let size = 556.0;
    let mut shapes = cornell_box(size);
    shapes.push(mesh_shape(
        "uv_sphere",
        uv_sphere(Vec3::new(200.0, 150.0, 300.0), 120.0, 24, 48),
    ));
    shapes.push(mesh_shape(
        "soup",
        triangle_soup(&mut rng, 1500, Vec3::splat(20.0), Vec3::splat(536.0)),
    ));
    let geometry = Geometry::build(&shapes);
    let tris = reference_triangles(&shapes);
    assert_eq!(geometry.triangle_count(), tris.len());
    let bounds = geometry.bounds();
    let (lo, hi) = (bounds.min - 20.0, bounds.max + 20.0);

    let rays = 100_000;
    let (mut hits, mut ties, mut grazing_disagreements) = (0, 0, 0);
    let mut worst_relative = 0.0f64;
    let mut below_floor = 0; // hits whose relative error exceeds 1e-5 (short distances)
    let mut occlusion_checks = 0;
    for i in 0..rays {
        let o = rng.in_box(lo, hi);
        // Unnormalised directions half of the time: t is in units of |d|.
        let d = rng.direction()
            * if i % 2 == 0 {
                1.0
            } else {
                0.1 + 10.0 * rng.f32()
            };
        let ray = Ray::new(o, d);
        let reference = brute_force(&tris, o, d, f64::INFINITY);
        let found = geometry.intersect(&ray);
        // The kernel query reports the same surface and distance as the full one.
        let kernel = geometry.closest_hit(&ray);
        assert_eq!(
            kernel.map(|k| (k.t, k.shape, k.primitive)),
            found.map(|f| (f.t, f.shape, f.primitive)),
            "ray {i}: closest_hit and intersect disagree"
        );
        match (&reference, &found) {
            (Some(r), Some(f)) => {
                hits += 1;
                // Distances agree to 1e-5 relative, above an absolute floor for short
                // distances: f32 coordinates of magnitude X are only known to u·X, and the
                // test's arithmetic runs through a few such roundings (16·u·X).
                let len = d.length() as f64;
                let error = (f.t as f64 - r.t).abs() * len;
                let floor = 16.0
                    * f32::EPSILON as f64
                    * 0.5
                    * (o.abs().max_element() + f.p.abs().max_element()) as f64;
                assert!(
                    error <= 1e-5 * r.t * len + floor,
                    "ray {i}: t {} vs reference {} (distance error {error:e})",
                    f.t,
                    r.t
                );
                worst_relative = worst_relative.max(error / (r.t * len));
                if error > 1e-5 * r.t * len {
                    below_floor += 1;
                }
                if (f.shape, f.primitive) != (r.shape, r.primitive) {
                    ties += 1; // same distance (checked above): a shared edge or vertex
                }
                // The reported point lies on the ray and within its error bound of it.
                let on_ray = ray.at(f.t);
                assert!((on_ray - f.p).length() <= 1e-4 * (f.p.length() + (f.t * d).length()));
                assert!((f.ng.length() - 1.0).abs() < 1e-5 && (f.ns.length() - 1.0).abs() < 1e-5);
            }
            // A miss/hit disagreement is allowed only for a ray through a triangle's very
            // boundary (f32 vs f64 arithmetic), and must stay rare.
            (Some(r), None) => {
                assert!(
                    r.min_bary < 1e-5,
                    "ray {i} missed a hit at t = {} (barycentric {})",
                    r.t,
                    r.min_bary
                );
                grazing_disagreements += 1;
            }
            (None, Some(f)) => {
                // f32 found a hit the f64 reference does not: must be at a boundary too.
                let tri = &tris
                    .iter()
                    .find(|t| (t.shape, t.primitive) == (f.shape, f.primitive))
                    .unwrap();
                let slack = moller_trumbore_slack(tri, o.as_dvec3(), d.as_dvec3());
                assert!(
                    slack < 1e-5,
                    "ray {i} hit nothing in the reference but found t = {} (outside by {slack})",
                    f.t
                );
                grazing_disagreements += 1;
            }
            (None, None) => {}
        }
        // Any-hit against brute force on a random segment of the same ray.
        let t_max = match &reference {
            Some(r) => (r.t * (0.25 + 1.5 * rng.f32() as f64)) as f32,
            None => 1e4,
        };
        let segment = Ray { o, d, t_max };
        // Brute-force occlusion: the nearest hit lies within the segment.
        let expected = reference.as_ref().filter(|r| r.t < t_max as f64);
        let occluded = geometry.occluded(&segment);
        if occluded != expected.is_some() {
            // Only when the nearest surface sits at the end of the segment or on an edge.
            let r = reference.as_ref().unwrap();
            assert!(
                (r.t - t_max as f64).abs() < 1e-5 * r.t || r.min_bary < 1e-5,
                "ray {i}: occluded = {occluded}, brute force says {}",
                expected.is_some()
            );
            grazing_disagreements += 1;
        }
        occlusion_checks += 1;
    }
    eprintln!(
        "{rays} rays: {hits} hits (worst relative distance error {worst_relative:e}, {below_floor} above 1e-5 within the absolute floor), {ties} ties at shared edges, {grazing_disagreements} boundary disagreements, {occlusion_checks} occlusion checks"
    );
    assert!(hits > rays / 2);
    assert!(
        grazing_disagreements <= 10,
        "{grazing_disagreements} boundary disagreements"
    );
}

/// How far outside the triangle (in barycentric units) the ray's plane crossing lies.
fn moller_trumbore_slack(tri: &RefTriangle, o: DVec3, d: DVec3) -> f64 {
    let e1 = tri.v[1] - tri.v[0];
    let e2 = tri.v[2] - tri.v[0];
    let p = d.cross(e2);
    let inv = 1.0 / e1.dot(p);
    let s = o - tri.v[0];
    let u = s.dot(p) * inv;
    let v = d.dot(s.cross(e1)) * inv;
    (-u).max(-v).max(u + v - 1.0).max(0.0)
}

// ---------------------------------------------------------------------------------------
// Watertightness.

#[test]
fn closed_mesh_is_watertight() {
    // Rays from inside a closed mesh with shared vertices must all hit it. Half of them are
    // aimed exactly at vertices and edges, where a non-watertight test lets rays through.
    let mut rng = Random::new(0x5eed_0002);
    let mut escapes = 0;
    let mut total = 0;
    for (center, radius) in [(Vec3::ZERO, 1.0f32), (Vec3::new(1e3, -2e3, 5e2), 3e2)] {
        let mesh = cube_sphere(center, radius, 48);
        let geometry = Geometry::build(&[mesh_shape("closed", mesh.clone())]);
        for i in 0..500_000 {
            let o = center + rng.direction() * radius * 0.9 * rng.f32().cbrt();
            let d = if i % 2 == 0 {
                rng.direction()
            } else {
                let t = mesh.indices[rng.below(mesh.indices.len())];
                let (a, b) = (mesh.positions[t[0] as usize], mesh.positions[t[1] as usize]);
                let target = if i % 4 == 1 {
                    a
                } else {
                    a + (b - a) * rng.f32()
                };
                target - o
            };
            total += 1;
            if geometry.intersect(&Ray::new(o, d)).is_none() {
                escapes += 1;
            }
        }
    }
    eprintln!("watertightness: {escapes} escapes out of {total} rays");
    assert_eq!(escapes, 0);
}

// ---------------------------------------------------------------------------------------
// Analytic shapes.

fn sphere_shape(center: Vec3, radius: f32, flip: bool) -> ShapeDesc {
    let mut s = shape("sphere", ShapeGeometry::Sphere { center, radius });
    s.flip_normals = flip;
    s
}

fn disk_shape(to_world: Mat4, flip: bool) -> ShapeDesc {
    let mut s = shape(
        "disk",
        ShapeGeometry::Disk {
            to_world: Transform::new(to_world).unwrap(),
        },
    );
    s.flip_normals = flip;
    s
}

#[test]
fn spheres_match_closed_form() {
    let mut rng = Random::new(0x5eed_0003);
    for (center, radius) in [
        (Vec3::new(0.3, -0.2, 0.1), 0.7f32),
        (Vec3::new(5e4, -2e4, 1e3), 250.0),
    ] {
        for flip in [false, true] {
            let g = Geometry::build(&[sphere_shape(center, radius, flip)]);
            let (c, r) = (center.as_dvec3(), radius as f64);
            let mut hits = 0;
            for _ in 0..20_000 {
                let o = center + rng.direction() * radius * (0.2 + 2.8 * rng.f32());
                let d = rng.direction();
                // Closed form: |o + t d − c|² = r², nearest positive root.
                let f = o.as_dvec3() - c;
                let (b, cc) = (f.dot(d.as_dvec3()), f.length_squared() - r * r);
                let disc = b * b - cc;
                let expected = (disc >= 0.0)
                    .then(|| [-b - disc.sqrt(), -b + disc.sqrt()])
                    .and_then(|ts| ts.into_iter().find(|&t| t > 0.0));
                let found = g.intersect(&Ray::new(o, d));
                assert_eq!(g.occluded(&Ray::new(o, d)), found.is_some());
                match (expected, found) {
                    (Some(t), Some(si)) => {
                        hits += 1;
                        assert!((si.t as f64 - t).abs() < 1e-5 * (t + r), "{} vs {t}", si.t);
                        let outward = (si.p.as_dvec3() - c).normalize().as_vec3();
                        let n = if flip { -outward } else { outward };
                        assert!((si.ng - n).length() < 1e-5 && si.ns == si.ng);
                        assert!(
                            ((si.p.as_dvec3() - c).length() - r).abs()
                                <= si.p_error.length() as f64 * 2.0
                        );
                        // Mitsuba's spherical uv.
                        let phi = outward.y.atan2(outward.x).rem_euclid(std::f32::consts::TAU);
                        let theta = outward.z.clamp(-1.0, 1.0).acos();
                        let uv =
                            Vec2::new(phi / std::f32::consts::TAU, theta / std::f32::consts::PI);
                        let du = (si.uv.x - uv.x).abs();
                        assert!(du.min(1.0 - du) < 1e-4 && (si.uv.y - uv.y).abs() < 1e-4);
                        assert_eq!((si.shape, si.primitive), (0, 0));
                    }
                    (None, None) => {}
                    (e, f) => {
                        // Only tangent rays may disagree.
                        assert!(
                            disc.abs() < 1e-6 * r * r,
                            "expected {e:?}, found {:?}",
                            f.map(|s| s.t)
                        );
                    }
                }
            }
            assert!(hits > 5000);
        }
    }
}

#[test]
fn disks_match_closed_form() {
    let mut rng = Random::new(0x5eed_0004);
    let to_world = Mat4::from_translation(Vec3::new(1.0, -2.0, 0.5))
        * Mat4::from_rotation_y(0.7)
        * Mat4::from_rotation_x(-0.4)
        * Mat4::from_scale(Vec3::new(2.0, 2.0, 1.0));
    let normal = to_world.transform_vector3(Vec3::Z).normalize(); // uniform xy scale: no shear
    let center = to_world.transform_point3(Vec3::ZERO);
    for flip in [false, true] {
        let g = Geometry::build(&[disk_shape(to_world, flip)]);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = center + rng.direction() * 4.0;
            // Aimed at the disk's surroundings: about half of the rays hit it.
            let d = center + (rng.vec3() - 0.5) * 6.0 - o;
            let denom = d.dot(normal) as f64;
            let t = (center - o).dot(normal) as f64 / denom;
            let local = to_world
                .inverse()
                .transform_point3((o.as_dvec3() + d.as_dvec3() * t).as_vec3());
            let r = local.truncate().length();
            let expected = t > 0.0 && r <= 1.0;
            let found = g.intersect(&Ray::new(o, d));
            if (r - 1.0).abs() < 1e-4 {
                continue; // the rim: f32 input rounding decides
            }
            assert_eq!(found.is_some(), expected);
            assert_eq!(g.occluded(&Ray::new(o, d)), expected);
            if let Some(si) = found {
                hits += 1;
                assert!((si.t as f64 - t).abs() < 1e-5 * t.max(1.0));
                assert!((si.ng - if flip { -normal } else { normal }).length() < 1e-5);
                assert!((si.uv.x - r).abs() < 1e-4);
                let phi = local.y.atan2(local.x).rem_euclid(std::f32::consts::TAU);
                let dv = (si.uv.y - phi / std::f32::consts::TAU).abs();
                assert!(dv.min(1.0 - dv) < 1e-4 || r < 1e-3);
            }
        }
        assert!(hits > 1000);
    }
}

#[test]
fn closest_hit_across_shape_kinds() {
    // A triangle wall, a sphere and a disk along the x axis: the nearest one wins.
    let wall = TriangleMesh {
        positions: vec![
            Vec3::new(10.0, -5.0, -5.0),
            Vec3::new(10.0, 5.0, -5.0),
            Vec3::new(10.0, 0.0, 5.0),
        ],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2]],
    };
    let disk = Mat4::from_translation(Vec3::new(6.0, 0.0, 0.0))
        * Mat4::from_rotation_y(-std::f32::consts::FRAC_PI_2);
    let shapes = vec![
        mesh_shape("wall", wall),
        sphere_shape(Vec3::new(3.0, 0.0, 0.0), 1.0, false),
        disk_shape(disk, false),
    ];
    let g = Geometry::build(&shapes);
    // The kernel query alone: (shape, t) from the closed forms (sphere at x = 3 − 1, disk at
    // x = 6 reached with |d| = 2, triangle wall at x = 10).
    for (ray, shape, t) in [
        (Ray::new(Vec3::ZERO, Vec3::X), 1, 2.0),
        (Ray::new(Vec3::new(4.5, 0.0, 0.0), Vec3::X * 2.0), 2, 0.75),
        (Ray::new(Vec3::new(7.0, 0.0, 0.0), Vec3::X), 0, 3.0),
    ] {
        let hit = g.closest_hit(&ray).unwrap();
        assert_eq!((hit.shape, hit.primitive), (shape, 0));
        assert!((hit.t - t).abs() < 1e-6, "shape {shape}: t = {}", hit.t);
        assert_eq!(g.interaction(&hit).t, hit.t);
    }
    let o = Vec3::ZERO;
    let si = g.intersect(&Ray::new(o, Vec3::X)).unwrap();
    assert_eq!(si.shape, 1);
    assert!((si.t - 2.0).abs() < 1e-6);
    let si = g
        .intersect(&Ray::new(Vec3::new(4.5, 0.0, 0.0), Vec3::X * 2.0))
        .unwrap();
    assert_eq!(si.shape, 2);
    assert!((si.t - 0.75).abs() < 1e-6, "t in units of |d|: {}", si.t);
    assert!(
        (si.ng - -Vec3::X).length() < 1e-6,
        "disk normal: local +z → world −x"
    );
    let si = g
        .intersect(&Ray::new(Vec3::new(7.0, 0.0, 0.0), Vec3::X))
        .unwrap();
    assert_eq!((si.shape, si.primitive), (0, 0));
    assert!(
        (si.ng - Vec3::X).length() < 1e-6,
        "(v1 − v0) × (v2 − v0) = +x: the ray sees the back"
    );
    assert!(g.occluded(&Ray {
        o,
        d: Vec3::X,
        t_max: 2.5
    }));
    assert!(!g.occluded(&Ray {
        o,
        d: Vec3::X,
        t_max: 1.9
    }));
    let b = g.bounds();
    assert!(
        b.min.cmple(Vec3::new(2.0, -5.0, -5.0)).all()
            && b.max.cmpge(Vec3::new(10.0, 5.0, 5.0)).all()
    );
}

#[test]
fn mesh_attributes_are_interpolated() {
    let mesh = TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        normals: Some(vec![
            Vec3::Z,
            Vec3::new(1.0, 0.0, 1.0).normalize(),
            Vec3::new(0.0, 1.0, 1.0).normalize(),
        ]),
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(0.0, 4.0),
        ]),
        indices: vec![[0, 1, 2]],
    };
    let plain = TriangleMesh {
        normals: None,
        uvs: None,
        ..mesh.clone()
    };
    let mut moved = plain.clone();
    moved.positions.iter_mut().for_each(|p| p.z -= 1.0);
    let g = Geometry::build(&[mesh_shape("attributes", mesh), mesh_shape("plain", moved)]);
    let si = g
        .intersect(&Ray::new(Vec3::new(0.25, 0.5, 1.0), -Vec3::Z))
        .unwrap();
    let (b1, b2) = (0.25, 0.5);
    assert!((si.uv - Vec2::new(2.0 * b1, 4.0 * b2)).length() < 1e-5);
    let n = (Vec3::Z * 0.25
        + Vec3::new(1.0, 0.0, 1.0).normalize() * b1
        + Vec3::new(0.0, 1.0, 1.0).normalize() * b2)
        .normalize();
    assert!((si.ns - n).length() < 1e-5 && si.ng == Vec3::Z);
    assert!((si.frame().n - si.ns).length() < 1e-6);
    // No attributes: barycentric uv, ns = ng.
    let si = g
        .intersect(&Ray::new(Vec3::new(0.25, 0.5, -0.5), -Vec3::Z))
        .unwrap();
    assert_eq!(si.shape, 1);
    assert!((si.uv - Vec2::new(b1, b2)).length() < 1e-5 && si.ns == si.ng);
}

#[test]
fn bad_input_does_not_panic() {
    let broken = TriangleMesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::X * 2.0,
        ],
        normals: Some(vec![Vec3::Z]), // wrong length: ignored
        uvs: None,
        indices: vec![[0, 1, 7], [0, 1, 2], [0, 1, 3], [0, 1, 1]],
    };
    let shapes = vec![
        mesh_shape("broken", broken),
        sphere_shape(Vec3::ZERO, -1.0, false),
        sphere_shape(Vec3::splat(f32::INFINITY), 1.0, false),
    ];
    let g = Geometry::build(&shapes);
    assert_eq!(g.triangle_count(), 0);
    assert_eq!(g.skipped(), (2, 4));
    assert!(g.bounds().is_empty());
    assert!(g.intersect(&Ray::new(Vec3::ONE, Vec3::X)).is_none());
    let empty = Geometry::build(&[]);
    assert!(empty.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
    assert!(!empty.occluded(&Ray::new(Vec3::ZERO, Vec3::X)));
    let g = Geometry::build(&cornell_box(1.0));
    for d in [
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::splat(f32::INFINITY),
    ] {
        assert!(g.intersect(&Ray::new(Vec3::splat(0.5), d)).is_none());
        assert!(!g.occluded(&Ray::new(Vec3::splat(0.5), d)));
    }
    assert!(
        g.intersect(&Ray {
            o: Vec3::splat(0.5),
            d: Vec3::X,
            t_max: f32::NAN
        })
        .is_none()
    );
    // A single triangle is a valid scene.
    let one = TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2]],
    };
    let g = Geometry::build(&[mesh_shape("one", one)]);
    assert!(
        g.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z))
            .is_some()
    );
}

// ---------------------------------------------------------------------------------------
// Self-intersection of spawned rays.

/// A scene at scale `s` translated by `offset`: the Cornell box with a closed mesh sphere,
/// an analytic sphere and a disk inside.
fn scaled_scene(s: f32, offset: Vec3) -> Vec<ShapeDesc> {
    let mut shapes = cornell_box(s);
    for sh in &mut shapes {
        if let ShapeGeometry::Mesh(m) = &mut sh.geometry {
            m.positions.iter_mut().for_each(|p| *p += offset);
        }
    }
    shapes.push(mesh_shape(
        "mesh_sphere",
        uv_sphere_with_triangles(offset + Vec3::new(0.7, 0.5, 0.3) * s, 0.12 * s, 2000),
    ));
    shapes.push(sphere_shape(
        offset + Vec3::new(0.3, 0.75, 0.3) * s,
        0.1 * s,
        false,
    ));
    let disk = Mat4::from_translation(offset + Vec3::new(0.5, 0.85, 0.6) * s)
        * Mat4::from_rotation_x(0.6)
        * Mat4::from_scale(Vec3::splat(0.08 * s));
    shapes.push(disk_shape(disk, false));
    shapes
}

fn same_surface(a: &SurfaceInteraction, b: &SurfaceInteraction) -> bool {
    (a.shape, a.primitive) == (b.shape, b.primitive)
}

/// The analytic sphere of `scaled_scene`.
struct SceneSphere {
    index: u32,
    center: Vec3,
    radius: f32,
}

/// Whether `next`, the closest hit of `ray` spawned from `from` (one or two surfaces), is a
/// self-intersection. A plane cannot be met again by a ray leaving it, so any hit of the
/// same triangle or disk is one. The sphere may legitimately be met again (a ray going
/// inward exits on the far side; a shadow ray may pass through it): the hit is false only
/// if the exact ray (f64, from the spawned origin) does not meet the sphere there.
fn self_hit(
    from: &[&SurfaceInteraction],
    ray: &Ray,
    next: &SurfaceInteraction,
    sphere: &SceneSphere,
) -> bool {
    if !from.iter().any(|f| same_surface(f, next)) {
        return false;
    }
    if next.shape != sphere.index {
        return true;
    }
    let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
    let f = o - sphere.center.as_dvec3();
    let r = sphere.radius as f64;
    let (a, b, c) = (d.length_squared(), f.dot(d), f.length_squared() - r * r);
    let disc = b * b - a * c;
    if disc < 0.0 {
        return true;
    }
    let roots = [(-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a];
    let tolerance = |t: f64| 1e-6 * (t + r / a.sqrt());
    !roots
        .iter()
        .any(|&t| t > 0.0 && (next.t as f64 - t).abs() <= tolerance(t))
}

#[test]
fn spawned_rays_do_not_self_intersect() {
    let mut rng = Random::new(0x5eed_0005);
    let configurations = [
        (1.0f32, Vec3::ZERO),
        (556.0, Vec3::ZERO),
        (1e3, Vec3::ZERO),
        (1e5, Vec3::ZERO),
        (1.0, Vec3::new(1e3, -1e3, 1e3)),
        (100.0, Vec3::new(5e4, 5e4, -5e4)),
    ];
    let mut report = Vec::new();
    let mut total_failures = 0;
    for (s, offset) in configurations {
        let shapes = scaled_scene(s, offset);
        let sphere = shapes
            .iter()
            .enumerate()
            .find_map(|(i, x)| match x.geometry {
                ShapeGeometry::Sphere { center, radius } => Some(SceneSphere {
                    index: i as u32,
                    center,
                    radius,
                }),
                _ => None,
            })
            .unwrap();
        let g = Geometry::build(&shapes);
        let (lo, hi) = (
            offset + Vec3::splat(0.02 * s),
            offset + Vec3::splat(0.98 * s),
        );
        let mut hits = Vec::new();
        let mut failures = [0u32; 4]; // reflected, transmitted, spawn_ray_to, to interaction
        let mut tests = 0;
        for _ in 0..40_000 {
            let o = rng.in_box(lo, hi);
            let Some(si) = g.intersect(&Ray::new(o, rng.direction())) else {
                continue;
            };
            let wi = (o - si.p).normalize();
            let incident_side = if wi.dot(si.ng) >= 0.0 { si.ng } else { -si.ng };
            // Reflection side: the mirror direction and a random one (often grazing);
            // transmission side: straight through and a random one.
            let mirror = -wi + si.ng * 2.0 * wi.dot(si.ng);
            let mut random = rng.direction();
            if random.dot(incident_side) < 0.0 {
                random = -random;
            }
            let mut through = rng.direction();
            if through.dot(incident_side) > 0.0 {
                through = -through;
            }
            for (k, w) in [(0, mirror), (0, random), (1, -wi), (1, through)] {
                tests += 1;
                let ray = si.spawn_ray(w);
                if let Some(next) = g.intersect(&ray)
                    && self_hit(&[&si], &ray, &next, &sphere)
                {
                    failures[k] += 1;
                }
            }
            hits.push(si);
        }
        // Shadow rays between pairs of hits on different surfaces.
        for pair in hits.chunks_exact(2) {
            let (a, b) = (&pair[0], &pair[1]);
            // Skip pairs on one plane (within their error bounds): the segment then runs
            // along the plane and may cross it legitimately where b's rounding puts b.
            let coplanar = |x: &SurfaceInteraction, y: &SurfaceInteraction| {
                (y.p - x.p).dot(x.ng).abs() <= 2.0 * x.ng.abs().dot(x.p_error + y.p_error)
            };
            if same_surface(a, b) || coplanar(a, b) || coplanar(b, a) {
                continue;
            }
            tests += 2;
            let ray = a.spawn_ray_to(b.p);
            if let Some(next) = g.intersect(&ray)
                && self_hit(&[a], &ray, &next, &sphere)
            {
                failures[2] += 1;
            }
            let ray = a.spawn_ray_to_interaction(b);
            if let Some(next) = g.intersect(&ray)
                && self_hit(&[a, b], &ray, &next, &sphere)
            {
                failures[3] += 1;
            }
        }
        report.push(format!(
            "scale {s:e} offset {offset}: {tests} rays, failures {failures:?}"
        ));
        total_failures += failures.iter().sum::<u32>();
    }
    eprintln!("{}", report.join("\n"));
    assert_eq!(total_failures, 0, "{}", report.join("\n"));
}

#[test]
fn build_does_not_depend_on_thread_count() {
    // Images must be bit-identical for any --threads: the same hits, ties included, whatever
    // the rayon pool that built the BVH.
    let shapes = vec![
        mesh_shape("mesh", cube_sphere(Vec3::ZERO, 1.0, 40)),
        mesh_shape(
            "uv",
            uv_sphere_with_triangles(Vec3::new(0.5, 0.1, 0.0), 0.7, 20_000),
        ),
    ];
    let mut rng = Random::new(0x5eed_0006);
    let rays: Vec<Ray> = (0..50_000)
        .map(|_| {
            Ray::new(
                rng.in_box(Vec3::splat(-1.5), Vec3::splat(1.5)),
                rng.direction(),
            )
        })
        .collect();
    let hits = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let g = pool.install(|| Geometry::build(&shapes));
        rays.iter()
            .map(|r| {
                g.intersect(r)
                    .map(|s| (s.shape, s.primitive, s.t.to_bits()))
            })
            .collect::<Vec<_>>()
    };
    let one = hits(1);
    assert!(one.iter().filter(|h| h.is_some()).count() > 10_000);
    assert_eq!(one, hits(3));
}

#[test]
fn stream_queries_match_single_ray_queries() {
    // `intersect_stream` interleaves several traversals; each must still find exactly what
    // `intersect` finds (same surface, same bits), whatever the mix of shapes, segment
    // lengths and unusable rays in the stream.
    let mut shapes = scaled_scene(1.0, Vec3::ZERO);
    shapes.push(mesh_shape(
        "dense",
        uv_sphere_with_triangles(Vec3::new(0.4, 0.3, 0.5), 0.2, 20_000),
    ));
    let g = Geometry::build(&shapes);
    let mut rng = Random::new(77);
    let b = g.bounds();
    let mut rays: Vec<Ray> = (0..20_000)
        .map(|i| {
            let mut ray = Ray::new(rng.in_box(b.min, b.max), rng.direction());
            if i % 3 == 0 {
                ray.t_max = rng.f32() * 0.5;
            }
            ray
        })
        .collect();
    rays[5].d = Vec3::ZERO;
    rays[6].o = Vec3::NAN;
    rays[7].t_max = -1.0;
    let mut out = Vec::new();
    g.intersect_stream(&rays, &mut out);
    assert_eq!(out.len(), rays.len());
    let mut hits = 0;
    for (ray, streamed) in rays.iter().zip(&out) {
        match (g.intersect(ray), streamed) {
            (None, None) => {}
            (Some(a), Some(s)) => {
                hits += 1;
                assert_eq!((a.shape, a.primitive), (s.shape, s.primitive), "{ray:?}");
                assert_eq!(a.t.to_bits(), s.t.to_bits(), "{ray:?}");
                assert_eq!(a.p, s.p, "{ray:?}");
                assert_eq!(a.ns, s.ns, "{ray:?}");
            }
            (a, s) => panic!(
                "{ray:?}: single {:?}, stream {:?}",
                a.is_some(),
                s.is_some()
            ),
        }
    }
    // The test means something only if most rays hit and some miss.
    assert!(hits > rays.len() / 2 && hits < rays.len(), "{hits} hits");
}

/// Sixteen rays per query (`closest_hits_lanes`, `surface_lanes`, `occluded_lanes`): each
/// lane must answer exactly as the per-ray queries do (same surface, same bits), on small
/// scenes tested sixteen rays per triangle and sphere (with and without analytic shapes),
/// on a small tree answered either way, and on a scene answered one ray at a time (a tree). The rays include ones aimed exactly at shared vertices (zero edge
/// functions), rays leaving surfaces (T near its error bound), short segments and rays
/// that cannot hit anything.
#[test]
fn packet_queries_match_single_ray_queries() {
    use mltbench::geometry::packet::{ClosestLanes, RayLanes};
    use mltbench::math::lanes::{F32x16, Mask16, V3};

    let mut small = cornell_box(1.0);
    small.push(mesh_shape(
        "rounded",
        cube_sphere(Vec3::new(0.6, 0.3, 0.4), 0.15, 1),
    ));
    // A small scene with analytic shapes: spheres (two overlapping, one with its normals
    // flipped, one that some rays start inside) and disks, tested in f64 lanes.
    let mut small_analytic = cornell_box(1.0);
    small_analytic.push(sphere_shape(Vec3::new(0.3, 0.3, 0.3), 0.2, false));
    small_analytic.push(sphere_shape(Vec3::new(0.42, 0.35, 0.3), 0.15, false));
    small_analytic.push(sphere_shape(Vec3::new(0.7, 0.35, 0.6), 0.25, true));
    let disk = Mat4::from_translation(Vec3::new(0.5, 0.85, 0.6))
        * Mat4::from_rotation_x(0.6)
        * Mat4::from_scale(Vec3::splat(0.2));
    small_analytic.push(disk_shape(disk, false));
    // A second, larger disk crossing the first and a sphere: the nearest of several
    // analytic hits must win in each lane.
    let disk = Mat4::from_translation(Vec3::new(0.45, 0.5, 0.5))
        * Mat4::from_rotation_y(0.9)
        * Mat4::from_scale(Vec3::splat(0.35));
    small_analytic.push(disk_shape(disk, true));
    // A small tree (49 to 112 triangles): full packets test every triangle in record
    // order, part-empty ones go through the tree in traversal order, and both must keep
    // the same hit (rays from inside the blocks meet their bottom faces and the floor
    // beneath at nearly the same t).
    let mut small_tree = cornell_box(1.0);
    small_tree.push(mesh_shape(
        "rounded",
        cube_sphere(Vec3::new(0.6, 0.3, 0.4), 0.15, 2),
    ));
    for (name, shapes) in [
        ("small", small),
        ("small and analytic", small_analytic),
        ("small tree", small_tree),
        ("tree and analytic", scaled_scene(1.0, Vec3::ZERO)),
    ] {
        let g = Geometry::build(&shapes);
        let n = g.triangle_count();
        if name == "small tree" {
            assert!(
                n > mltbench::geometry::flat::FLAT_LIMIT && n <= 112,
                "{n} triangles"
            );
        } else if name.starts_with("small") {
            assert!(n <= mltbench::geometry::flat::FLAT_LIMIT, "{n} triangles");
        }
        let vertices: Vec<Vec3> = shapes
            .iter()
            .filter_map(|s| match &s.geometry {
                ShapeGeometry::Mesh(m) => Some(m.positions.clone()),
                _ => None,
            })
            .flatten()
            .collect();
        let mut rng = Random::new(2024);
        let b = g.bounds();
        let mut rays: Vec<Ray> = Vec::new();
        for i in 0..16 * 4000 {
            let o = rng.in_box(b.min, b.max);
            let mut ray = match i % 4 {
                // At a vertex, exactly.
                0 => Ray::new(o, vertices[rng.below(vertices.len())] - o),
                // Leaving a surface.
                1 => match g.intersect(&Ray::new(o, rng.direction())) {
                    Some(si) => si.spawn_ray(rng.direction()),
                    None => Ray::new(o, rng.direction()),
                },
                // Along a plane through a vertex (a direction component of zero, the
                // origin on a face of the boxes around the records): the boxes that skip
                // records (`packet_boxes.rs`) must keep the triangles in that plane.
                3 if i % 8 == 7 => {
                    let v = vertices[rng.below(vertices.len())];
                    let k = rng.below(3);
                    let (mut o, mut d) = (o, rng.direction());
                    (o[k], d[k]) = (v[k], 0.0);
                    Ray::new(o, d)
                }
                _ => Ray::new(o, rng.direction()),
            };
            if i % 7 == 0 {
                ray.t_max = rng.f32() * 0.8;
            }
            rays.push(ray);
        }
        rays[3].d = Vec3::ZERO;
        rays[18].o = Vec3::NAN;
        rays[33].t_max = -1.0;
        let (mut hits, mut blocked, mut clear) = (0, 0, 0);
        let mut analytic_hits = 0;
        let mut closest = ClosestLanes::default();
        for (k, chunk) in rays.chunks_exact(16).enumerate() {
            let lanes =
                |f: &dyn Fn(&Ray) -> f32| F32x16::from_array(std::array::from_fn(|i| f(&chunk[i])));
            let packet = RayLanes {
                o: V3::new(lanes(&|r| r.o.x), lanes(&|r| r.o.y), lanes(&|r| r.o.z)),
                d: V3::new(lanes(&|r| r.d.x), lanes(&|r| r.d.y), lanes(&|r| r.d.z)),
                t_max: lanes(&|r| r.t_max),
            };
            // Some packets leave lanes out.
            let m = if k % 5 == 0 {
                Mask16(0xf0f3)
            } else {
                Mask16::ALL
            };
            g.closest_hits_lanes(&packet, m, &mut closest);
            let surface = g.surface_lanes(&closest, &packet);
            let occluded = g.occluded_lanes(&packet, m);
            let bits =
                |v: &V3<F32x16>, i: usize| [v.x, v.y, v.z].map(|c| c.to_array()[i].to_bits());
            for (i, ray) in chunk.iter().enumerate() {
                let want = if m.get(i) { g.intersect(ray) } else { None };
                assert_eq!(closest.hit.get(i), want.is_some(), "{name}: {ray:?}");
                assert_eq!(
                    occluded.get(i),
                    m.get(i) && g.occluded(ray),
                    "{name}: occluded {ray:?}"
                );
                blocked += occluded.get(i) as usize;
                clear += (m.get(i) && !occluded.get(i)) as usize;
                let Some(want) = want else {
                    continue;
                };
                hits += 1;
                analytic_hits +=
                    !matches!(shapes[want.shape as usize].geometry, ShapeGeometry::Mesh(_))
                        as usize;
                let got = g.interaction(&closest.closest_hit(&g, &packet, i).unwrap());
                assert_eq!((got.shape, got.primitive), (want.shape, want.primitive));
                assert_eq!(got.t.to_bits(), want.t.to_bits(), "{name}: {ray:?}");
                assert_eq!(got.p, want.p, "{name}: {ray:?}");
                let v = |x: Vec3| x.to_array().map(f32::to_bits);
                assert_eq!(bits(&surface.p, i), v(want.p), "{name}: p {ray:?}");
                assert_eq!(
                    bits(&surface.p_error, i),
                    v(want.p_error),
                    "{name}: {ray:?}"
                );
                assert_eq!(bits(&surface.ng, i), v(want.ng), "{name}: ng {ray:?}");
                assert_eq!(bits(&surface.ns, i), v(want.ns), "{name}: ns {ray:?}");
                assert_eq!(
                    (surface.shape.to_array()[i], surface.primitive.to_array()[i]),
                    (want.shape, want.primitive)
                );
            }
        }
        // Most rays hit, some miss, some segments are blocked and some not.
        assert!(
            hits > rays.len() / 2 && hits < rays.len(),
            "{name}: {hits} hits"
        );
        assert!(
            blocked > 100 && clear > 100,
            "{name}: {blocked} blocked, {clear} clear"
        );
        if name.contains("analytic") {
            assert!(
                analytic_hits > 1000,
                "{name}: {analytic_hits} analytic hits"
            );
        }
    }
}
