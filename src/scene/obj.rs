//! Wavefront OBJ meshes (via tobj).
//!
//! Every object and group of the file goes into one mesh. Faces are fan-triangulated
//! (0,1,2), (0,2,3), … like Mitsuba 3 does; points and lines are ignored; materials (`mtllib`)
//! are not read. A vertex is a distinct (position, uv, normal) index triple over the whole
//! file, numbered in order of first use, as Mitsuba 3 numbers them, so positions, normals and
//! uvs line up. Normals are kept only when every vertex has one (and are
//! normalised), uvs likewise; no normals are computed here.
//!
//! Texture coordinates are returned as written in the file. Mitsuba 3 flips them by default
//! (`v` → 1 − `v`, its `flip_tex_coords`), which is the scene loader's business.
//!
//! Before tobj parses the file, every `v`, `vt`, `vn` and `f` record is checked here, so
//! that bad input gets a message with its line and tobj never sees a record it could reject
//! or mishandle: vertex records need their numbers (x y z, u v, x y z; finite), and only
//! those go on to tobj (any further values are ignored, as Mitsuba 3 ignores a `w` or a
//! vertex colour); face indices must refer to records above them.

use std::io::Cursor;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::TriangleMesh;
use crate::error::{Error, Location, Result};

/// Reads every object of an OBJ file into one mesh in object space.
pub fn read_obj(path: &Path) -> Result<TriangleMesh> {
    crate::io::check_input_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        Error::input(
            Location::file(path),
            format!(
                "not a text file (invalid UTF-8 at byte {})",
                e.valid_up_to()
            ),
        )
    })?;
    let geometry = geometry_records(path, text)?;

    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj_buf(&mut Cursor::new(geometry), &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| Error::input(Location::file(path), format!("bad OBJ file: {e}")))?;

    merge_models(path, &models)
}

/// The file's geometry records, checked, as tobj should read them. Only these go to tobj:
/// without `o`, `g` and `usemtl` it sees one object and keeps one vertex table for the whole
/// file, so a vertex is shared by every face that names the same (v, vt, vn) triple, as in
/// Mitsuba 3 (this decides which faces a computed smooth normal averages over); it never
/// sees `l` records (which it would turn into polygons) nor material files.
///
/// Face indices (1-based, or negative = relative to the end) are checked against the `v`,
/// `vt` and `vn` records before them.
fn geometry_records(path: &Path, text: &str) -> Result<String> {
    let (mut positions, mut texcoords, mut normals) = (0i64, 0i64, 0i64);
    let mut faces = 0u64;
    let mut out = String::with_capacity(text.len());
    for (line_index, line) in text.lines().enumerate() {
        let line_number = u32::try_from(line_index + 1).unwrap_or(u32::MAX);
        let mut words = line.split_whitespace();
        match words.next() {
            Some(keyword @ ("v" | "vt" | "vn")) => {
                let (needed, what) = match keyword {
                    "v" => (3, "a position needs 3 numbers (x y z)"),
                    "vt" => (2, "a texture coordinate needs 2 numbers (u v)"),
                    _ => (3, "a normal needs 3 numbers (x y z)"),
                };
                let record_error = |message: String| {
                    let shown: String = line.trim().chars().take(40).collect();
                    Error::input(
                        Location::at(path, line_number, format!("`{shown}`")),
                        message,
                    )
                };
                let values: Vec<&str> = words.take(needed).collect();
                if values.len() < needed {
                    return Err(record_error(format!("{what}, got {}", values.len())));
                }
                let mut numbers = [0.0f32; 3];
                for (number, value) in numbers.iter_mut().zip(&values) {
                    *number = match value.parse::<f32>() {
                        Ok(x) if x.is_finite() => x,
                        Ok(_) => return Err(record_error(format!("`{value}` is not finite"))),
                        Err(_) => {
                            return Err(record_error(format!("`{value}` is not a number")));
                        }
                    };
                }
                if keyword == "vn" && Vec3::from(numbers).normalize_or_zero() == Vec3::ZERO {
                    return Err(record_error("the normal has zero length".into()));
                }
                out.push_str(keyword);
                for value in values {
                    out.push(' ');
                    out.push_str(value);
                }
                out.push('\n');
                match keyword {
                    "v" => positions += 1,
                    "vt" => texcoords += 1,
                    _ => normals += 1,
                }
            }
            Some("f") => {
                let face_error = |message: String| {
                    Error::input(
                        Location::at(path, line_number, format!("face {faces}")),
                        message,
                    )
                };
                for vertex in words {
                    let mut parts = vertex.split('/');
                    for (kind, kinds, count) in [
                        ("vertex", "vertices", positions),
                        ("texture coordinate", "texture coordinates", texcoords),
                        ("normal", "normals", normals),
                    ] {
                        let Some(part) = parts.next() else { break };
                        if part.is_empty() && kind != "vertex" {
                            continue;
                        }
                        let index: i64 = part.parse().map_err(|_| {
                            face_error(format!("`{vertex}` is not a valid face vertex"))
                        })?;
                        let valid = (1..=count).contains(&index) || (-count..=-1).contains(&index);
                        if !valid {
                            return Err(face_error(format!(
                                "{kind} index {index} is out of range ({count} {kinds} defined \
                                 above this line)"
                            )));
                        }
                    }
                    if parts.next().is_some() {
                        return Err(face_error(format!("`{vertex}` is not a valid face vertex")));
                    }
                }
                out.push_str(line);
                out.push('\n');
                faces += 1;
            }
            _ => {}
        }
    }
    Ok(out)
}

fn merge_models(path: &Path, models: &[tobj::Model]) -> Result<TriangleMesh> {
    let vertex_total: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    let all_have = |per_vertex: fn(&tobj::Mesh) -> usize| {
        models
            .iter()
            .all(|m| per_vertex(&m.mesh) == m.mesh.positions.len() / 3)
    };
    let keep_normals = all_have(|m| m.normals.len() / 3);
    let keep_uvs = all_have(|m| m.texcoords.len() / 2);

    let mut mesh = TriangleMesh {
        positions: Vec::with_capacity(vertex_total),
        normals: keep_normals.then(|| Vec::with_capacity(vertex_total)),
        uvs: keep_uvs.then(|| Vec::with_capacity(vertex_total)),
        indices: Vec::new(),
    };
    let bad = |message: String| Err(Error::input(Location::file(path), message));

    for model in models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        let count = m.positions.len() / 3;
        for (i, p) in m.positions.chunks_exact(3).enumerate() {
            let p = Vec3::new(p[0], p[1], p[2]);
            if !p.is_finite() {
                return bad(format!("vertex {i} has a non-finite position {p}"));
            }
            mesh.positions.push(p);
        }
        if let Some(normals) = &mut mesh.normals {
            for (i, n) in m.normals.chunks_exact(3).enumerate() {
                let n = Vec3::new(n[0], n[1], n[2]);
                let unit = n.normalize_or_zero();
                if !n.is_finite() || unit == Vec3::ZERO {
                    return bad(format!(
                        "vertex {i} has a normal {n} that is not finite or has zero length"
                    ));
                }
                normals.push(unit);
            }
        }
        if let Some(uvs) = &mut mesh.uvs {
            for (i, t) in m.texcoords.chunks_exact(2).enumerate() {
                let t = Vec2::new(t[0], t[1]);
                if !t.is_finite() {
                    return bad(format!("vertex {i} has non-finite texture coordinates {t}"));
                }
                uvs.push(t);
            }
        }
        if m.indices.len() % 3 != 0 {
            return bad("tobj returned faces that are not triangles".into());
        }
        for tri in m.indices.chunks_exact(3) {
            if tri.iter().any(|&i| i as usize >= count) {
                return bad("tobj returned a face with a missing vertex".into());
            }
            let offset = |i: u32| (base + i as usize) as u32;
            mesh.indices
                .push([offset(tri[0]), offset(tri[1]), offset(tri[2])]);
        }
    }
    Ok(mesh)
}
