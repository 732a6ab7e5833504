//! PLY and OBJ readers: the same mesh written in every format loads to the same values
//! (known by construction), and bad files give errors that name the file, never panics.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use mltbench::error::Error;
use mltbench::scene::TriangleMesh;
use mltbench::scene::obj::read_obj;
use mltbench::scene::ply::read_ply;

mod scratch_support;
use scratch_support::ScratchDir;

/// A fresh directory for one test's fixture files.
fn temp_dir(test: &str) -> ScratchDir {
    ScratchDir::new(&format!("mesh-{test}"))
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

// The fixture: a unit quad in the z = 0 plane (vertices 0..4) and a triangle (1, 4, 2), every
// value exactly representable in binary floating point. The normals are written with
// length 2 (the readers must normalise them) and all point along +z.
const POSITIONS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [2.0, 0.5, 0.25],
];
const NORMALS_WRITTEN: [[f32; 3]; 5] = [
    [0.0, 0.0, 2.0],
    [0.0, 0.0, 2.0],
    [0.0, 0.0, 2.0],
    [0.0, 0.0, 2.0],
    [0.0, 0.0, 2.0],
];
const UVS: [[f32; 2]; 5] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.75, 0.5]];
const QUAD: [u32; 4] = [0, 1, 2, 3];
const TRIANGLE: [u32; 3] = [1, 4, 2];

/// The mesh every fixture must load to: the quad fanned as (0,1,2), (0,2,3).
fn expected_mesh() -> TriangleMesh {
    TriangleMesh {
        positions: POSITIONS.iter().map(|&p| Vec3::from(p)).collect(),
        normals: Some(vec![Vec3::Z; 5]),
        uvs: Some(UVS.iter().map(|&t| Vec2::from(t)).collect()),
        indices: vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]],
    }
}

fn ascii_ply() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\ncomment a quad and a triangle\n\
         element vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty list uchar float extra\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float u\nproperty float v\n\
         element material 1\nproperty list int int ids\nproperty double shine\n\
         element face 2\nproperty int flags\nproperty list uchar int vertex_indices\n\
         property float weight\nend_header\n",
    );
    for i in 0..5 {
        let [x, y, z] = POSITIONS[i];
        let [nx, ny, nz] = NORMALS_WRITTEN[i];
        let [u, v] = UVS[i];
        s += &format!("{x} {y} {z} 200 2 1.5 -3 {nx} {ny} {nz} {u} {v}\n");
    }
    s += "3 7 8 9 0.5\n";
    s += "17 4 0 1 2 3 0.5\n";
    s += "18 3 1 4 2 0.25\n";
    s
}

/// Writes the fixture as binary PLY with a mix of types, in either byte order. `index_name`
/// and `uv_names` vary the spellings the reader must accept.
fn binary_ply(big_endian: bool, index_name: &str, uv_names: (&str, &str)) -> Vec<u8> {
    let format = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\nformat {format} 1.0\nelement vertex 5\n\
         property double x\nproperty float y\nproperty double z\n\
         property list ushort short junk\n\
         property float nx\nproperty double ny\nproperty float nz\n\
         property float {u}\nproperty double {v}\n\
         element face 2\nproperty list uchar uint {index_name}\nproperty short flags\n\
         element edge 2\nproperty int vertex1\nproperty int vertex2\n\
         end_header\n",
        u = uv_names.0,
        v = uv_names.1,
    );
    let mut w = Writer {
        bytes: header.into_bytes(),
        big_endian,
    };
    for i in 0..5 {
        let [x, y, z] = POSITIONS[i];
        let [nx, ny, nz] = NORMALS_WRITTEN[i];
        let [u, v] = UVS[i];
        w.f64(x as f64);
        w.f32(y);
        w.f64(z as f64);
        w.u16(2);
        w.i16(-7);
        w.i16(300);
        w.f32(nx);
        w.f64(ny as f64);
        w.f32(nz);
        w.f32(u);
        w.f64(v as f64);
    }
    w.u8(4);
    for i in QUAD {
        w.u32(i);
    }
    w.i16(-1);
    w.u8(3);
    for i in TRIANGLE {
        w.u32(i);
    }
    w.i16(5);
    for e in [0, 1, 1, 2] {
        w.i32(e);
    }
    w.bytes
}

/// A little binary writer for fixtures.
struct Writer {
    bytes: Vec<u8>,
    big_endian: bool,
}

impl Writer {
    fn put<const N: usize>(&mut self, le: [u8; N]) {
        let mut b = le;
        if self.big_endian {
            b.reverse();
        }
        self.bytes.extend_from_slice(&b);
    }
    fn u8(&mut self, v: u8) {
        self.bytes.push(v);
    }
    fn i16(&mut self, v: i16) {
        self.put(v.to_le_bytes());
    }
    fn u16(&mut self, v: u16) {
        self.put(v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.put(v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.put(v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.put(v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.put(v.to_le_bytes());
    }
}

fn obj_text() -> String {
    let mut s = String::from("# a quad and a triangle\nmtllib missing.mtl\no quad\n");
    for [x, y, z] in POSITIONS {
        s += &format!("v {x} {y} {z}\n");
    }
    for [u, v] in UVS {
        s += &format!("vt {u} {v}\n");
    }
    for [x, y, z] in NORMALS_WRITTEN {
        s += &format!("vn {x} {y} {z}\n");
    }
    s += "usemtl nothing\nf 1/1/1 2/2/2 3/3/3 4/4/4\n";
    // The second object uses relative indices: -4 is vertex 2, -1 is vertex 5, -3 is 3.
    s += "o tri\nf -4/-4/-4 -1/-1/-1 -3/-3/-3\n";
    s += "l 1 2 3\n";
    s
}

#[test]
fn every_format_loads_the_same_mesh() {
    let dir = temp_dir("same");
    let expected = expected_mesh();
    let files = [
        write(&dir, "ascii.ply", ascii_ply().as_bytes()),
        write(
            &dir,
            "le.ply",
            &binary_ply(false, "vertex_indices", ("u", "v")),
        ),
        write(
            &dir,
            "be.ply",
            &binary_ply(true, "vertex_index", ("s", "t")),
        ),
        write(
            &dir,
            "be_texture.ply",
            &binary_ply(true, "vertex_indices", ("texture_u", "texture_v")),
        ),
    ];
    for file in &files {
        let mesh = read_ply(file).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mesh, expected, "{}", file.display());
    }
    let obj = write(&dir, "mesh.obj", obj_text().as_bytes());
    assert_eq!(read_obj(&obj).unwrap_or_else(|e| panic!("{e}")), expected);
}

#[test]
fn polygons_are_fan_triangulated() {
    let dir = temp_dir("fan");
    let ply = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
               property float z\nelement face 2\nproperty list uchar int vertex_index\nend_header\n\
               0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n2 0 1\n";
    let mesh = read_ply(&write(&dir, "pentagon.ply", ply.as_bytes())).unwrap();
    // The two-vertex face adds nothing.
    assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    assert_eq!(mesh.normals, None);
    assert_eq!(mesh.uvs, None);

    let obj = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n";
    let mesh = read_obj(&write(&dir, "pentagon.obj", obj.as_bytes())).unwrap();
    assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    assert_eq!(mesh.positions[2], Vec3::new(2.0, 1.0, 0.0));
}

#[test]
fn obj_keeps_normals_and_uvs_only_when_every_vertex_has_them() {
    let dir = temp_dir("partial");
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.5 0.5\nvn 0 0 3\n\
               f 1/1/1 2/1/1 3/1/1\nf 2 4 3\n";
    let mesh = read_obj(&write(&dir, "partial.obj", obj.as_bytes())).unwrap();
    // `2` and `2/1/1` are different vertices (as in Mitsuba 3), so there are six.
    assert_eq!(mesh.positions.len(), 6);
    assert_eq!(mesh.positions[3], Vec3::X);
    assert_eq!(mesh.normals, None);
    assert_eq!(mesh.uvs, None);
    assert_eq!(mesh.indices, vec![[0, 1, 2], [3, 4, 5]]);

    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 3\nf 1//1 2//1 3//1\n";
    let mesh = read_obj(&write(&dir, "normals.obj", obj.as_bytes())).unwrap();
    assert_eq!(mesh.normals, Some(vec![Vec3::Z; 3]));
    assert_eq!(mesh.uvs, None);
}

#[test]
fn obj_reads_x_y_z_and_ignores_further_vertex_values() {
    // As Mitsuba 3.9.1 does (measured): a `w` does not divide the position, vertex colours
    // are ignored, a third texture coordinate too.
    let dir = temp_dir("obj-extra-values");
    let obj = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 2\nvt 0.5 0.5 0.7\nvt 0.5 0.5\nvt 0.5 0.2 0.1\nf 1/1 2/2 3/3\n";
    let mesh = read_obj(&write(&dir, "extra.obj", obj.as_bytes())).unwrap();
    assert_eq!(mesh.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(
        mesh.uvs,
        Some(vec![
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 0.2)
        ])
    );
}

#[test]
fn empty_obj_is_an_empty_mesh() {
    let dir = temp_dir("empty");
    let mesh = read_obj(&write(&dir, "empty.obj", b"# nothing\n")).unwrap();
    assert!(mesh.positions.is_empty() && mesh.indices.is_empty());
}

/// The error's text, after checking that it names the file.
fn error_text(result: Result<TriangleMesh, Error>, file: &Path) -> String {
    let error = match result {
        Ok(_) => panic!("{} loaded but should not have", file.display()),
        Err(e) => e,
    };
    let text = error.to_string();
    let name = file.file_name().unwrap().to_str().unwrap();
    assert!(text.contains(name), "error does not name the file: {text}");
    text
}

fn ply_error(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let path = write(dir, name, bytes);
    error_text(read_ply(&path), &path)
}

fn obj_error(dir: &Path, name: &str, text: &str) -> String {
    let path = write(dir, name, text.as_bytes());
    error_text(read_obj(&path), &path)
}

#[test]
fn missing_files_are_io_errors_naming_the_file() {
    let dir = temp_dir("missing");
    for (path, result) in [
        (dir.join("nope.ply"), read_ply(&dir.join("nope.ply"))),
        (dir.join("nope.obj"), read_obj(&dir.join("nope.obj"))),
    ] {
        assert!(matches!(&result, Err(Error::Io { .. })), "{path:?}");
        error_text(result, &path);
    }
}

#[test]
fn readers_refuse_directories_and_fifos_without_opening_them() {
    let dir = temp_dir("not-files");
    let fifo = dir.join("pipe.ply");
    let has_fifo = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    let mut inputs = vec![(dir.to_path_buf(), "is a directory")];
    if has_fifo {
        inputs.push((fifo, "not a regular file"));
    }
    for (path, what) in inputs {
        // On another thread: a reader that opened the FIFO would block forever.
        let (send, receive) = std::sync::mpsc::channel();
        let p = path.clone();
        std::thread::spawn(move || {
            let errors = [
                read_ply(&p).err().map(|e| e.to_string()),
                read_obj(&p).err().map(|e| e.to_string()),
                mltbench::io::exr::read_exr(&p).err().map(|e| e.to_string()),
            ];
            send.send(errors)
        });
        let errors = receive
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("a reader blocked");
        for error in errors {
            let error = error.expect("an error");
            assert!(
                error.contains(&path.display().to_string()) && error.contains(what),
                "{error}"
            );
        }
    }
}

#[test]
fn ply_errors_name_the_file_and_the_record() {
    let dir = temp_dir("ply-errors");
    let text = ascii_ply();

    let e = ply_error(&dir, "magic.ply", b"plx\nformat ascii 1.0\nend_header\n");
    assert!(e.contains("not a PLY file"), "{e}");
    ply_error(&dir, "empty.ply", b"");

    let e = ply_error(
        &dir,
        "format.ply",
        text.replace("ascii 1.0", "utf16 1.0").as_bytes(),
    );
    assert!(e.contains("unknown PLY format"), "{e}");
    // 1.0 is the only version, and nothing may follow it.
    for format in [
        "ascii 7.5 junk",
        "ascii 1.0 junk",
        "ascii",
        "binary_little_endian 2.0",
    ] {
        let e = ply_error(
            &dir,
            "version.ply",
            text.replace("ascii 1.0", format).as_bytes(),
        );
        assert!(e.contains(":2:") && e.contains("1.0"), "{e}");
    }
    ply_error(
        &dir,
        "no_end.ply",
        b"ply\nformat ascii 1.0\nelement vertex 0\n",
    );
    let e = ply_error(
        &dir,
        "type.ply",
        text.replace("property float z", "property half z")
            .as_bytes(),
    );
    assert!(e.contains("half"), "{e}");

    // Truncated: the binary file cut inside the faces, the ascii one inside the vertices.
    let binary = binary_ply(false, "vertex_indices", ("u", "v"));
    let e = ply_error(&dir, "cut.ply", &binary[..binary.len() - 40]);
    assert!(e.contains("face") || e.contains("too short"), "{e}");
    let cut = &text[..text.find("0.75").unwrap()];
    let e = ply_error(&dir, "cut_ascii.ply", cut.as_bytes());
    assert!(
        e.contains(":27: vertex 4 has 10 values, expected 12"),
        "{e}"
    );
    let cut = &text[..text.find("18 3").unwrap()];
    let e = ply_error(&dir, "cut_ascii_line.ply", cut.as_bytes());
    assert!(e.contains(":30: face 1") && e.contains("ends early"), "{e}");

    // Ascii records are lines: too few or too many values on one is an error naming it,
    // counting list lengths as written.
    let line_of = |needle: &str| 1 + text.lines().position(|l| l.starts_with(needle)).unwrap();
    let second_vertex = text.lines().nth(23).unwrap().to_string();
    for (name, from, to, message) in [
        (
            "short_vertex.ply",
            second_vertex.as_str(),
            "0 1",
            "vertex 1 has 2 values, expected at least 10",
        ),
        (
            "long_vertex.ply",
            second_vertex.as_str(),
            &format!("{second_vertex} 7") as &str,
            "vertex 1 has 13 values, expected 12",
        ),
        (
            "short_face.ply",
            "17 4 0 1 2 3 0.5",
            "17 4 0 1 2",
            "face 0 has 5 values, expected 7",
        ),
        (
            "long_face.ply",
            "18 3 1 4 2 0.25",
            "18 3 1 4 2 0 0.25",
            "face 1 has 7 values, expected 6",
        ),
    ] {
        let e = ply_error(&dir, name, text.replacen(from, to, 1).as_bytes());
        let line = line_of(from);
        assert!(e.contains(&format!("{name}:{line}: {message}")), "{e}");
    }

    // Counts that do not match the data: one vertex too many declared, one too few.
    ply_error(
        &dir,
        "more.ply",
        text.replace("element vertex 5", "element vertex 6")
            .as_bytes(),
    );
    let e = ply_error(
        &dir,
        "fewer.ply",
        text.replace("element face 2", "element face 1").as_bytes(),
    );
    assert!(
        e.contains(":30:") && e.contains("follow the last element"),
        "{e}"
    );
    // A header count far beyond the file size is rejected before anything is allocated.
    let e = ply_error(
        &dir,
        "huge.ply",
        text.replace("element vertex 5", "element vertex 4000000000000")
            .as_bytes(),
    );
    assert!(e.contains("too short"), "{e}");

    // A face index out of range names the face (counted from 0) and its line.
    let e = ply_error(
        &dir,
        "index.ply",
        text.replace("18 3 1 4 2", "18 3 1 5 2").as_bytes(),
    );
    assert!(
        e.contains("face 1") && e.contains("index 5") && e.contains(":30:"),
        "{e}"
    );
    let mut binary = binary_ply(true, "vertex_indices", ("u", "v"));
    let n = binary.len();
    // The triangle's last index is the u32 before the face's i16 flags and the 16 edge bytes.
    binary[n - 22..n - 18].copy_from_slice(&7u32.to_be_bytes());
    let e = ply_error(&dir, "index_be.ply", &binary);
    assert!(e.contains("face 1") && e.contains("index 7"), "{e}");

    // Non-finite coordinates, ascii and binary.
    let e = ply_error(
        &dir,
        "nan.ply",
        text.replacen("2 0.5 0.25", "2 nan 0.25", 1).as_bytes(),
    );
    assert!(e.contains("vertex 4") && e.contains("non-finite"), "{e}");
    let mut binary = binary_ply(false, "vertex_indices", ("u", "v"));
    let start = binary.windows(10).position(|w| w == b"end_header").unwrap() + 11;
    binary[start..start + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
    let e = ply_error(&dir, "inf.ply", &binary);
    assert!(e.contains("vertex 0") && e.contains("non-finite"), "{e}");
    // A double that overflows f32 is not finite either.
    binary[start..start + 8].copy_from_slice(&1e300f64.to_le_bytes());
    ply_error(&dir, "overflow.ply", &binary);

    // A zero normal cannot be normalised.
    let e = ply_error(
        &dir,
        "zero_normal.ply",
        text.replacen("0 0 2 0.75", "0 0 0 0.75", 1).as_bytes(),
    );
    assert!(e.contains("vertex 4") && e.contains("zero length"), "{e}");

    // Structure: no x, no face index list, an index that is not an integer.
    ply_error(
        &dir,
        "no_x.ply",
        text.replace("property float x", "property float q")
            .as_bytes(),
    );
    ply_error(
        &dir,
        "no_list.ply",
        text.replace("vertex_indices", "corners").as_bytes(),
    );
    ply_error(
        &dir,
        "not_int.ply",
        text.replace("17 4 0 1 2 3", "17 4 0 1.5 2 3").as_bytes(),
    );
}

#[test]
fn obj_errors_name_the_file_and_the_face() {
    let dir = temp_dir("obj-errors");
    let e = obj_error(
        &dir,
        "index.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    );
    assert!(
        e.contains("face 1") && e.contains(":5:") && e.contains("index 9"),
        "{e}"
    );
    let e = obj_error(&dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    assert!(e.contains("face 0") && e.contains("index 0"), "{e}");
    let e = obj_error(
        &dir,
        "relative.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
    );
    assert!(e.contains("index -4"), "{e}");
    let e = obj_error(
        &dir,
        "uv.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
    );
    assert!(e.contains("texture coordinate index 2"), "{e}");
    let e = obj_error(
        &dir,
        "normal.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n",
    );
    assert!(e.contains("normal index 1"), "{e}");
    obj_error(&dir, "word.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
    let e = obj_error(&dir, "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    assert!(e.contains("not finite") && e.contains(":2:"), "{e}");
    let e = obj_error(
        &dir,
        "inf.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn inf 0 0\nf 1//1 2//1 3//1\n",
    );
    assert!(e.contains("not finite") && e.contains(":4:"), "{e}");
    let e = obj_error(
        &dir,
        "zero_normal.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",
    );
    assert!(e.contains("zero length"), "{e}");
    assert!(e.contains(":4:"), "{e}");
    // Vertex records: too few numbers or words that are not numbers, with the line.
    for (name, text, line, what) in [
        ("bad_v.obj", "v 0 0\nf 1 1 1\n", 1, "3 numbers"),
        (
            "word_v.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 abc\nf 1 2 3\n",
            3,
            "`abc`",
        ),
        (
            "short_vt.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5\nf 1/1 2/1 3/1\n",
            4,
            "2 numbers",
        ),
        (
            "short_vn.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nvn 0 0\nf 1//1 2//1 3//1\n",
            5,
            "3 numbers",
        ),
    ] {
        let e = obj_error(&dir, name, text);
        assert!(
            e.contains(&format!("{name}:{line}:")) && e.contains(what),
            "{e}"
        );
    }
    let path = write(&dir, "latin1.obj", b"v 0 0 0 \xff\n");
    error_text(read_obj(&path), &path);
}

/// A small fixed-seed generator (xorshift64*), so the garbage is the same on every run.
struct Garbage(u64);

impl Garbage {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn garbage_never_panics() {
    let dir = temp_dir("garbage");
    let mut rng = Garbage(0x9e37_79b9_7f4a_7c15);
    let valid: Vec<Vec<u8>> = vec![
        ascii_ply().into_bytes(),
        binary_ply(false, "vertex_indices", ("u", "v")),
        binary_ply(true, "vertex_index", ("s", "t")),
        obj_text().into_bytes(),
    ];
    let ply_path = dir.join("garbage.ply");
    let obj_path = dir.join("garbage.obj");
    for round in 0..1200 {
        let bytes: Vec<u8> = match round % 3 {
            // Pure noise, sometimes behind a plausible header line.
            0 => {
                let mut b: Vec<u8> = if rng.below(2) == 0 {
                    b"ply\nformat binary_little_endian 1.0\n".to_vec()
                } else {
                    Vec::new()
                };
                let n = rng.below(300);
                b.extend((0..n).map(|_| rng.next() as u8));
                b
            }
            // A valid file with a few bytes changed.
            1 => {
                let mut b = valid[rng.below(valid.len())].clone();
                for _ in 0..1 + rng.below(4) {
                    let i = rng.below(b.len());
                    b[i] = if rng.below(2) == 0 {
                        rng.next() as u8
                    } else {
                        b"0123456789 \n-e.\xff"[rng.below(16)]
                    };
                }
                b
            }
            // A valid file cut short.
            _ => {
                let b = &valid[rng.below(valid.len())];
                b[..rng.below(b.len())].to_vec()
            }
        };
        std::fs::write(&ply_path, &bytes).unwrap();
        std::fs::write(&obj_path, &bytes).unwrap();
        for mesh in [read_ply(&ply_path), read_obj(&obj_path)]
            .into_iter()
            .flatten()
        {
            // Whatever loads is consistent.
            let n = mesh.positions.len() as u32;
            assert!(mesh.indices.iter().flatten().all(|&i| i < n));
            assert!(mesh.positions.iter().all(|p| p.is_finite()));
            assert!(
                mesh.normals
                    .iter()
                    .flatten()
                    .all(|v| (v.length() - 1.0).abs() < 1e-5)
            );
            assert!(mesh.normals.as_ref().is_none_or(|v| v.len() == n as usize));
            assert!(mesh.uvs.as_ref().is_none_or(|v| v.len() == n as usize));
        }
    }
}
