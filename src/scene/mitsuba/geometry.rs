//! Shape geometry in world space: Mitsuba's built-in `rectangle` and `cube` as triangle
//! meshes, mesh placement (`to_world`, normals, `flip_normals`, degenerate triangles) and
//! analytic spheres.

use glam::{Vec2, Vec3};

use crate::math::Transform;
use crate::scene::TriangleMesh;

/// `rectangle`: [-1, 1]² in the xy plane, normal +z, uv = (p + 1) / 2.
pub(super) fn rectangle() -> TriangleMesh {
    TriangleMesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
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

/// `cube`: [-1, 1]³ as Mitsuba 3 builds it, four vertices per face (flat faces), every
/// face's uvs running from (0, 0) to (1, 1) in Mitsuba's orientation, counter-clockwise
/// seen from outside so every geometric normal points outward. The tables are Mitsuba's
/// mesh as `mitsuba.traverse` lists it (positions, texcoords, faces).
pub(super) fn cube() -> TriangleMesh {
    // Per face (−y, +y, +x, +z, −x, −z): its four corners in Mitsuba's order.
    const CORNERS: [[[f32; 3]; 4]; 6] = [
        [
            [1., -1., -1.],
            [1., -1., 1.],
            [-1., -1., 1.],
            [-1., -1., -1.],
        ],
        [[1., 1., -1.], [-1., 1., -1.], [-1., 1., 1.], [1., 1., 1.]],
        [[1., -1., -1.], [1., 1., -1.], [1., 1., 1.], [1., -1., 1.]],
        [[1., -1., 1.], [1., 1., 1.], [-1., 1., 1.], [-1., -1., 1.]],
        [
            [-1., -1., 1.],
            [-1., 1., 1.],
            [-1., 1., -1.],
            [-1., -1., -1.],
        ],
        [
            [1., 1., -1.],
            [1., -1., -1.],
            [-1., -1., -1.],
            [-1., 1., -1.],
        ],
    ];
    // The same uvs at the four corners of every face.
    const UVS: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
    let mut mesh = TriangleMesh {
        uvs: Some(Vec::new()),
        ..TriangleMesh::default()
    };
    for face in CORNERS {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(face.map(Vec3::from));
        if let Some(uvs) = &mut mesh.uvs {
            uvs.extend(UVS.map(Vec2::from));
        }
        mesh.indices.push([base, base + 1, base + 2]);
        mesh.indices.push([base + 3, base, base + 2]);
    }
    mesh
}

/// Reverses the winding of every triangle (the geometric normal turns around).
pub(super) fn reverse_winding(mesh: &mut TriangleMesh) {
    for tri in &mut mesh.indices {
        tri.swap(1, 2);
    }
}

/// Why a mesh could not be placed (the caller adds file and line).
#[derive(Debug)]
pub(super) enum MeshProblem {
    IndexOutOfRange {
        triangle: usize,
        index: u32,
    },
    AttributeCount {
        what: &'static str,
        got: usize,
        expected: usize,
    },
}

impl std::fmt::Display for MeshProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshProblem::IndexOutOfRange { triangle, index } => {
                write!(
                    f,
                    "triangle {triangle} uses vertex {index}, which does not exist"
                )
            }
            MeshProblem::AttributeCount {
                what,
                got,
                expected,
            } => {
                write!(f, "mesh has {got} {what} for {expected} vertices")
            }
        }
    }
}

/// Options of a mesh shape.
pub(super) struct Placement {
    pub to_world: Transform,
    /// Drop vertex normals: flat shading.
    pub face_normals: bool,
    pub flip_normals: bool,
}

/// Moves an object-space mesh to world space: positions by `to_world`, normals by its inverse
/// transpose (renormalised); drops triangles of zero area or with non-finite corners (counted
/// in the second result); gives meshes without normals smooth vertex normals unless
/// `face_normals`; applies `flip_normals` by reversing the winding and negating normals.
pub(super) fn place_mesh(
    mut mesh: TriangleMesh,
    placement: &Placement,
) -> Result<(TriangleMesh, usize), MeshProblem> {
    let vertex_count = mesh.positions.len();
    for (triangle, tri) in mesh.indices.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(MeshProblem::IndexOutOfRange { triangle, index });
        }
    }
    if let Some(normals) = &mesh.normals
        && normals.len() != vertex_count
    {
        return Err(MeshProblem::AttributeCount {
            what: "normals",
            got: normals.len(),
            expected: vertex_count,
        });
    }
    if let Some(uvs) = &mesh.uvs
        && uvs.len() != vertex_count
    {
        return Err(MeshProblem::AttributeCount {
            what: "texture coordinates",
            got: uvs.len(),
            expected: vertex_count,
        });
    }

    let to_world = &placement.to_world;
    for p in &mut mesh.positions {
        *p = to_world.point(*p);
    }
    if placement.face_normals {
        mesh.normals = None;
    }
    if let Some(normals) = &mut mesh.normals {
        for n in normals.iter_mut() {
            *n = to_world.normal(*n).normalize_or_zero();
        }
    }

    let before = mesh.indices.len();
    let positions = &mesh.positions;
    mesh.indices.retain(|&[a, b, c]| {
        let (p0, p1, p2) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        p0.is_finite()
            && p1.is_finite()
            && p2.is_finite()
            && (p1 - p0).cross(p2 - p0).normalize_or_zero() != Vec3::ZERO
    });
    let skipped = before - mesh.indices.len();

    if !placement.face_normals {
        let unusable = |n: &Vec3| *n == Vec3::ZERO || !n.is_finite();
        match &mesh.normals {
            None => mesh.normals = Some(smooth_normals(&mesh)),
            // Keep the file's normals; only replace ones that did not survive the transform.
            Some(normals) if normals.iter().any(unusable) => {
                let smooth = smooth_normals(&mesh);
                if let Some(normals) = &mut mesh.normals {
                    for (n, s) in normals.iter_mut().zip(smooth) {
                        if unusable(n) {
                            *n = s;
                        }
                    }
                }
            }
            Some(_) => {}
        }
    }

    if placement.flip_normals {
        reverse_winding(&mut mesh);
        if let Some(normals) = &mut mesh.normals {
            for n in normals.iter_mut() {
                *n = -*n;
            }
        }
    }
    Ok((mesh, skipped))
}

/// Smooth vertex normals as Mitsuba computes them: each triangle's unit normal weighted by its
/// angle at the vertex (Thürmer and Wüthrich 1998, "Computing Vertex Normals from Polygonal
/// Facets", JGT 3(1)). Vertices used by no triangle, or whose weighted sum vanishes, get the
/// normal of a triangle touching them, or +z.
pub(super) fn smooth_normals(mesh: &TriangleMesh) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; mesh.positions.len()];
    let mut fallback = vec![Vec3::Z; mesh.positions.len()];
    for tri in &mesh.indices {
        let p = tri.map(|i| mesh.positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        if n == Vec3::ZERO {
            continue;
        }
        for corner in 0..3 {
            let here = p[corner];
            let e1 = (p[(corner + 1) % 3] - here).normalize_or_zero();
            let e2 = (p[(corner + 2) % 3] - here).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            let vertex = tri[corner] as usize;
            sums[vertex] += n * angle;
            fallback[vertex] = n;
        }
    }
    sums.iter()
        .zip(fallback)
        .map(|(sum, fallback)| {
            let n = sum.normalize_or_zero();
            if n == Vec3::ZERO || !n.is_finite() {
                fallback
            } else {
                n
            }
        })
        .collect()
}

/// Center and radius of Mitsuba's `sphere`: the unit sphere under
/// to_world · translate(center) · scale(radius), which must be a similarity.
pub(super) fn sphere(
    to_world: &Transform,
    center: Vec3,
    radius: f32,
) -> Result<(Vec3, f32), &'static str> {
    let m = to_world.matrix;
    let columns = [
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    ];
    let lengths = columns.map(|c| c.length());
    let scale = lengths[0];
    // Equal column lengths and orthogonal columns: rotation times uniform scale. The
    // tolerance is relative, so it holds at any scene scale.
    let tolerance = 1e-4 * scale;
    let uniform = lengths.iter().all(|l| (l - scale).abs() <= tolerance)
        && (0..3).all(|i| {
            let j = (i + 1) % 3;
            columns[i].dot(columns[j]).abs() <= tolerance * scale
        });
    if !uniform {
        return Err(
            "sphere to_world must be a uniform scale with rotations and translations \
                    (a non-uniform scale or shear would make an ellipsoid)",
        );
    }
    let world_center = to_world.point(center);
    let world_radius = radius * scale;
    if !(world_radius > 0.0 && world_radius.is_finite() && world_center.is_finite()) {
        return Err("sphere radius in world space must be positive and finite");
    }
    Ok((world_center, world_radius))
}
