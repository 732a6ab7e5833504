//! Meshes built in code, for tests and benchmarks: a Cornell box, UV spheres, closed
//! cube-spheres with shared vertices, and a smooth displaced sphere of about a million
//! triangles. Everything is returned in world space, ready for `Geometry::build`.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use crate::scene::{ShapeDesc, ShapeGeometry, TriangleMesh};

/// A shape with default material settings (bsdf 0, no emitter, no media).
pub fn shape(name: &str, geometry: ShapeGeometry) -> ShapeDesc {
    ShapeDesc {
        name: name.to_string(),
        geometry,
        bsdf: 0,
        emitter: None,
        flip_normals: false,
        interior_medium: None,
        exterior_medium: None,
    }
}

/// A mesh shape with default material settings.
pub fn mesh_shape(name: &str, mesh: TriangleMesh) -> ShapeDesc {
    shape(name, ShapeGeometry::Mesh(mesh))
}

/// A planar quad `corner, corner + a, corner + a + b, corner + b` as two triangles whose
/// front side (counter-clockwise winding) faces `a × b`.
pub fn quad(corner: Vec3, a: Vec3, b: Vec3) -> TriangleMesh {
    TriangleMesh {
        positions: vec![corner, corner + a, corner + a + b, corner + b],
        normals: None,
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// An oriented box with outward faces: base centre `base`, half extents `half` (x, z) and
/// height `height`, rotated by `angle_y` radians about the vertical axis.
fn block(base: Vec3, half_x: f32, half_z: f32, height: f32, angle_y: f32) -> TriangleMesh {
    let (s, c) = angle_y.sin_cos();
    let ex = Vec3::new(c, 0.0, -s) * (2.0 * half_x);
    let ez = Vec3::new(s, 0.0, c) * (2.0 * half_z);
    let ey = Vec3::new(0.0, height, 0.0);
    let o = base - ex * 0.5 - ez * 0.5;
    // Six faces, each with its two edge vectors ordered so that a × b points outward.
    let faces = [
        (o, ex, ez),      // bottom (-y)
        (o + ey, ez, ex), // top (+y)
        (o, ey, ex),      // -z side
        (o + ez, ex, ey), // +z side
        (o, ez, ey),      // -x side
        (o + ex, ey, ez), // +x side
    ];
    let mut mesh = TriangleMesh::default();
    for (corner, a, b) in faces {
        append(&mut mesh, &quad(corner, a, b));
    }
    mesh
}

/// Appends `other` to `mesh` (attributes are kept only when both have them).
pub fn append(mesh: &mut TriangleMesh, other: &TriangleMesh) {
    let base = mesh.positions.len() as u32;
    let first = mesh.indices.is_empty();
    mesh.normals = match (first, mesh.normals.take(), &other.normals) {
        (true, _, Some(n)) => Some(n.clone()),
        (false, Some(mut a), Some(b)) => {
            a.extend_from_slice(b);
            Some(a)
        }
        _ => None,
    };
    mesh.uvs = match (first, mesh.uvs.take(), &other.uvs) {
        (true, _, Some(u)) => Some(u.clone()),
        (false, Some(mut a), Some(b)) => {
            a.extend_from_slice(b);
            Some(a)
        }
        _ => None,
    };
    mesh.positions.extend_from_slice(&other.positions);
    mesh.indices.extend(
        other
            .indices
            .iter()
            .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
    );
}

/// A Cornell-box-like room of side `size` with its corner at the origin: floor (y = 0),
/// ceiling, back wall (z = size), left (x = 0) and right walls facing inward, the front
/// (z = 0) open; a short and a tall block standing on the floor; and a square light just
/// below the ceiling facing down. One shape per part (8 shapes, 36 triangles).
/// A camera at (size/2, size/2, -1.4·size) looking along +z sees all of it.
pub fn cornell_box(size: f32) -> Vec<ShapeDesc> {
    let s = size;
    let x = Vec3::X * s;
    let y = Vec3::Y * s;
    let z = Vec3::Z * s;
    let light_half = 0.12 * s;
    let light_corner = Vec3::new(0.5 * s - light_half, 0.998 * s, 0.5 * s - light_half);
    vec![
        mesh_shape("floor", quad(Vec3::ZERO, z, x)),
        mesh_shape("ceiling", quad(y, x, z)),
        mesh_shape("back", quad(z, y, x)),
        mesh_shape("left", quad(Vec3::ZERO, y, z)),
        mesh_shape("right", quad(x, z, y)),
        mesh_shape(
            "short_block",
            block(
                Vec3::new(0.66 * s, 0.0, 0.35 * s),
                0.15 * s,
                0.15 * s,
                0.3 * s,
                -0.29,
            ),
        ),
        mesh_shape(
            "tall_block",
            block(
                Vec3::new(0.33 * s, 0.0, 0.65 * s),
                0.15 * s,
                0.15 * s,
                0.6 * s,
                0.29,
            ),
        ),
        mesh_shape(
            "light",
            quad(
                light_corner,
                Vec3::X * (2.0 * light_half),
                Vec3::Z * (2.0 * light_half),
            ),
        ),
    ]
}

/// A closed UV sphere with shared vertices (one vertex per pole, the seam shared), outward
/// counter-clockwise faces and radial vertex normals; no uvs (the seam would need split
/// vertices). `rings` ≥ 2 latitude bands, `segments` ≥ 3 longitude steps:
/// 2·segments·(rings − 1) triangles.
pub fn uv_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> TriangleMesh {
    let rings = rings.max(2);
    let segments = segments.max(3);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut push = |n: Vec3| {
        positions.push(center + n * radius);
        normals.push(n);
    };
    push(Vec3::Z); // north pole: index 0
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            push(Vec3::new(st * cp, st * sp, ct));
        }
    }
    push(-Vec3::Z); // south pole: last index
    let south = 1 + (rings - 1) * segments;
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut indices = Vec::with_capacity(2 * (segments * (rings - 1)) as usize);
    for j in 0..segments {
        // Counter-clockwise seen from outside: phi grows anticlockwise about +z.
        indices.push([0, ring(1, j), ring(1, j + 1)]);
        indices.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            indices.push([a, c, d]);
            indices.push([a, d, b]);
        }
    }
    TriangleMesh {
        positions,
        normals: Some(normals),
        uvs: None,
        indices,
    }
}

/// A UV sphere with about `triangles` triangles (twice as many segments as rings).
pub fn uv_sphere_with_triangles(center: Vec3, radius: f32, triangles: u32) -> TriangleMesh {
    let rings = ((triangles as f32 / 4.0).sqrt().round() as u32).max(2);
    uv_sphere(center, radius, rings, 2 * rings)
}

/// The unit cube [-1, 1]³ subdivided into an n×n grid per face, mapped onto the unit
/// sphere, as directions with shared vertices (12·n² triangles, outward CCW faces).
fn cube_sphere_directions(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let n = n.max(1);
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::new();
    let mut dirs = Vec::new();
    let mut vertex = |key: [u32; 3]| -> u32 {
        *index_of.entry(key).or_insert_with(|| {
            let c = Vec3::new(key[0] as f32, key[1] as f32, key[2] as f32) * (2.0 / n as f32)
                - Vec3::ONE;
            // Cube to sphere with near-uniform cells: each coordinate is scaled by
            // sqrt(1 − b²/2 − c²/2 + b²c²/3) (the "spherified cube" map).
            let s = c * c;
            let m = Vec3::new(
                c.x * (1.0 - s.y / 2.0 - s.z / 2.0 + s.y * s.z / 3.0)
                    .max(0.0)
                    .sqrt(),
                c.y * (1.0 - s.z / 2.0 - s.x / 2.0 + s.z * s.x / 3.0)
                    .max(0.0)
                    .sqrt(),
                c.z * (1.0 - s.x / 2.0 - s.y / 2.0 + s.x * s.y / 3.0)
                    .max(0.0)
                    .sqrt(),
            );
            dirs.push(m.normalize());
            (dirs.len() - 1) as u32
        })
    };
    let mut indices = Vec::with_capacity(12 * (n * n) as usize);
    for axis in 0..3 {
        for side in [0, n] {
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            // Outward normal along +axis when side = n: u × v = +axis, so keep the order;
            // on the side = 0 face reverse it.
            let flip = side == 0;
            for a in 0..n {
                for b in 0..n {
                    let key = |du: u32, dv: u32| {
                        let mut k = [0u32; 3];
                        k[axis] = side;
                        k[u_axis] = a + du;
                        k[v_axis] = b + dv;
                        k
                    };
                    let (p00, p10) = (vertex(key(0, 0)), vertex(key(1, 0)));
                    let (p11, p01) = (vertex(key(1, 1)), vertex(key(0, 1)));
                    if flip {
                        indices.push([p00, p11, p10]);
                        indices.push([p00, p01, p11]);
                    } else {
                        indices.push([p00, p10, p11]);
                        indices.push([p00, p11, p01]);
                    }
                }
            }
        }
    }
    (dirs, indices)
}

/// A closed, watertight sphere mesh with shared vertices: a subdivided cube projected onto
/// the sphere, 12·n² triangles, outward faces, radial vertex normals.
pub fn cube_sphere(center: Vec3, radius: f32, n: u32) -> TriangleMesh {
    let (dirs, indices) = cube_sphere_directions(n);
    TriangleMesh {
        positions: dirs.iter().map(|&d| center + d * radius).collect(),
        normals: Some(dirs),
        uvs: None,
        indices,
    }
}

/// Radius factor of the displaced sphere in direction `d` (unit): a few low-frequency
/// sinusoids, between about 0.8 and 1.2.
pub fn displacement(d: Vec3) -> f32 {
    1.0 + 0.08 * (5.0 * d.x + 0.3).sin() * (4.0 * d.y + 1.1).sin()
        + 0.06 * (7.0 * d.z + 2.0).sin()
        + 0.04 * (3.0 * (d.x + d.y - d.z)).cos()
}

/// A smooth, closed, displaced sphere: the cube-sphere of resolution `n` (12·n² triangles;
/// n = 289 gives 1 002 252) with its radius modulated by `displacement`, and smooth vertex
/// normals (area-weighted face normals).
pub fn displaced_sphere(center: Vec3, radius: f32, n: u32) -> TriangleMesh {
    let (dirs, indices) = cube_sphere_directions(n);
    let positions: Vec<Vec3> = dirs
        .iter()
        .map(|&d| center + d * (radius * displacement(d)))
        .collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &indices {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a); // length = twice the area: area weighting
        for &i in t {
            normals[i as usize] += n;
        }
    }
    for n in &mut normals {
        *n = n.normalize();
    }
    TriangleMesh {
        positions,
        normals: Some(normals),
        uvs: None,
        indices,
    }
}

/// The displaced sphere with about a million triangles (n = 289).
pub fn displaced_sphere_1m(center: Vec3, radius: f32) -> TriangleMesh {
    displaced_sphere(center, radius, 289)
}

/// The benchmark's first scene: the Cornell box of side `size` with a ~100k-triangle UV
/// sphere of radius 0.2·size resting on its floor.
pub fn cornell_box_with_sphere(size: f32) -> Vec<ShapeDesc> {
    let mut shapes = cornell_box(size);
    let center = Vec3::new(0.5 * size, 0.2 * size, 0.3 * size);
    shapes.push(mesh_shape(
        "uv_sphere",
        uv_sphere_with_triangles(center, 0.2 * size, 100_000),
    ));
    shapes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every edge of a closed mesh with shared vertices is used exactly twice, once in each
    /// direction (consistent orientation, no cracks).
    fn assert_closed(mesh: &TriangleMesh) {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &mesh.indices {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(count, 1, "edge {a}-{b} used {count} times in one direction");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
    }

    fn signed_volume(mesh: &TriangleMesh) -> f32 {
        let p = &mesh.positions;
        mesh.indices
            .iter()
            .map(|t| p[t[0] as usize].dot(p[t[1] as usize].cross(p[t[2] as usize])) / 6.0)
            .sum()
    }

    #[test]
    fn spheres_are_closed_and_outward() {
        let uv = uv_sphere(Vec3::ZERO, 2.0, 10, 20);
        assert_eq!(uv.indices.len(), 2 * 20 * 9);
        assert_closed(&uv);
        let cs = cube_sphere(Vec3::ZERO, 2.0, 8);
        assert_eq!(cs.indices.len(), 12 * 64);
        assert_closed(&cs);
        // Outward orientation: positive volume close to the ball's 4/3·π·r³ (inscribed).
        let ball = 4.0 / 3.0 * std::f32::consts::PI * 8.0;
        for m in [&uv, &cs] {
            let v = signed_volume(m);
            assert!(v > 0.9 * ball && v < ball, "volume {v} vs {ball}");
        }
        let ds = displaced_sphere(Vec3::ZERO, 1.0, 8);
        assert_closed(&ds);
        assert!(signed_volume(&ds) > 0.0);
    }

    #[test]
    fn cornell_box_faces_inward_and_blocks_outward() {
        let shapes = cornell_box(2.0);
        let centre = Vec3::splat(1.0);
        for s in &shapes {
            let ShapeGeometry::Mesh(m) = &s.geometry else {
                panic!()
            };
            for t in &m.indices {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                let n = (b - a).cross(c - a);
                let mid = (a + b + c) / 3.0;
                if s.name.ends_with("block") {
                    // outward: away from the block's own centroid
                    let bc = m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
                    assert!(n.dot(mid - bc) > 0.0, "{}", s.name);
                } else if s.name == "light" {
                    assert!(n.y < 0.0);
                } else {
                    assert!(n.dot(centre - mid) > 0.0, "{} faces outward", s.name);
                }
            }
        }
    }
}
