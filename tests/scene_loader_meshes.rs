//! The Mitsuba XML loader with the parts it calls into: the OBJ/PLY readers
//! (`scene::obj`, `scene::ply`) and the spectra (`scene::spectra`). Values are computed by hand
//! where the loader does the work (placement, normals, winding, degenerate triangles), and
//! compared with direct calls where the other module does (spectrum conversion, named IORs).

mod loader_support;

use glam::{Vec2, Vec3};
use loader_support::*;
use mltbench::math::Rgb;
use mltbench::scene::mitsuba::load_file;
use mltbench::scene::spectra::{SpectrumUse, named_conductor, named_ior, spectrum_to_rgb};
use mltbench::scene::*;

const TOL: f32 = 1e-5;

fn mesh_of(shape: &ShapeDesc) -> &TriangleMesh {
    match &shape.geometry {
        ShapeGeometry::Mesh(mesh) => mesh,
        other => panic!("expected a mesh, got {other:?}"),
    }
}

/// Geometric unit normal of triangle `t`.
fn face_normal(mesh: &TriangleMesh, t: usize) -> Vec3 {
    let p = mesh.indices[t].map(|i| mesh.positions[i as usize]);
    (p[1] - p[0]).cross(p[2] - p[0]).normalize()
}

/// The vertex of `mesh` at `p` (meshes are small; positions are exact here).
fn vertex_at(mesh: &TriangleMesh, p: Vec3) -> usize {
    mesh.positions
        .iter()
        .position(|q| approx_v(*q, p, TOL))
        .expect("vertex present")
}

fn obj_scene(test: &str, obj: &str, shape_body: &str) -> SceneDescription {
    let dir = scratch(test);
    write(&dir, "mesh.obj", obj);
    let text = scene(&format!(
        r#"<shape type="obj"><string name="filename" value="mesh.obj"/>{shape_body}</shape>"#
    ));
    match load_written(&dir, &text) {
        Ok(desc) => desc,
        Err(e) => panic!("{e}"),
    }
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

#[test]
fn obj_mesh_is_placed_in_world_space() {
    let desc = obj_scene(
        "obj_placed",
        QUAD,
        r#"<transform name="to_world"><scale value="2"/><translate value="0, 0, 5"/></transform>"#,
    );
    let mesh = mesh_of(&desc.shapes[0]);
    assert_eq!(mesh.indices.len(), 2);
    for p in [
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(2.0, 0.0, 5.0),
        Vec3::new(2.0, 2.0, 5.0),
    ] {
        vertex_at(mesh, p);
    }
    for t in 0..2 {
        assert!(approx_v(face_normal(mesh, t), Vec3::Z, TOL));
    }
    // A flat mesh without normals gets smooth normals equal to its face normal.
    let normals = mesh.normals.as_ref().expect("smooth normals computed");
    assert!(normals.iter().all(|n| approx_v(*n, Vec3::Z, TOL)));
    assert_eq!(desc.files_read.len(), 2);
    assert!(desc.files_read[1].ends_with("mesh.obj"));
}

#[test]
fn smooth_normals_are_angle_weighted_like_mitsuba() {
    // Two triangles share vertex A = 0: triangle 1 (A, B, C) with normal +z and angle 90° at
    // A; triangle 2 (A, C, D) with normal (1,0,1)/√2 and angle acos(1/√3) at A. Angle
    // weighting (Thürmer & Wüthrich) differs from area weighting here (areas 1/2 and √2/2).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 1 1\nf 1 2 3\nf 1 3 4\n";
    let desc = obj_scene("angle_weighted", obj, "");
    let mesh = mesh_of(&desc.shapes[0]);
    let normals = mesh.normals.as_ref().expect("normals");
    let n2 = Vec3::new(1.0, 0.0, 1.0) / 2f32.sqrt();
    let expected_a =
        (Vec3::Z * std::f32::consts::FRAC_PI_2 + n2 * (1.0 / 3f32.sqrt()).acos()).normalize();
    assert!(approx_v(
        normals[vertex_at(mesh, Vec3::ZERO)],
        expected_a,
        1e-5
    ));
    // B is used by triangle 1 only, D by triangle 2 only.
    assert!(approx_v(normals[vertex_at(mesh, Vec3::X)], Vec3::Z, 1e-5));
    assert!(approx_v(
        normals[vertex_at(mesh, Vec3::new(-1.0, 1.0, 1.0))],
        n2,
        1e-5
    ));
}

#[test]
fn file_normals_follow_the_inverse_transpose_and_face_normals_drops_them() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 1 0\nf 1//1 2//1 3//1\n";
    let scale_x = r#"<transform name="to_world"><scale x="2"/></transform>"#;
    let desc = obj_scene("file_normals", obj, scale_x);
    let normals = mesh_of(&desc.shapes[0])
        .normals
        .as_ref()
        .expect("normals kept");
    // (1,1,0) under diag(2,1,1)⁻ᵀ = diag(1/2,1,1): (1/2, 1, 0), normalised.
    let expected = Vec3::new(0.5, 1.0, 0.0).normalize();
    assert!(normals.iter().all(|n| approx_v(*n, expected, TOL)));
    let desc = obj_scene(
        "face_normals",
        obj,
        &format!(r#"{scale_x}<boolean name="face_normals" value="true"/>"#),
    );
    assert!(mesh_of(&desc.shapes[0]).normals.is_none());
}

#[test]
fn flip_normals_reverses_winding_and_negates_normals() {
    let plain = obj_scene("flip_plain", QUAD, "");
    let flipped = obj_scene(
        "flip",
        QUAD,
        r#"<boolean name="flip_normals" value="true"/>"#,
    );
    let (a, b) = (mesh_of(&plain.shapes[0]), mesh_of(&flipped.shapes[0]));
    assert_eq!(a.positions, b.positions);
    for (ta, tb) in a.indices.iter().zip(&b.indices) {
        assert_eq!([ta[0], ta[2], ta[1]], *tb);
    }
    for t in 0..b.indices.len() {
        assert!(approx_v(face_normal(b, t), -Vec3::Z, TOL));
    }
    let (na, nb) = (a.normals.as_ref().unwrap(), b.normals.as_ref().unwrap());
    for (x, y) in na.iter().zip(nb) {
        assert_eq!(*x, -*y);
    }
    assert!(flipped.shapes[0].flip_normals);
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    // Triangle 2 has collinear corners, triangle 3 repeats a vertex.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 3 3 1\n";
    let dir = scratch("degenerate");
    write(&dir, "mesh.obj", obj);
    write(&dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    let text = scene(
        r#"<shape type="obj"><string name="filename" value="mesh.obj"/></shape>
<shape type="obj"><string name="filename" value="flat.obj"/></shape>"#,
    );
    let desc = load_written(&dir, &text).expect("loads");
    assert_eq!(desc.skipped_triangles, 3);
    assert_eq!(desc.shapes.len(), 1, "the mesh left empty is dropped");
    assert_eq!(mesh_of(&desc.shapes[0]).indices.len(), 1);
    assert!(
        desc.warnings
            .iter()
            .any(|w| w.contains("2 degenerate") && w.contains("scene.xml:2"))
    );
    let skipped: Vec<&String> = desc
        .warnings
        .iter()
        .filter(|w| w.contains("shape skipped"))
        .collect();
    assert_eq!(skipped.len(), 1, "{:?}", desc.warnings);
    assert!(
        skipped[0].contains("all 1 triangles") && skipped[0].contains("scene.xml:3"),
        "{}",
        skipped[0]
    );
    // Nothing else left: the scene is empty, and the error says why (warnings are printed
    // only with a scene that loads).
    let text = scene(r#"<shape type="obj"><string name="filename" value="flat.obj"/></shape>"#);
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert!(message.contains("no shapes"), "{message}");
    assert!(
        message.contains("scene.xml:2") && message.contains("degenerate"),
        "{message}"
    );
    // The same for a mesh file without faces.
    write(&dir, "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    let text = scene(r#"<shape type="obj"><string name="filename" value="points.obj"/></shape>"#);
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert!(
        message.contains("scene.xml:2") && message.contains("no faces"),
        "{message}"
    );
}

#[test]
fn obj_texture_coordinates_are_flipped_by_default() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.25\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let desc = obj_scene("uv_flip", obj, "");
    let mesh = mesh_of(&desc.shapes[0]);
    let uvs = mesh.uvs.as_ref().expect("uvs");
    assert_eq!(uvs[vertex_at(mesh, Vec3::ZERO)], Vec2::new(0.25, 0.75));
    let desc = obj_scene(
        "uv_keep",
        obj,
        r#"<boolean name="flip_tex_coords" value="false"/>"#,
    );
    let mesh = mesh_of(&desc.shapes[0]);
    assert_eq!(
        mesh.uvs.as_ref().unwrap()[vertex_at(mesh, Vec3::ZERO)],
        Vec2::new(0.25, 0.25)
    );
}

#[test]
fn ply_meshes_load_and_get_smooth_normals() {
    let dir = scratch("ply");
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    write(&dir, "meshes/quad.ply", ply);
    let text = scene(
        r#"<path value="meshes"/>
           <shape type="ply"><string name="filename" value="quad.ply"/>
             <transform name="to_world"><rotate x="1" angle="-90"/></transform></shape>"#,
    );
    let desc = load_written(&dir, &text).expect("loads");
    let mesh = mesh_of(&desc.shapes[0]);
    assert_eq!(mesh.indices.len(), 2);
    for t in 0..2 {
        assert!(approx_v(face_normal(mesh, t), Vec3::Y, TOL));
    }
    assert!(
        mesh.normals
            .as_ref()
            .unwrap()
            .iter()
            .all(|n| approx_v(*n, Vec3::Y, TOL))
    );
    assert_eq!(
        desc.files_read,
        vec![dir.join("scene.xml"), dir.join("meshes/quad.ply")]
    );
}

#[test]
fn mesh_reader_errors_are_located_in_the_scene() {
    let dir = scratch("mesh_errors");
    let obj = write(&dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    let text = scene("<shape type=\"obj\">\n<string name=\"filename\" value=\"bad.obj\"/></shape>");
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert_names(&message, &dir.join("scene.xml"), 2);
    assert!(
        message.contains(&obj.display().to_string()),
        "names the mesh file: {message}"
    );
    // A missing mesh file is found missing before any reader runs.
    let text =
        scene("<shape type=\"ply\">\n<string name=\"filename\" value=\"none.ply\"/></shape>");
    let message = load_written(&dir, &text).unwrap_err().to_string();
    assert_names(&message, &dir.join("scene.xml"), 3);
    assert!(message.contains("none.ply"), "{message}");
}

// ---------------------------------------------------------------------------------------
// Spectra and named IORs

const PAIRS: [(f32, f32); 4] = [(400.0, 0.1), (500.0, 0.4), (600.0, 0.7), (700.0, 0.6)];

#[test]
fn spectra_are_converted_for_their_use() {
    let value = "400:0.1, 500:0.4, 600:0.7, 700:0.6";
    let desc = load_ok(
        "spectra_use",
        &scene(&format!(
            r#"<shape type="sphere">
                 <bsdf type="diffuse"><spectrum name="reflectance" value="{value}"/></bsdf>
                 <emitter type="area"><spectrum name="radiance" value="{value}"/></emitter>
               </shape>
               <shape type="sphere"><bsdf type="conductor">
                 <spectrum name="eta" value="{value}"/><spectrum name="k" value="{value}"/>
               </bsdf></shape>"#
        )),
    );
    let reflectance = spectrum_to_rgb(&PAIRS, SpectrumUse::Reflectance);
    let emission = spectrum_to_rgb(&PAIRS, SpectrumUse::Emission);
    let unbounded = spectrum_to_rgb(&PAIRS, SpectrumUse::Unbounded);
    assert_eq!(
        desc.bsdfs[desc.shapes[0].bsdf],
        BsdfDesc::Diffuse { reflectance }
    );
    assert_eq!(
        desc.emitters[0],
        EmitterDesc::Area {
            radiance: emission,
            shape: 0
        }
    );
    assert_eq!(
        desc.bsdfs[desc.shapes[1].bsdf],
        BsdfDesc::Conductor {
            eta_k: Some((unbounded, unbounded)),
            specular_reflectance: Rgb::splat(1.0)
        }
    );
}

#[test]
fn named_iors_and_conductors() {
    let desc = load_ok(
        "named",
        &scene(
            r#"<shape type="sphere"><bsdf type="dielectric">
                 <string name="int_ior" value="water"/><string name="ext_ior" value="Vacuum"/></bsdf></shape>
               <shape type="sphere"><bsdf type="conductor"><string name="material" value="Au"/></bsdf></shape>
               <shape type="sphere"><bsdf type="roughplastic"><string name="int_ior" value="diamond"/></bsdf></shape>"#,
        ),
    );
    let water = named_ior("water").expect("water");
    assert!((water - 1.333).abs() < 1e-3);
    match &desc.bsdfs[desc.shapes[0].bsdf] {
        BsdfDesc::Dielectric { ior, .. } => {
            assert_eq!(
                *ior,
                IorPair {
                    int_ior: water,
                    ext_ior: named_ior("vacuum").unwrap()
                }
            )
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        desc.bsdfs[desc.shapes[1].bsdf],
        BsdfDesc::Conductor {
            eta_k: Some(named_conductor("Au").expect("gold")),
            specular_reflectance: Rgb::splat(1.0)
        }
    );
    match &desc.bsdfs[desc.shapes[2].bsdf] {
        BsdfDesc::RoughPlastic { ior, .. } => {
            assert_eq!(ior.int_ior, named_ior("diamond").unwrap())
        }
        other => panic!("{other:?}"),
    }
    let ior = "<shape type=\"sphere\"><bsdf type=\"dielectric\">\n<string name=\"int_ior\" value=\"unobtainium\"/></bsdf></shape>";
    let metal = "<shape type=\"sphere\"><bsdf type=\"conductor\">\n<string name=\"material\" value=\"Kryptonite\"/></bsdf></shape>";
    load_err_at("unknown_ior", &scene(ior), 3);
    load_err_at("unknown_metal", &scene(metal), 3);
}

#[test]
fn composed_scene_with_spectra_equals_the_scene_written_by_hand() {
    let data =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/loader/composed_spectra");
    let composed = load_file(&data.join("scene.xml")).expect("composed scene loads");
    let by_hand = load_file(&data.join("by_hand.xml")).expect("hand-written scene loads");
    assert_eq!(composed.emitters, by_hand.emitters);
    assert_eq!(composed.shapes.len(), 3);
    assert_eq!(composed.shapes.len(), by_hand.shapes.len());
    for (a, b) in composed.shapes.iter().zip(&by_hand.shapes) {
        assert_eq!(a.geometry, b.geometry);
        assert_eq!(composed.bsdfs[a.bsdf], by_hand.bsdfs[b.bsdf]);
        assert_eq!(a.emitter, b.emitter);
    }
    assert_eq!(
        composed.bsdfs[composed.shapes[1].bsdf],
        BsdfDesc::Diffuse {
            reflectance: spectrum_to_rgb(&PAIRS, SpectrumUse::Reflectance)
        }
    );
}
