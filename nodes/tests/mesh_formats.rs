//! Mesh file formats (issue 16, point 2): OBJ, STL (ASCII and binary),
//! PLY (ASCII, binary little- and big-endian), glTF (base64 buffer) and
//! GLB, each written here — y-up and z-up — from meshes the test makes and
//! from the shipped Suzanne, fandisk and bunny (`tests/data`), must load
//! to the same welded triangles and render the same gradient; malformed
//! files are refused naming the file and the line or byte.

use crate::mesh_formats_util;

use evflow_nodes::mesh::formats::load_file;
use evflow_nodes::mesh::place::{reorient, Up};
use evflow_nodes::mesh::Mesh;
use mesh_formats_util::{gradient, obj, Axis, WRITERS};
use std::path::{Path, PathBuf};

/// A file of the shipped test data.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// Touch points: five diagonal strokes over a 0.1 m fitted footprint.
fn strokes() -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for k in 0..5 {
        let off = -0.04 + 0.02 * k as f64;
        for i in 0..600 {
            let s = -0.05 + 0.1 * i as f64 / 600.0;
            x.push(s);
            y.push(0.6 * s + off);
        }
    }
    (x, y)
}

/// Asserts two runs' outputs are identical, naming the first difference.
fn same(out: &[Vec<f64>], reference: &[Vec<f64>], what: &str) {
    let names = ["intensity", "fsq", "slope", "z", "tri"];
    for (k, (a, b)) in out.iter().zip(reference).enumerate() {
        assert_eq!(a.len(), b.len(), "{what}: {}", names[k]);
        if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
            panic!("{what}: {} differs first at tick {i}: {} vs {} (reference)", names[k], a[i], b[i]);
        }
    }
}

/// Writes `mesh` in every format and both orientations into `dir`, loads
/// each with its `up` and checks it against `reference` (the node outputs
/// for the mesh as loaded from its own file): the same welded triangle
/// count and the same outputs. With `up` left to `auto`, the y-up OBJ and
/// glTF files and the z-up STL and PLY files are read right.
fn same_in_every_format(dir: &Path, name: &str, mesh: &Mesh, reference: &[Vec<f64>], fit: &str) {
    let (x, y) = strokes();
    for axis in [Axis::ZUp, Axis::YUp] {
        for (suffix, write) in WRITERS {
            let file = format!("{name}-{}.{suffix}", axis.word().replace('+', ""));
            std::fs::write(dir.join(&file), write(mesh, axis)).unwrap();
            let up = match axis {
                Axis::ZUp => Up::PlusZ,
                Axis::YUp => Up::PlusY,
            };
            let loaded = reorient(load_file(&dir.join(&file), 0.0).unwrap(), up);
            assert_eq!(loaded.triangles.len(), mesh.triangles.len(), "{file}: welded triangles");
            assert_eq!(loaded.vertices.len(), mesh.vertices.len(), "{file}: welded vertices");
            let out = gradient(dir, &format!("file = \"{file}\"\nup = \"{}\"\n{fit}", axis.word()), &x, &y).unwrap();
            assert!(out.iter().flatten().all(|v| v.is_finite()), "{file}");
            same(&out, reference, &file);
            let default_is_right = match suffix {
                "obj" | "gltf" | "glb" => axis == Axis::YUp,
                _ => axis == Axis::ZUp,
            };
            if default_is_right {
                same(
                    &gradient(dir, &format!("file = \"{file}\"\n{fit}"), &x, &y).unwrap(),
                    reference,
                    &format!("{file}, up = auto"),
                );
            }
        }
    }
}

#[test]
fn a_written_height_field_is_the_same_in_every_format_and_orientation() {
    let dir = tempfile::tempdir().unwrap();
    // A 12 × 9 cell height field (cm), z-up, with f32-exact coordinates.
    let (n, m) = (12u32, 9u32);
    let h = |x: f64, y: f64| (0.5 * (0.8 * x).sin() + 0.1 * y + 1.0) as f32 as f64;
    let mut v = Vec::new();
    for j in 0..=m {
        for i in 0..=n {
            v.push([i as f64, j as f64, h(i as f64, j as f64)]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut t = Vec::new();
    for j in 0..m {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mesh = Mesh::new(v, t, 0.0);
    std::fs::write(dir.path().join("ref.obj"), obj(&mesh, Axis::ZUp)).unwrap();
    let (x, y) = strokes();
    let fit = "fit = \"footprint\"";
    let reference = gradient(dir.path(), &format!("file = \"ref.obj\"\nup = \"+z\"\n{fit}"), &x, &y).unwrap();
    // Inside the fitted footprint (0.1 × 0.075 m) the finger is on the mesh.
    let on = reference[4].iter().filter(|&&t| t >= 0.0).count();
    assert!(on > x.len() / 2, "{on} of {}", x.len());
    same_in_every_format(dir.path(), "grid", &mesh, &reference, fit);
    // Unfitted too: the same surface in cm at the same place.
    let reference = gradient(dir.path(), "file = \"ref.obj\"\nup = \"+z\"", &x, &y).unwrap();
    same_in_every_format(dir.path(), "grid-cm", &mesh, &reference, "");
}

#[test]
fn suzanne_fandisk_and_bunny_are_the_same_in_every_format_and_orientation() {
    let dir = tempfile::tempdir().unwrap();
    let (x, y) = strokes();
    let fit = "fit = \"footprint\"";
    // Each shipped file read with its format's default up; the counts of the originals.
    for (file, up, triangles) in
        [("suzanne.obj", Up::PlusY, 967), ("fandisk.ply", Up::PlusZ, 12_946), ("bunny.glb", Up::PlusY, 69_451)]
    {
        let name = file.split('.').next().unwrap();
        let shipped = reorient(load_file(&data(file), 0.0).unwrap(), up);
        assert_eq!(shipped.triangles.len(), triangles, "{file}");
        // The binary formats hold f32: the reference is the mesh rounded to f32 (a no-op
        // for the PLY and GLB, which are f32 already), written as a z-up OBJ.
        let rounded: Vec<[f64; 3]> = shipped.vertices.iter().map(|v| v.map(|x| x as f32 as f64)).collect();
        let mesh = Mesh::new(rounded, shipped.triangles.clone(), 0.0);
        let ref_file = format!("{name}-ref.obj");
        std::fs::write(dir.path().join(&ref_file), obj(&mesh, Axis::ZUp)).unwrap();
        let reference = gradient(dir.path(), &format!("file = \"{ref_file}\"\nup = \"+z\"\n{fit}"), &x, &y).unwrap();
        let on = reference[4].iter().filter(|&&t| t >= 0.0).count();
        assert!(on > x.len() / 5, "{file}: on the mesh {on} of {} ticks", x.len());
        // The shipped file itself, `up` left to its format's default.
        let own = gradient(dir.path(), &format!("file = \"{}\"\n{fit}", data(file).display()), &x, &y).unwrap();
        if file.ends_with(".obj") {
            // Rounding to f32 moves the surface by ~1e-7 of its size: the same triangles but
            // for points within that of an edge, the same heights within that.
            let same_tri = own[4].iter().zip(&reference[4]).filter(|(a, b)| a == b).count();
            assert!(same_tri >= x.len() * 99 / 100, "{file}: {same_tri} of {}", x.len());
            for (k, (a, b)) in own[3].iter().zip(&reference[3]).enumerate() {
                if own[4][k] >= 0.0 && reference[4][k] >= 0.0 {
                    assert!((a - b).abs() < 1e-7, "{file}: height at tick {k}: {a} vs {b}");
                }
            }
        } else {
            same(&own, &reference, file);
        }
        same_in_every_format(dir.path(), name, &mesh, &reference, fit);
    }
}

#[test]
fn malformed_files_of_each_format_name_the_file_and_the_line_or_byte() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = reorient(load_file(&data("suzanne.obj"), 0.0).unwrap(), Up::PlusY);
    let good = |suffix: &str| WRITERS.iter().find(|(s, _)| *s == suffix).unwrap().1(&mesh, Axis::ZUp);
    let cut = |b: Vec<u8>, n: usize| b[..b.len() - n].to_vec();
    // The first occurrence of `from` replaced (bytes: the binary formats have text headers).
    let text_edit = |b: Vec<u8>, from: &str, to: &str| {
        let at = b.windows(from.len()).position(|w| w == from.as_bytes()).unwrap();
        [&b[..at], to.as_bytes(), &b[at + from.len()..]].concat()
    };
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("cut.stl", cut(good("bin.stl"), 30), "cut.stl: byte 48384: the file ends inside triangle 967 of the 967"),
        ("cut-ascii.stl", cut(good("ascii.stl"), 40), "cut-ascii.stl:6769: the file ends inside a facet"),
        ("word.stl", text_edit(good("ascii.stl"), "outer loop", "outer lop"), "word.stl:3: expected `outer loop`"),
        ("header.ply", text_edit(good("le.ply"), "property uchar red", "property uchar"), "header.ply:8: PLY header"),
        ("cut.ply", cut(good("be.ply"), 5), "cut.ply: byte"),
        (
            "index.ply",
            text_edit(good("ascii.ply"), "\n3 ", "\n3 9999 "),
            "index.ply:520: face 0: vertex index 9999 is out of range (0..505)",
        ),
        ("magic.glb", text_edit(good("glb"), "glTF", "gltf"), "magic.glb: byte 0: GLB files start with \"glTF\""),
        ("json.gltf", text_edit(good("gltf"), "\"scene\":0", "\"scene\":0,,"), "json.gltf:1: column"),
        ("range.gltf", text_edit(good("gltf"), "\"indices\":1", "\"indices\":5"), "range.gltf: glTF: invalid document"),
        ("shape.off", b"OFF\n".to_vec(), "unknown mesh format"),
    ];
    for (file, bytes, want) in cases {
        std::fs::write(dir.path().join(file), bytes).unwrap();
        let e = gradient(dir.path(), &format!("file = \"{file}\""), &[0.0], &[0.0]).err().unwrap();
        assert!(e.contains(want), "{file}: {e}\nwant: {want}");
    }
}
