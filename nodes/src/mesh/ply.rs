//! PLY loading (ASCII, binary little- and big-endian) through the
//! `ply-rs-bw` crate, which parses the header and decodes each element;
//! this file walks the elements one at a time so that an error names the
//! line (header, ASCII body) or the byte offset of the element (binary).
//!
//! A mesh needs an `element vertex` with scalar properties `x`, `y`, `z`
//! (any numeric type) and an `element face` with a list property
//! `vertex_indices` (or `vertex_index`, as some scanners write) of
//! integers; every other element and property (normals, colours,
//! confidence, `edge`, `material`) is ignored. Faces of more than three
//! vertices are triangulated as fans; a file without faces is a point
//! cloud and is refused. [`Mesh::new`] welds the vertices.

use super::error::MeshError;
use super::trimesh::Mesh;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType};
use std::io::Cursor;
use std::path::Path;

/// Loads a PLY file.
pub fn load_ply(path: &Path, weld: f64) -> Result<Mesh, MeshError> {
    let bytes = evflow_engine::files::read_regular(path)
        .map_err(|e| MeshError::Io { path: path.into(), message: e.to_string() })?;
    parse_ply(path, &bytes, weld)
}

/// One element as the parser fills it: the coordinates and the index
/// list a mesh needs, whatever else the element holds.
#[derive(Debug, Default)]
struct Element {
    /// x, y, z.
    xyz: [f64; 3],
    /// The face's vertex indices.
    indices: Vec<i64>,
}

impl PropertyAccess for Element {
    fn new() -> Self {
        Self::default()
    }
    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "vertex_indices" | "vertex_index" => {
                self.indices = match p {
                    Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
                    Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
                    Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
                    Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
                    Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
                    Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
                    _ => return PropertyAccessResult::UnsupportedType,
                };
                return PropertyAccessResult::Set;
            }
            _ => return PropertyAccessResult::Ignored,
        };
        self.xyz[axis] = match p {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// Where an element sits, for errors.
#[derive(Clone, Copy)]
enum At {
    /// A line of an ASCII body.
    Line(usize),
    /// A byte offset in a binary body.
    Byte(u64),
}

/// Parses PLY bytes; `path` only names the source in errors.
pub fn parse_ply(path: &Path, bytes: &[u8], weld: f64) -> Result<Mesh, MeshError> {
    if !bytes.starts_with(b"ply") {
        let found = String::from_utf8_lossy(&bytes[..bytes.len().min(4)]).into_owned();
        return Err(MeshError::Magic { path: path.into(), format: "PLY", expected: "ply".into(), found });
    }
    let parser = Parser::<Element>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser.read_header(&mut reader).map_err(|e| {
        let line = e.line().unwrap_or(reader.line().max(1));
        header_err(path, line, one_line(&e.to_string()))
    })?;
    let body_start = reader.get_ref().position() as usize;
    let header_text = String::from_utf8_lossy(&bytes[..body_start]);
    let (vertex, face) = mesh_elements(path, &header, &header_text)?;
    let mut body = Body {
        path,
        parser: &parser,
        header: &header,
        bytes,
        body_start,
        header_lines: header_text.lines().count(),
        n_vertices: vertex.count,
        vertices: Vec::with_capacity(vertex.count.min(1 << 24)),
        triangles: Vec::with_capacity(face.count.min(1 << 24)),
    };
    match header.encoding {
        Encoding::Ascii => body.read_ascii()?,
        Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
            body.read_binary(header.encoding == Encoding::BinaryBigEndian)?
        }
    }
    Mesh::from_faces(&path.display().to_string(), body.vertices, body.triangles, weld)
}

/// An error in the header at `line`.
fn header_err(path: &Path, line: usize, message: String) -> MeshError {
    MeshError::PlyHeader { path: path.into(), line, message }
}

/// An error in the element read at `at`.
fn bad(path: &Path, at: At, message: String) -> MeshError {
    match at {
        At::Line(line) => MeshError::Syntax { path: path.into(), line, message },
        At::Byte(offset) => MeshError::Binary { path: path.into(), offset, message },
    }
}

/// The header's vertex and face elements, checked to hold what a mesh
/// needs: numeric `x`, `y`, `z` and an integer `vertex_indices` list.
fn mesh_elements<'h>(
    path: &Path,
    header: &'h Header,
    header_text: &str,
) -> Result<(&'h ElementDef, &'h ElementDef), MeshError> {
    let header_lines = header_text.lines().count();
    // The header line that declares an element (or `end_header`), for errors.
    let line_of = |element: &str| {
        header_text
            .lines()
            .position(|l| {
                let w: Vec<&str> = l.split_whitespace().collect();
                w.len() >= 2 && w[0] == "element" && w[1] == element
            })
            .map_or(header_lines, |k| k + 1)
    };
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| header_err(path, header_lines, "no `element vertex`: not a mesh this loader can read".into()))?;
    for axis in ["x", "y", "z"] {
        match vertex.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(header_err(
                    path,
                    line_of("vertex"),
                    format!("vertex property `{axis}` is a list, not a number"),
                ))
            }
            None => {
                return Err(header_err(path, line_of("vertex"), format!("the vertex element has no `{axis}` property")))
            }
        }
    }
    let Some(face) = header.elements.get("face") else {
        return Err(header_err(
            path,
            header_lines,
            "no `element face`: a point cloud, with no surface to touch (mesh it first, e.g. by Poisson reconstruction)"
                .into(),
        ));
    };
    let list = face.properties.get("vertex_indices").or_else(|| face.properties.get("vertex_index"));
    match list.map(|p| &p.data_type) {
        Some(PropertyType::List(_, item))
            if !matches!(item, ply_rs_bw::ply::ScalarType::Float | ply_rs_bw::ply::ScalarType::Double) => {}
        Some(_) => {
            return Err(header_err(
                path,
                line_of("face"),
                "the face's `vertex_indices` must be a list of integers".into(),
            ))
        }
        None => return Err(header_err(path, line_of("face"), "the face element has no `vertex_indices` list".into())),
    }
    Ok((vertex, face))
}

/// The file's body as it is read: the elements in header order, until both
/// the vertices and the faces are read (elements after them are not read).
struct Body<'a> {
    path: &'a Path,
    parser: &'a Parser<Element>,
    header: &'a Header,
    bytes: &'a [u8],
    body_start: usize,
    header_lines: usize,
    n_vertices: usize,
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Body<'_> {
    /// Reads an ASCII body, one element a (non-blank) line.
    fn read_ascii(&mut self) -> Result<(), MeshError> {
        let (path, bytes, body_start, header_lines) = (self.path, self.bytes, self.body_start, self.header_lines);
        let body = std::str::from_utf8(&bytes[body_start..]).map_err(|e| {
            let line = header_lines
                + bytes[body_start..body_start + e.valid_up_to()].iter().filter(|&&b| b == b'\n').count()
                + 1;
            bad(path, At::Line(line), format!("not text (byte {}) in an ASCII PLY", body_start + e.valid_up_to()))
        })?;
        let mut lines =
            body.lines().enumerate().map(|(k, l)| (header_lines + k + 1, l)).filter(|(_, l)| !l.trim().is_empty());
        let (mut faces_seen, mut vertices_seen) = (false, false);
        for def in self.header.elements.values() {
            if faces_seen && vertices_seen {
                break;
            }
            for k in 0..def.count {
                let Some((no, line)) = lines.next() else {
                    let last = header_lines + body.lines().count() + 1;
                    return Err(bad(
                        path,
                        At::Line(last),
                        format!(
                            "the file ends before {} `{}` {k} of {}: truncated?",
                            article(&def.name),
                            def.name,
                            def.count
                        ),
                    ));
                };
                let e = self
                    .parser
                    .read_ascii_element(line, def)
                    .map_err(|e| bad(path, At::Line(no), format!("{} {k}: {}", def.name, one_line(&e.to_string()))))?;
                self.take(def, k, e, At::Line(no))?;
            }
            faces_seen |= def.name == "face";
            vertices_seen |= def.name == "vertex";
        }
        Ok(())
    }

    /// Reads a binary body, little- or big-endian.
    fn read_binary(&mut self, big: bool) -> Result<(), MeshError> {
        let (path, bytes) = (self.path, self.bytes);
        let mut cursor = Cursor::new(bytes);
        cursor.set_position(self.body_start as u64);
        let (mut faces_seen, mut vertices_seen) = (false, false);
        for def in self.header.elements.values() {
            if faces_seen && vertices_seen {
                break;
            }
            for k in 0..def.count {
                let at = cursor.position();
                let read = if big {
                    self.parser.read_big_endian_element(&mut cursor, def)
                } else {
                    self.parser.read_little_endian_element(&mut cursor, def)
                };
                let e = read.map_err(|e| {
                    if e.kind() == std::io::ErrorKind::UnexpectedEof {
                        MeshError::Truncated {
                            path: path.into(),
                            offset: at,
                            what: format!("`{}` {k} of {}", def.name, def.count),
                            available: bytes.len() as u64 - at,
                        }
                    } else {
                        bad(path, At::Byte(at), format!("{} {k}: {}", def.name, one_line(&e.to_string())))
                    }
                })?;
                self.take(def, k, e, At::Byte(at))?;
            }
            faces_seen |= def.name == "face";
            vertices_seen |= def.name == "vertex";
        }
        Ok(())
    }

    /// Takes element `k` of `def`, read at `at`: a vertex (finite
    /// coordinates) or a face (in-range indices, triangulated as a fan).
    fn take(&mut self, def: &ElementDef, k: usize, e: Element, at: At) -> Result<(), MeshError> {
        let n_vertices = self.n_vertices;
        if def.name == "vertex" {
            if let Some(i) = e.xyz.iter().position(|x| !x.is_finite()) {
                return Err(bad(self.path, at, format!("vertex {k}: {} is {}", ["x", "y", "z"][i], e.xyz[i])));
            }
            self.vertices.push(e.xyz);
        } else if def.name == "face" {
            if e.indices.len() < 3 {
                return Err(bad(
                    self.path,
                    at,
                    format!("face {k}: a face needs at least 3 vertices, found {}", e.indices.len()),
                ));
            }
            if let Some(i) = e.indices.iter().find(|&&i| i < 0 || i as usize >= n_vertices) {
                return Err(bad(
                    self.path,
                    at,
                    format!("face {k}: vertex index {i} is out of range (0..{n_vertices})"),
                ));
            }
            let ix: Vec<u32> = e.indices.iter().map(|&i| i as u32).collect();
            for j in 1..ix.len() - 1 {
                self.triangles.push([ix[0], ix[j], ix[j + 1]]);
            }
        }
        Ok(())
    }
}

/// "a" or "an" before an element name.
fn article(name: &str) -> &'static str {
    if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

/// A (multi-line) parser message on one line.
fn one_line(s: &str) -> String {
    s.lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a unit square and a tilted triangle\nelement vertex 5\n\
        property float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 2\n\
        property list uchar int vertex_indices\nend_header\n0 0 0 255\n1 0 0 255\n1 1 0 255\n0 1 0 255\n2 0 1 0\n\
        4 0 1 2 3\n3 1 4 2\n";

    /// The same mesh in binary, with a double z and a short index list.
    fn binary(big: bool) -> Vec<u8> {
        let enc = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut b = format!(
            "ply\nformat {enc} 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty double z\n\
             element face 2\nproperty list uchar ushort vertex_indices\nend_header\n"
        )
        .into_bytes();
        let v: [[f64; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 1.0]];
        for p in v {
            let (x, y, z) = (p[0] as f32, p[1] as f32, p[2]);
            if big {
                b.extend(x.to_be_bytes().into_iter().chain(y.to_be_bytes()).chain(z.to_be_bytes()));
            } else {
                b.extend(x.to_le_bytes().into_iter().chain(y.to_le_bytes()).chain(z.to_le_bytes()));
            }
        }
        for f in [&[0u16, 1, 2, 3][..], &[1, 4, 2]] {
            b.push(f.len() as u8);
            for i in f {
                b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
            }
        }
        b
    }

    #[test]
    fn ascii_and_both_binaries_read_the_same_mesh() {
        let p = Path::new("t.ply");
        let a = parse_ply(p, ASCII.as_bytes(), 0.0).unwrap();
        assert_eq!((a.vertices.len(), a.triangles.len()), (5, 3));
        assert_eq!(parse_ply(p, &binary(false), 0.0).unwrap(), a);
        assert_eq!(parse_ply(p, &binary(true), 0.0).unwrap(), a);
    }

    #[test]
    fn malformed_files_name_the_line_or_byte() {
        let p = Path::new("t.ply");
        let e = |b: &[u8]| match parse_ply(p, b, 0.0) {
            Ok(_) => format!("accepted: {}", String::from_utf8_lossy(b)),
            Err(e) => e.to_string(),
        };
        let cases = [
            (ASCII.replace("element vertex 5", "element vertex five"), "t.ply:4: PLY header"),
            (ASCII.replace("format ascii 1.0", "format text 1.0"), "t.ply:2: PLY header"),
            (ASCII.replace("property float z\n", ""), "t.ply:4: PLY header: the vertex element has no `z`"),
            (
                ASCII.replace("element face 2\nproperty list uchar int vertex_indices\n", ""),
                "t.ply:9: PLY header: no `element face`: a point cloud",
            ),
            (
                ASCII.replace("property list uchar int vertex_indices", "property list uchar float vertex_indices"),
                "t.ply:9: PLY header: the face's",
            ),
            (
                ASCII.replace("1 1 0 255", "1 1 nan 255"),
                "t.ply:14: vertex 2: Couldn't parse element line. String: '1 1 nan 255'",
            ),
            (ASCII.replace("1 1 0 255", "1 1 zero 255"), "t.ply:14: vertex 2:"),
            (ASCII.replace("3 1 4 2", "3 1 5 2"), "t.ply:18: face 1: vertex index 5 is out of range (0..5)"),
            (ASCII.replace("3 1 4 2", "2 1 4"), "t.ply:18: face 1: a face needs at least 3"),
            (ASCII.replace("3 1 4 2\n", ""), "t.ply:18: the file ends before a `face` 1 of 2"),
            ("plx\n".to_string(), "t.ply: byte 0: PLY files start with \"ply\", this one with \"plx\\n\""),
        ];
        for (text, want) in cases {
            let s = e(text.as_bytes());
            assert!(s.starts_with(want), "{s}\nwant {want}");
        }
        // Binary: the header is 173 bytes, a vertex 16, the first face 9.
        let b = binary(false);
        let s = e(&b[..b.len() - 2]);
        assert_eq!(s, "t.ply: byte 262: the file ends inside `face` 1 of 2 (5 bytes left)");
        let mut bad = b.clone();
        bad[262 + 3] = 9; // face 1's second index
        assert_eq!(e(&bad), "t.ply: byte 262: face 1: vertex index 9 is out of range (0..5)");
        let mut nan = b.clone();
        nan[173 + 16 * 3 + 4..173 + 16 * 3 + 8].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(e(&nan), "t.ply: byte 221: vertex 3: y is NaN");
        let bb = binary(true);
        assert_eq!(e(&bb[..200]), "t.ply: byte 186: the file ends inside `vertex` 1 of 5 (14 bytes left)");
    }
}
