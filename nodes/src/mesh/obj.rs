//! OBJ loading with tobj: every line that tobj would read is checked first
//! so a malformed file is refused with its file name and line number (tobj
//! itself reports neither); quads and n-gons are triangulated by tobj (as a
//! fan); vertex normals, texture coordinates and materials are ignored —
//! normals are recomputed from the geometry ([`Mesh::new`]), which also
//! welds the vertices tobj splits per object and group. OBJ files are
//! y-up by convention (docs/mesh.md, "Formats").

use super::error::MeshError;
use super::trimesh::Mesh;
use std::io::BufRead;
use std::path::Path;

/// Loads an OBJ file.
pub fn load_obj(path: &Path, weld: f64) -> Result<Mesh, MeshError> {
    let text = evflow_engine::files::read_regular_to_string(path)
        .map_err(|e| MeshError::Io { path: path.into(), message: e.to_string() })?;
    parse_obj(path, &text, weld)
}

/// Parses OBJ text; `path` only names the source in errors.
pub fn parse_obj(path: &Path, text: &str, weld: f64) -> Result<Mesh, MeshError> {
    check_lines(path, text)?;
    let opts = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| MeshError::Obj { path: path.into(), message: e.to_string() })?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for m in &models {
        let base = vertices.len() as u32;
        for p in m.mesh.positions.chunks_exact(3) {
            vertices.push([p[0], p[1], p[2]]);
        }
        for t in m.mesh.indices.chunks_exact(3) {
            triangles.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    Mesh::from_faces(&path.display().to_string(), vertices, triangles, weld)
}

/// Checks the lines tobj reads for geometry: `v` needs three finite
/// numbers (optionally a nonzero w, or an RGB colour), `vt`/`vn` numbers,
/// `f` at least three vertex references, each index a nonzero integer
/// within the vertices defined so far (negative = relative).
fn check_lines(path: &Path, text: &str) -> Result<(), MeshError> {
    let err = |line: usize, message: String| MeshError::Syntax { path: path.into(), line, message };
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    for (k, line) in text.as_bytes().lines().enumerate() {
        let no = k + 1;
        let line = line.map_err(|e| err(no, format!("unreadable line: {e}")))?;
        let mut words = line.split_whitespace();
        let Some(tag) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        let numbers = |n: usize, what: &str| -> Result<Vec<f64>, MeshError> {
            if rest.len() < n {
                return Err(err(no, format!("`{tag}` needs {n} numbers ({what}), found {}", rest.len())));
            }
            rest.iter()
                .map(|w| match w.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    Ok(_) => Err(err(no, format!("`{w}` is not a finite number"))),
                    Err(_) => Err(err(no, format!("`{w}` is not a number"))),
                })
                .collect()
        };
        match tag {
            "v" => {
                let x = numbers(3, "x y z")?;
                match x.len() {
                    3 | 6 => {}
                    4 if x[3] != 0.0 => {}
                    4 => return Err(err(no, "vertex weight w is zero".into())),
                    n => return Err(err(no, format!("`v` takes 3, 4 or 6 numbers, found {n}"))),
                }
                nv += 1;
            }
            "vt" => {
                numbers(1, "u [v [w]]")?;
                nt += 1;
            }
            "vn" => {
                numbers(3, "x y z")?;
                nn += 1;
            }
            "f" => {
                if rest.len() < 3 {
                    return Err(err(no, format!("a face needs at least 3 vertices, found {}", rest.len())));
                }
                for w in &rest {
                    let parts: Vec<&str> = w.split('/').collect();
                    if parts.len() > 3 {
                        return Err(err(no, format!("`{w}` is not a vertex reference (v, v/vt, v//vn or v/vt/vn)")));
                    }
                    for (j, (part, count)) in parts.iter().zip([nv, nt, nn]).enumerate() {
                        if part.is_empty() && j > 0 {
                            continue;
                        }
                        let what = ["vertex", "texture coordinate", "normal"][j];
                        let i: i64 = part.parse().map_err(|_| err(no, format!("`{w}`: `{part}` is not an index")))?;
                        let ok = (i > 0 && i <= count) || (i < 0 && -i <= count);
                        if !ok {
                            return Err(err(
                                no,
                                format!(
                                    "`{w}`: {what} index {i} is out of range (1..={count} or -{count}..=-1 so far)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Mesh, MeshError> {
        parse_obj(Path::new("t.obj"), text, 0.0)
    }

    #[test]
    fn quads_and_ngons_are_triangulated_and_groups_welded() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvn 0 0 1\nvt 0 0\n\
                    o a\nf 1/1/1 2/1/1 3/1/1 4/1/1\no b\nf 2//1 5//1 6//1 3//1\n\
                    g c\nf -6 -5 -4 -3 -2\n";
        let m = parse(text).unwrap();
        // 2 + 2 + 3 triangles, six distinct positions; the pentagon's first two
        // triangles repeat the first quad's and are dropped.
        assert_eq!(m.triangles.len(), 5);
        assert_eq!(m.vertices.len(), 6);
        // The fan of the (self-overlapping) pentagon folds one triangle over:
        // normals are ±z, the consistently oriented sheet faces up.
        assert!(m.normals.iter().all(|n| n[2].abs() == 1.0));
        assert!(m.normals.iter().filter(|n| n[2] == 1.0).count() >= 4, "{:?}", m.normals);
    }

    #[test]
    fn malformed_files_name_file_and_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", 2, "needs 3 numbers"),
            ("v 0 0 0\nv 1 0 zero\n", 2, "not a number"),
            ("v 0 0 nan\n", 1, "finite"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "out of range"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "at least 3"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 0\n", 5, "out of range"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n", 4, "not an index"),
            ("v 0 0 0 0\n", 1, "w is zero"),
        ];
        for (text, line, msg) in cases {
            let e = parse(text).unwrap_err();
            let s = e.to_string();
            assert!(s.starts_with(&format!("t.obj:{line}: ")), "{s}");
            assert!(s.contains(msg), "{s}");
        }
        assert!(matches!(parse("v 0 0 0\n"), Err(MeshError::Empty { .. })));
        let e = load_obj(Path::new("/nonexistent/x.obj"), 0.0).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/x.obj"));
    }
}
