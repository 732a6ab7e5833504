//! Stanford PLY meshes: ascii, binary little- and big-endian.
//!
//! What is read: the `vertex` element's `x`, `y`, `z` (any numeric type), the optional normal
//! `nx`, `ny`, `nz` and the optional texture coordinates (`u`/`v`, else `texture_u`/`texture_v`,
//! else `s`/`t`, the order Mitsuba 3 looks for them), and the `face` element's `vertex_index`
//! (else `vertex_indices`) list. Polygons are fan-triangulated (0,1,2), (0,2,3), …; faces with
//! fewer than three vertices add no triangle. Every other element and property, lists included,
//! is read over and ignored. Texture coordinates are returned as written (no flip). An ascii
//! body is read line by line, one record per line: a line with too few or too many values for
//! its record is an error naming the line.
//!
//! Bad input never panics and never makes the reader allocate more than the file's size
//! justifies: every count in the header is checked against the bytes that follow it.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::TriangleMesh;
use crate::error::{Error, Location, Result};

/// Reads a PLY file into a mesh in object space.
pub fn read_ply(path: &Path) -> Result<TriangleMesh> {
    crate::io::check_input_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let header = parse_header(path, &bytes)?;
    let body = match header.format {
        Format::Ascii => Body::Ascii {
            data: &bytes,
            pos: header.body_start,
            line: header.body_line,
            record_line: header.body_line,
            tokens: Vec::new(),
            next: 0,
        },
        Format::BinaryLittleEndian => Body::Binary {
            data: &bytes,
            pos: header.body_start,
            big_endian: false,
        },
        Format::BinaryBigEndian => Body::Binary {
            data: &bytes,
            pos: header.body_start,
            big_endian: true,
        },
    };
    MeshReader { path, body }.read(&header)
}

/// A scalar type of the PLY format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The range of an integer type (as f64, exact for every type here).
    fn integer_range(self) -> (f64, f64) {
        match self {
            Scalar::I8 => (i8::MIN as f64, i8::MAX as f64),
            Scalar::U8 => (0.0, u8::MAX as f64),
            Scalar::I16 => (i16::MIN as f64, i16::MAX as f64),
            Scalar::U16 => (0.0, u16::MAX as f64),
            Scalar::I32 => (i32::MIN as f64, i32::MAX as f64),
            Scalar::U32 => (0.0, u32::MAX as f64),
            Scalar::F32 | Scalar::F64 => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PropertyKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

impl PropertyKind {
    /// The fewest bytes (binary) a value of this property takes.
    fn min_binary_size(self) -> usize {
        match self {
            PropertyKind::Scalar(t) => t.size(),
            PropertyKind::List { count, .. } => count.size(),
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: PropertyKind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

impl Element {
    fn property(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|p| p.name == name)
    }

    /// The index of a scalar property (a list of that name does not count).
    fn scalar_property(&self, name: &str) -> Option<usize> {
        self.property(name)
            .filter(|&i| matches!(self.properties[i].kind, PropertyKind::Scalar(_)))
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the first byte after `end_header`'s line.
    body_start: usize,
    /// 1-based line number of the body's first line (for ascii messages).
    body_line: u32,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let header_error =
        |line: u32, message: String| Error::input(Location::at(path, line, "PLY header"), message);

    let mut pos = 0usize;
    let mut line_number = 0u32;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(if line_number == 0 {
                Error::input(Location::file(path), "empty file: not a PLY file")
            } else {
                header_error(line_number, "the header has no `end_header` line".into())
            });
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let raw = &bytes[pos..end];
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        pos = (end + 1).min(bytes.len());
        line_number += 1;

        if line_number == 1 {
            if raw != b"ply" {
                return Err(Error::input(
                    Location::file(path),
                    "not a PLY file: the first line is not `ply`",
                ));
            }
            continue;
        }
        let text = String::from_utf8_lossy(raw);
        let mut words = text.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let rest: Vec<&str> = words.collect();
        match keyword {
            "comment" | "obj_info" => {}
            "format" => {
                if format.is_some() {
                    return Err(header_error(line_number, "a second `format` line".into()));
                }
                format = Some(match rest.first().copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::BinaryLittleEndian,
                    Some("binary_big_endian") => Format::BinaryBigEndian,
                    other => {
                        return Err(header_error(
                            line_number,
                            format!(
                                "unknown PLY format `{}` (expected ascii, binary_little_endian \
                                 or binary_big_endian)",
                                other.unwrap_or("")
                            ),
                        ));
                    }
                });
                // 1.0 is the only version of the format there is.
                if rest.get(1..) != Some(&["1.0"][..]) {
                    return Err(header_error(
                        line_number,
                        format!(
                            "expected `format {} 1.0`, got `format {}`",
                            rest[0],
                            rest.join(" ")
                        ),
                    ));
                }
            }
            "element" => {
                let [name, count] = rest[..] else {
                    return Err(header_error(
                        line_number,
                        "expected `element <name> <count>`".into(),
                    ));
                };
                let count = count.parse::<u64>().map_err(|_| {
                    header_error(line_number, format!("bad element count `{count}`"))
                })?;
                if elements.iter().any(|e| e.name == name) {
                    return Err(header_error(
                        line_number,
                        format!("a second `{name}` element"),
                    ));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(header_error(
                        line_number,
                        "a property before any element".into(),
                    ));
                };
                let type_error =
                    |t: &str| header_error(line_number, format!("unknown property type `{t}`"));
                let (kind, name) = match rest[..] {
                    ["list", count, item, name] => {
                        let count_type = Scalar::parse(count).ok_or_else(|| type_error(count))?;
                        if !count_type.is_integer() {
                            return Err(header_error(
                                line_number,
                                format!("list count type `{count}` is not an integer type"),
                            ));
                        }
                        let item = Scalar::parse(item).ok_or_else(|| type_error(item))?;
                        (
                            PropertyKind::List {
                                count: count_type,
                                item,
                            },
                            name,
                        )
                    }
                    [ty, name] if ty != "list" => (
                        PropertyKind::Scalar(Scalar::parse(ty).ok_or_else(|| type_error(ty))?),
                        name,
                    ),
                    _ => {
                        return Err(header_error(
                            line_number,
                            "expected `property <type> <name>` or \
                             `property list <count type> <item type> <name>`"
                                .into(),
                        ));
                    }
                };
                if element.property(name).is_some() {
                    return Err(header_error(
                        line_number,
                        format!("a second property `{name}` in element `{}`", element.name),
                    ));
                }
                element.properties.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            "end_header" => break,
            other => {
                return Err(header_error(
                    line_number,
                    format!("unknown header keyword `{other}`"),
                ));
            }
        }
    }
    let Some(format) = format else {
        return Err(header_error(
            line_number,
            "the header has no `format` line".into(),
        ));
    };
    Ok(Header {
        format,
        elements,
        body_start: pos,
        body_line: line_number + 1,
    })
}

/// The data after the header, read value by value; ascii records one line each.
enum Body<'a> {
    Ascii {
        data: &'a [u8],
        /// Start of the first line not read yet, and its 1-based number.
        pos: usize,
        line: u32,
        /// The current record's line, its values (byte ranges) and the next one to read.
        record_line: u32,
        tokens: Vec<(usize, usize)>,
        next: usize,
    },
    Binary {
        data: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

/// Why a value could not be read.
enum ValueError {
    /// An ascii record's line holds no more values.
    EndOfLine,
    Message(String),
}

impl From<String> for ValueError {
    fn from(message: String) -> Self {
        ValueError::Message(message)
    }
}

const ENDS_EARLY: &str =
    "the file ends early (truncated data or a count in the header that is too large)";

impl Body<'_> {
    fn remaining(&self) -> usize {
        match *self {
            Body::Ascii { data, pos, .. } | Body::Binary { data, pos, .. } => data.len() - pos,
        }
    }

    fn line(&self) -> Option<u32> {
        match *self {
            Body::Ascii { record_line, .. } => Some(record_line),
            Body::Binary { .. } => None,
        }
    }

    /// The fewest bytes a value of this property takes: for ascii, one character and one
    /// separator per value.
    fn min_size(&self, kind: PropertyKind) -> usize {
        match self {
            Body::Ascii { .. } => 2,
            Body::Binary { .. } => kind.min_binary_size(),
        }
    }

    /// Ascii: moves to the next line that holds values, the next record's. Binary: nothing.
    fn begin_record(&mut self) -> std::result::Result<(), ValueError> {
        let Body::Ascii {
            data,
            pos,
            line,
            record_line,
            tokens,
            next,
        } = self
        else {
            return Ok(());
        };
        tokens.clear();
        *next = 0;
        while tokens.is_empty() {
            *record_line = *line;
            if *pos >= data.len() {
                return Err(ENDS_EARLY.to_string().into());
            }
            let end = data[*pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(data.len(), |i| *pos + i);
            let mut i = *pos;
            while i < end {
                if data[i].is_ascii_whitespace() {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < end && !data[i].is_ascii_whitespace() {
                    i += 1;
                }
                tokens.push((start, i));
            }
            *pos = (end + 1).min(data.len());
            *line += 1;
        }
        Ok(())
    }

    /// Ascii: (values on the record's line, values read) when the line holds more values
    /// than the record took.
    fn extra_values(&self) -> Option<(usize, usize)> {
        match self {
            Body::Ascii { tokens, next, .. } if *next < tokens.len() => Some((tokens.len(), *next)),
            _ => None,
        }
    }

    /// Ascii: the number of values a record of `element` on the current line needs, from
    /// the list lengths written there; the flag is false when a missing list length makes
    /// it a lower bound. Also the number of values on the line.
    fn expected_values(&self, element: &Element) -> (usize, bool, usize) {
        let Body::Ascii { data, tokens, .. } = self else {
            return (0, true, 0);
        };
        let token = |i: usize| {
            tokens
                .get(i)
                .and_then(|&(s, e)| std::str::from_utf8(&data[s..e]).ok())
        };
        let (mut at, mut total, mut exact) = (0usize, 0usize, true);
        for property in &element.properties {
            total += 1;
            if let PropertyKind::List { .. } = property.kind {
                match token(at).and_then(|t| t.parse::<usize>().ok()) {
                    Some(n) => {
                        total = total.saturating_add(n);
                        at = at.saturating_add(n);
                    }
                    None => exact = false,
                }
            }
            at = at.saturating_add(1);
        }
        (total, exact, tokens.len())
    }

    /// Reads one value as f64 (exact for every PLY type). The caller adds the location.
    fn read(&mut self, ty: Scalar) -> std::result::Result<f64, ValueError> {
        match self {
            Body::Ascii {
                data, tokens, next, ..
            } => {
                let Some(&(start, end)) = tokens.get(*next) else {
                    return Err(ValueError::EndOfLine);
                };
                *next += 1;
                let token = std::str::from_utf8(&data[start..end]).unwrap_or("");
                let value: f64 = token
                    .parse()
                    .map_err(|_| format!("`{}` is not a number", token.escape_debug()))?;
                if ty.is_integer() {
                    let (lo, hi) = ty.integer_range();
                    if value.fract() != 0.0 || value < lo || value > hi {
                        return Err(
                            format!("`{token}` is not a valid `{}` value", ty.name()).into()
                        );
                    }
                }
                Ok(value)
            }
            Body::Binary {
                data,
                pos,
                big_endian,
            } => {
                let size = ty.size();
                if data.len() - *pos < size {
                    return Err(ENDS_EARLY.to_string().into());
                }
                let mut raw = [0u8; 8];
                raw[..size].copy_from_slice(&data[*pos..*pos + size]);
                *pos += size;
                if *big_endian {
                    raw[..size].reverse();
                }
                let b = raw;
                Ok(match ty {
                    Scalar::I8 => b[0] as i8 as f64,
                    Scalar::U8 => b[0] as f64,
                    Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }

    /// Reads a list's length and checks that the rest of the file (ascii: of the line) can
    /// hold it.
    fn read_list_len(
        &mut self,
        count: Scalar,
        item: Scalar,
    ) -> std::result::Result<usize, ValueError> {
        let n = self.read(count)?;
        if n < 0.0 {
            return Err(format!("negative list length {n}").into());
        }
        let n = n as usize;
        if let Body::Ascii { tokens, next, .. } = self {
            return if n > tokens.len() - *next {
                Err(ValueError::EndOfLine)
            } else {
                Ok(n)
            };
        }
        let min_item = self.min_size(PropertyKind::Scalar(item));
        if n.saturating_mul(min_item) > self.remaining() {
            return Err(
                format!("a list of {n} values does not fit in the rest of the file").into(),
            );
        }
        Ok(n)
    }
}

struct MeshReader<'a> {
    path: &'a Path,
    body: Body<'a>,
}

/// Where to find the vertex attributes in the `vertex` element.
struct VertexLayout {
    position: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
}

impl MeshReader<'_> {
    /// An error about record `index` of an element ("vertex 3", "face 12", counted from 0).
    /// The error for a value of record `index` of `element` that could not be read.
    fn value_error(&self, element: &Element, index: u64, e: ValueError) -> Error {
        match e {
            ValueError::Message(message) => self.error(&element.name, index, message),
            ValueError::EndOfLine => {
                let (expected, exact, got) = self.body.expected_values(element);
                let at_least = if exact { "" } else { "at least " };
                self.record_count_error(element, index, got, &format!("{at_least}{expected}"))
            }
        }
    }

    /// "FILE:LINE: vertex 3 has 2 values, expected 3" (ascii only).
    fn record_count_error(
        &self,
        element: &Element,
        index: u64,
        got: usize,
        expected: &str,
    ) -> Error {
        Error::input(
            Location {
                file: self.path.to_path_buf(),
                line: self.body.line(),
                element: None,
            },
            format!(
                "{} {index} has {got} values, expected {expected}",
                element.name
            ),
        )
    }

    fn error(&self, element: &str, index: u64, message: impl Into<String>) -> Error {
        let what = format!("{element} {index}");
        let location = match self.body.line() {
            Some(line) => Location::at(self.path, line, what),
            None => Location {
                file: self.path.to_path_buf(),
                line: None,
                element: Some(what),
            },
        };
        Error::input(location, message)
    }

    fn read(mut self, header: &Header) -> Result<TriangleMesh> {
        let path = self.path;
        let Some(vertex_element) = header.elements.iter().find(|e| e.name == "vertex") else {
            return Err(Error::input(
                Location::file(path),
                "the PLY file has no `vertex` element",
            ));
        };
        let layout = vertex_layout(path, vertex_element)?;
        let vertex_count = vertex_element.count;

        let face_list = match header.elements.iter().find(|e| e.name == "face") {
            None => None,
            Some(face) => {
                let index = face
                    .property("vertex_index")
                    .or_else(|| face.property("vertex_indices"))
                    .ok_or_else(|| {
                        Error::input(
                            Location::file(path),
                            "the `face` element has no `vertex_index` or `vertex_indices` list",
                        )
                    })?;
                let PropertyKind::List { .. } = face.properties[index].kind else {
                    return Err(Error::input(
                        Location::file(path),
                        format!(
                            "face property `{}` is not a list",
                            face.properties[index].name
                        ),
                    ));
                };
                Some(index)
            }
        };

        let mut mesh = TriangleMesh {
            positions: Vec::new(),
            normals: layout.normal.map(|_| Vec::new()),
            uvs: layout.uv.map(|_| Vec::new()),
            indices: Vec::new(),
        };
        let mut values: Vec<f64> = Vec::new();
        let mut polygon: Vec<u32> = Vec::new();

        for element in &header.elements {
            // Check the declared count against the bytes left before allocating anything.
            let min_record: usize = element
                .properties
                .iter()
                .map(|p| self.body.min_size(p.kind))
                .sum::<usize>();
            let fits =
                (element.count as u128) * (min_record as u128) <= self.body.remaining() as u128;
            if !fits {
                return Err(Error::input(
                    Location::file(path),
                    format!(
                        "the header declares {} `{}` records but the file is too short to hold \
                         them (truncated, or a wrong count)",
                        element.count, element.name
                    ),
                ));
            }
            // `fits` bounds the count by the file size (a record takes at least one byte
            // unless it has no properties at all).
            let capacity = if min_record == 0 {
                0
            } else {
                element.count as usize
            };
            let is_vertex = element.name == "vertex";
            let is_face = element.name == "face";
            if is_vertex {
                mesh.positions.reserve_exact(capacity);
                if let Some(n) = &mut mesh.normals {
                    n.reserve_exact(capacity);
                }
                if let Some(uv) = &mut mesh.uvs {
                    uv.reserve_exact(capacity);
                }
            } else if is_face {
                mesh.indices.reserve(capacity);
            }

            for record in 0..element.count {
                values.clear();
                if !element.properties.is_empty() {
                    self.body
                        .begin_record()
                        .map_err(|e| self.value_error(element, record, e))?;
                }
                for (k, property) in element.properties.iter().enumerate() {
                    match property.kind {
                        PropertyKind::Scalar(ty) => {
                            let v = self
                                .body
                                .read(ty)
                                .map_err(|e| self.value_error(element, record, e))?;
                            values.push(v);
                        }
                        PropertyKind::List { count, item } => {
                            values.push(0.0);
                            let n = self
                                .body
                                .read_list_len(count, item)
                                .map_err(|e| self.value_error(element, record, e))?;
                            let keep = is_face && face_list == Some(k);
                            if keep {
                                polygon.clear();
                            }
                            for _ in 0..n {
                                let v = self
                                    .body
                                    .read(item)
                                    .map_err(|e| self.value_error(element, record, e))?;
                                if keep {
                                    if v.fract() != 0.0 || v < 0.0 || v >= vertex_count as f64 {
                                        return Err(self.error(
                                            "face",
                                            record,
                                            format!(
                                                "vertex index {v} is out of range (the file has \
                                                 {vertex_count} vertices)"
                                            ),
                                        ));
                                    }
                                    polygon.push(v as u32);
                                }
                            }
                        }
                    }
                }
                if let Some((got, expected)) = self.body.extra_values() {
                    return Err(self.record_count_error(
                        element,
                        record,
                        got,
                        &expected.to_string(),
                    ));
                }
                if is_vertex {
                    self.add_vertex(&mut mesh, &layout, &values, record)?;
                } else if is_face && polygon.len() >= 3 {
                    // Fan triangulation.
                    for i in 1..polygon.len() - 1 {
                        mesh.indices.push([polygon[0], polygon[i], polygon[i + 1]]);
                    }
                }
            }
        }
        self.check_end()?;
        Ok(mesh)
    }

    fn add_vertex(
        &self,
        mesh: &mut TriangleMesh,
        layout: &VertexLayout,
        values: &[f64],
        record: u64,
    ) -> Result<()> {
        let [x, y, z] = layout.position;
        let p = Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32);
        if !p.is_finite() {
            return Err(self.error("vertex", record, format!("non-finite position {p}")));
        }
        mesh.positions.push(p);
        if let (Some([x, y, z]), Some(normals)) = (layout.normal, &mut mesh.normals) {
            let n = Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32);
            let unit = n.normalize_or_zero();
            if !n.is_finite() || unit == Vec3::ZERO {
                return Err(self.error(
                    "vertex",
                    record,
                    format!("normal {n} is not finite or has zero length"),
                ));
            }
            normals.push(unit);
        }
        if let (Some([u, v]), Some(uvs)) = (layout.uv, &mut mesh.uvs) {
            let uv = Vec2::new(values[u] as f32, values[v] as f32);
            if !uv.is_finite() {
                return Err(self.error(
                    "vertex",
                    record,
                    format!("non-finite texture coordinates {uv}"),
                ));
            }
            uvs.push(uv);
        }
        Ok(())
    }

    /// After the last element only whitespace may follow (ascii), or at most a line ending
    /// (binary): anything else means the header's counts do not match the data.
    fn check_end(&self) -> Result<()> {
        let (data, pos, line) = match self.body {
            Body::Ascii {
                data, pos, line, ..
            } => (data, pos, Some(line)),
            Body::Binary { data, pos, .. } => (data, pos, None),
        };
        let rest = &data[pos..];
        let stray = match line {
            None => !(rest.is_empty() || rest == b"\n" || rest == b"\r\n"),
            Some(_) => rest.iter().any(|b| !b.is_ascii_whitespace()),
        };
        if !stray {
            return Ok(());
        }
        // Ascii: the line of the first value after the last record.
        let line = line.map(|line| {
            let blank = rest.iter().take_while(|b| b.is_ascii_whitespace());
            line + blank.filter(|&&b| b == b'\n').count() as u32
        });
        Err(Error::input(
            Location {
                file: self.path.to_path_buf(),
                line,
                element: None,
            },
            format!(
                "{} bytes of data follow the last element: the header's counts do not match \
                 the data",
                rest.len()
            ),
        ))
    }
}

fn vertex_layout(path: &Path, vertex: &Element) -> Result<VertexLayout> {
    let scalar = |name: &str| vertex.scalar_property(name);
    let (Some(x), Some(y), Some(z)) = (scalar("x"), scalar("y"), scalar("z")) else {
        return Err(Error::input(
            Location::file(path),
            "the `vertex` element lacks one of the scalar properties x, y, z",
        ));
    };
    let normal = match (scalar("nx"), scalar("ny"), scalar("nz")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = [("u", "v"), ("texture_u", "texture_v"), ("s", "t")]
        .iter()
        .find_map(|&(u, v)| Some([scalar(u)?, scalar(v)?]));
    Ok(VertexLayout {
        position: [x, y, z],
        normal,
        uv,
    })
}
