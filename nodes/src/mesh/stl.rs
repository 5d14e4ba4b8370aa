//! STL loading, ASCII and binary, hand-written (why not the `stl_io`
//! crate: docs/mesh.md, "Formats").
//!
//! **Which kind.** A binary STL is an 80-byte header, a little-endian u32
//! triangle count n and n records of 50 bytes (normal, three corners as
//! f32, a 2-byte attribute), so it is exactly 84 + 50·n bytes. A file of
//! that size is read as binary even when its header starts with `solid`
//! (several CAD exporters write such headers); any other file starting
//! with `solid` is ASCII; anything else is a binary STL of the wrong size,
//! refused with the byte offset where its data stops matching its count.
//!
//! **ASCII** keywords are matched case-insensitively, several `solid`
//! blocks may follow one another, a facet may list more than three
//! vertices (a polygon, triangulated as a fan), coordinates are read as
//! f64. Normals are ignored (some exporters write `nan` for degenerate
//! facets): [`Mesh::new`] recomputes them and welds the corners, which STL
//! repeats for every triangle, into shared vertices.

use super::error::MeshError;
use super::trimesh::Mesh;
use std::path::Path;

/// Size of the binary header: 80 bytes of text, the u32 triangle count.
const HEADER: usize = 84;
/// Size of one binary triangle record.
const RECORD: usize = 50;

/// Loads an STL file (ASCII or binary).
pub fn load_stl(path: &Path, weld: f64) -> Result<Mesh, MeshError> {
    let bytes = evflow_engine::files::read_regular(path)
        .map_err(|e| MeshError::Io { path: path.into(), message: e.to_string() })?;
    parse_stl(path, &bytes, weld)
}

/// Parses STL bytes; `path` only names the source in errors.
pub fn parse_stl(path: &Path, bytes: &[u8], weld: f64) -> Result<Mesh, MeshError> {
    let (vertices, triangles) = if is_binary(bytes) {
        read_binary(path, bytes)?
    } else if starts_with_solid(bytes) {
        read_ascii(path, bytes)?
    } else {
        // Neither: report it as a binary STL of the wrong size.
        read_binary(path, bytes)?
    };
    Mesh::from_faces(&path.display().to_string(), vertices, triangles, weld)
}

/// The binary triangle count a file's header announces, if it has one.
fn binary_count(bytes: &[u8]) -> Option<usize> {
    let c = bytes.get(80..HEADER)?;
    Some(u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize)
}

/// Whether the file is exactly the size of a binary STL of its count.
fn is_binary(bytes: &[u8]) -> bool {
    binary_count(bytes).is_some_and(|n| n.checked_mul(RECORD).and_then(|b| b.checked_add(HEADER)) == Some(bytes.len()))
}

/// Whether the first word of the file is `solid` (ASCII STL).
fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let rest = &bytes[start..];
    rest.len() >= 5 && rest[..5].eq_ignore_ascii_case(b"solid") && rest.get(5).is_none_or(|b| b.is_ascii_whitespace())
}

type Faces = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Reads the binary layout, refusing a file whose size does not match
/// its count (truncated: the byte where the first incomplete record
/// starts; longer: the first byte past the last record).
fn read_binary(path: &Path, bytes: &[u8]) -> Result<Faces, MeshError> {
    let Some(n) = binary_count(bytes) else {
        return Err(MeshError::Truncated {
            path: path.into(),
            offset: 0,
            what: "the 84-byte header of a binary STL (the file does not start with `solid`, so it is not ASCII)"
                .into(),
            available: bytes.len() as u64,
        });
    };
    let body = bytes.len() - HEADER;
    let have = body / RECORD;
    if have < n {
        let offset = HEADER + have * RECORD;
        return Err(MeshError::Truncated {
            path: path.into(),
            offset: offset as u64,
            what: format!("triangle {} of the {n} the header announces (50 bytes each)", have + 1),
            available: (bytes.len() - offset) as u64,
        });
    }
    let end = HEADER + n * RECORD;
    if bytes.len() != end {
        return Err(MeshError::Binary {
            path: path.into(),
            offset: end as u64,
            message: format!(
                "{} bytes follow the {n} triangles the header announces (a binary STL is 84 + 50·n bytes)",
                bytes.len() - end
            ),
        });
    }
    let mut vertices = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for k in 0..n {
        let rec = HEADER + k * RECORD;
        for c in 0..3 {
            let mut p = [0.0; 3];
            for (i, x) in p.iter_mut().enumerate() {
                let at = rec + 12 + 12 * c + 4 * i;
                let v = f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
                if !v.is_finite() {
                    return Err(MeshError::Binary {
                        path: path.into(),
                        offset: at as u64,
                        message: format!(
                            "triangle {}: corner {} coordinate {} is {v}",
                            k + 1,
                            c + 1,
                            ["x", "y", "z"][i]
                        ),
                    });
                }
                *x = v as f64;
            }
            vertices.push(p);
        }
        let b = 3 * k as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    Ok((vertices, triangles))
}

/// Where the ASCII reader is in the grammar.
#[derive(Clone, Copy, PartialEq)]
enum State {
    /// Before a `solid` (start of file, or after `endsolid`).
    Outside,
    /// Inside a solid: `facet` or `endsolid` next.
    Solid,
    /// After `facet`: `outer loop` next.
    Facet,
    /// Inside a loop: `vertex` or `endloop`.
    Loop,
    /// After `endloop`: `endfacet` next.
    EndLoop,
}

/// Reads the ASCII grammar line by line.
fn read_ascii(path: &Path, bytes: &[u8]) -> Result<Faces, MeshError> {
    let err = |line: usize, message: String| MeshError::Syntax { path: path.into(), line, message };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        let size = match binary_count(bytes) {
            Some(n) => format!(
                "; read as ASCII because it starts with `solid`, but a binary STL of {n} triangles would be {} bytes and this \
                 file is {}",
                HEADER as u64 + RECORD as u64 * n as u64,
                bytes.len()
            ),
            None => String::new(),
        };
        err(line, format!("not text (byte {}){size}", e.valid_up_to()))
    })?;
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut state = State::Outside;
    let mut polygon: Vec<u32> = Vec::with_capacity(3);
    let mut last = 0;
    for (k, line) in text.lines().enumerate() {
        let no = k + 1;
        last = no;
        let mut words = line.split_whitespace();
        let Some(word) = words.next() else { continue };
        let key = word.to_ascii_lowercase();
        let expect = |what: &str| err(no, format!("expected {what}, found `{}`", line.trim()));
        state = match (state, key.as_str()) {
            (State::Outside, "solid") => State::Solid,
            (State::Outside, _) => return Err(expect("`solid`")),
            (State::Solid, "facet") => State::Facet,
            (State::Solid, "endsolid") => State::Outside,
            (State::Solid, _) => return Err(expect("`facet` or `endsolid`")),
            (State::Facet, "outer") if words.next().is_some_and(|w| w.eq_ignore_ascii_case("loop")) => State::Loop,
            (State::Facet, _) => return Err(expect("`outer loop`")),
            (State::Loop, "vertex") => {
                let xyz: Vec<&str> = words.collect();
                if xyz.len() != 3 {
                    return Err(err(no, format!("`vertex` takes 3 numbers (x y z), found {}", xyz.len())));
                }
                let mut p = [0.0; 3];
                for (x, w) in p.iter_mut().zip(&xyz) {
                    *x = match w.parse::<f64>() {
                        Ok(v) if v.is_finite() => v,
                        Ok(_) => return Err(err(no, format!("`{w}` is not a finite number"))),
                        Err(_) => return Err(err(no, format!("`{w}` is not a number"))),
                    };
                }
                polygon.push(vertices.len() as u32);
                vertices.push(p);
                State::Loop
            }
            (State::Loop, "endloop") => {
                if polygon.len() < 3 {
                    return Err(err(no, format!("a facet needs at least 3 vertices, found {}", polygon.len())));
                }
                for i in 1..polygon.len() - 1 {
                    triangles.push([polygon[0], polygon[i], polygon[i + 1]]);
                }
                polygon.clear();
                State::EndLoop
            }
            (State::Loop, _) => return Err(expect("`vertex` or `endloop`")),
            (State::EndLoop, "endfacet") => State::Solid,
            (State::EndLoop, _) => return Err(expect("`endfacet`")),
        };
    }
    if state != State::Outside {
        let inside = match state {
            State::Solid => "a solid (no `endsolid`)",
            _ => "a facet",
        };
        return Err(err(last + 1, format!("the file ends inside {inside}: truncated?")));
    }
    Ok((vertices, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  \
                         endloop\n endfacet\n facet normal nan nan nan\n  outer loop\n   vertex 1 0 0\n   vertex 1 1 0.5\n   \
                         vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";

    fn binary(header: &[u8; 80], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = header.to_vec();
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0u8; 12]);
            for c in t {
                for x in c {
                    b.extend(x.to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    }

    #[test]
    fn ascii_and_binary_give_the_same_welded_mesh() {
        let a = parse_stl(Path::new("a.stl"), ASCII.as_bytes(), 0.0).unwrap();
        assert_eq!((a.vertices.len(), a.triangles.len()), (4, 2));
        let tris =
            [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.5], [0.0, 1.0, 0.0]]];
        // A binary header that starts with "solid", as some exporters write it.
        let mut h = [b' '; 80];
        h[..11].copy_from_slice(b"solid part1");
        let b = parse_stl(Path::new("b.stl"), &binary(&h, &tris), 0.0).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn ascii_polygons_case_and_several_solids() {
        let text = "SOLID\nFACET NORMAL 0 0 1\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 1 1 0\nVERTEX 0 1 0\n\
                    ENDLOOP\nENDFACET\nENDSOLID\nsolid b\nendsolid b\n";
        let m = parse_stl(Path::new("q.stl"), text.as_bytes(), 0.0).unwrap();
        assert_eq!(m.triangles.len(), 2);
    }

    #[test]
    fn malformed_files_name_the_line_or_byte() {
        let p = Path::new("t.stl");
        let ascii = [
            (ASCII.replace("vertex 1 1 0.5", "vertex 1 1"), 12, "takes 3 numbers"),
            (ASCII.replace("vertex 1 1 0.5", "vertex 1 1 inf"), 12, "not a finite number"),
            (ASCII.replace("vertex 1 1 0.5", "vertex 1 1 x"), 12, "not a number"),
            (ASCII.replace("  outer loop\n   vertex 1 0 0", "  vertex 1 0 0"), 10, "expected `outer loop`"),
            (ASCII.replace("endsolid t\n", ""), 16, "no `endsolid`"),
            (ASCII[..100].to_string(), 9, "inside a facet"),
            (
                ASCII.replace("   vertex 0 1 0\n  endloop\n endfacet\nendsolid", "  endloop\n endfacet\nendsolid"),
                13,
                "at least 3",
            ),
        ];
        for (text, line, msg) in ascii {
            let e = parse_stl(p, text.as_bytes(), 0.0).unwrap_err().to_string();
            assert!(e.starts_with(&format!("t.stl:{line}: ")) && e.contains(msg), "{e}");
        }
        let tri = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3];
        let good = binary(&[0; 80], &tri);
        // Truncated in the third record, after the header, inside the header.
        let e = parse_stl(p, &good[..good.len() - 7], 0.0).unwrap_err().to_string();
        assert_eq!(e, "t.stl: byte 184: the file ends inside triangle 3 of the 3 the header announces (50 bytes each) (43 bytes left)");
        let e = parse_stl(p, &good[..84], 0.0).unwrap_err().to_string();
        assert!(e.starts_with("t.stl: byte 84: the file ends inside triangle 1 of the 3"), "{e}");
        let e = parse_stl(p, &good[..50], 0.0).unwrap_err().to_string();
        assert!(e.starts_with("t.stl: byte 0: the file ends inside the 84-byte header"), "{e}");
        // Trailing bytes.
        let mut long = good.clone();
        long.extend([0; 3]);
        let e = parse_stl(p, &long, 0.0).unwrap_err().to_string();
        assert!(e.starts_with("t.stl: byte 234: 3 bytes follow the 3 triangles"), "{e}");
        // A NaN corner: the offset of the value.
        let mut nan = tri;
        nan[1][2][1] = f32::NAN;
        let e = parse_stl(p, &binary(&[0; 80], &nan), 0.0).unwrap_err().to_string();
        assert_eq!(e, "t.stl: byte 174: triangle 2: corner 3 coordinate y is NaN");
        // Binary that starts with "solid" but has the wrong size: read as ASCII, the size explained.
        let mut h = [0u8; 80];
        h[..6].copy_from_slice(b"solid ");
        let mut b = binary(&h, &tri);
        b.extend([0xff; 3]);
        let e = parse_stl(p, &b, 0.0).unwrap_err().to_string();
        assert!(e.contains("not text") && e.contains("would be 234 bytes and this file is 237"), "{e}");
        // Nothing to touch.
        assert!(matches!(parse_stl(p, &binary(&[0; 80], &[]), 0.0), Err(MeshError::Empty { .. })));
        let flat = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]; 2];
        assert!(matches!(parse_stl(p, &binary(&[0; 80], &flat), 0.0), Err(MeshError::Degenerate { triangles: 2, .. })));
        assert!(load_stl(Path::new("/nonexistent/x.stl"), 0.0).unwrap_err().to_string().contains("/nonexistent/x.stl"));
    }
}
