//! Writers of every mesh format, shared by `tests/mesh_formats.rs`,
//! `tests/mesh_extremes.rs` and `benches/mesh_formats.rs`: a [`Mesh`] written as OBJ, ASCII and binary
//! STL, ASCII and binary (both byte orders) PLY, glTF with a base64
//! buffer and GLB, z-up or y-up.
#![allow(dead_code)]

use base64::Engine;
use evflow_engine::harness::Single;
use evflow_nodes::mesh::{gradient_node, Mesh};
use std::fmt::Write;
use std::path::Path;

/// How a file's coordinates relate to the z-up mesh: written as is, or
/// y-up (the inverse of the turn `up = "+y"` makes: (x, y, z) → (x, z, −y)).
#[derive(Clone, Copy, PartialEq, Debug)]
pub enum Axis {
    /// As the mesh is (z-up).
    ZUp,
    /// Turned y-up.
    YUp,
}

impl Axis {
    /// A z-up point in the file's axes.
    pub fn write(self, [x, y, z]: [f64; 3]) -> [f64; 3] {
        match self {
            Axis::ZUp => [x, y, z],
            Axis::YUp => [x, z, -y],
        }
    }
    /// The `up` word that reads the file back.
    pub fn word(self) -> &'static str {
        match self {
            Axis::ZUp => "+z",
            Axis::YUp => "+y",
        }
    }
}

/// A writer of one format.
pub type Writer = fn(&Mesh, Axis) -> Vec<u8>;
/// Every way a mesh is written here: file name suffix and writer.
pub const WRITERS: [(&str, Writer); 8] = [
    ("obj", obj),
    ("ascii.stl", stl_ascii),
    ("bin.stl", stl_binary),
    ("ascii.ply", ply_ascii),
    ("le.ply", |m, a| ply_binary(m, a, false)),
    ("be.ply", |m, a| ply_binary(m, a, true)),
    ("gltf", gltf_embedded),
    ("glb", glb),
];

/// The mesh's vertices as the file stores them (the f64 values, which are
/// f32 values for the shipped meshes: text prints them exactly).
pub fn points(m: &Mesh, a: Axis) -> Vec<[f64; 3]> {
    m.vertices.iter().map(|&p| a.write(p)).collect()
}

/// The mesh as OBJ.
pub fn obj(m: &Mesh, a: Axis) -> Vec<u8> {
    let mut s = String::new();
    for p in points(m, a) {
        writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for t in &m.triangles {
        writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    s.into_bytes()
}

/// The mesh as ASCII STL.
pub fn stl_ascii(m: &Mesh, a: Axis) -> Vec<u8> {
    let p = points(m, a);
    let mut s = String::from("solid test\n");
    for t in &m.triangles {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for &i in t {
            let v = p[i as usize];
            writeln!(s, "      vertex {} {} {}", v[0], v[1], v[2]).unwrap();
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid test\n";
    s.into_bytes()
}

/// The mesh as binary STL (header starting with `solid`).
pub fn stl_binary(m: &Mesh, a: Axis) -> Vec<u8> {
    let p = points(m, a);
    let mut b = vec![0u8; 80];
    b[..5].copy_from_slice(b"solid"); // as some exporters write it
    b.extend((m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        b.extend([0u8; 12]);
        for &i in t {
            for x in p[i as usize] {
                b.extend((x as f32).to_le_bytes());
            }
        }
        b.extend([0u8; 2]);
    }
    b
}

pub fn ply_header(m: &Mesh, format: &str, xyz: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment written by mesh_formats.rs\nelement vertex {}\nproperty {xyz} x\n\
         property {xyz} y\nproperty {xyz} z\nproperty uchar red\nelement face {}\nproperty list uchar int vertex_indices\n\
         element edge 0\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        m.vertices.len(),
        m.triangles.len()
    )
}

/// The mesh as ASCII PLY (double coordinates).
pub fn ply_ascii(m: &Mesh, a: Axis) -> Vec<u8> {
    // Doubles, so that the exact values survive whatever they are.
    let mut s = ply_header(m, "ascii", "double");
    for p in points(m, a) {
        writeln!(s, "{} {} {} 200", p[0], p[1], p[2]).unwrap();
    }
    for t in &m.triangles {
        writeln!(s, "3 {} {} {}", t[0], t[1], t[2]).unwrap();
    }
    s.into_bytes()
}

/// The mesh as binary PLY (float coordinates), big- or little-endian.
pub fn ply_binary(m: &Mesh, a: Axis, big: bool) -> Vec<u8> {
    let enc = if big { "binary_big_endian" } else { "binary_little_endian" };
    let mut b = ply_header(m, enc, "float").into_bytes();
    let f = |x: f32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    let i = |x: i32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    for p in points(m, a) {
        for x in p {
            b.extend(f(x as f32));
        }
        b.push(200);
    }
    for t in &m.triangles {
        b.push(3);
        for &k in t {
            b.extend(i(k as i32));
        }
    }
    b
}

/// The glTF buffer (positions then u32 indices) and its JSON, the buffer
/// given by `uri` (or the GLB's BIN chunk).
pub fn gltf_parts(m: &Mesh, a: Axis, uri: impl Fn(&[u8]) -> Option<String>) -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    for p in points(m, a) {
        for x in p {
            bin.extend((x as f32).to_le_bytes());
        }
    }
    let np = bin.len();
    for t in &m.triangles {
        for &k in t {
            bin.extend(k.to_le_bytes());
        }
    }
    let (lo, hi) = points(m, a).iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
        ([0, 1, 2].map(|i| lo[i].min(p[i] as f32 as f64)), [0, 1, 2].map(|i| hi[i].max(p[i] as f32 as f64)))
    });
    let uri = uri(&bin).map_or(String::new(), |u| format!(r#""uri":"{u}","#));
    // A node with an identity transform written out, and one scene.
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"children":[1]}},{{"mesh":0,"translation":[0,0,0],"scale":[1,1,1]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],
"buffers":[{{{uri}"byteLength":{}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{np}}},{{"buffer":0,"byteOffset":{np},"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}},
{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - np,
        m.vertices.len(),
        3 * m.triangles.len()
    );
    (json, bin)
}

/// The mesh as glTF with a base64 data URI buffer.
pub fn gltf_embedded(m: &Mesh, a: Axis) -> Vec<u8> {
    let uri = |b: &[u8]| {
        Some(format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(b)))
    };
    gltf_parts(m, a, uri).0.into_bytes()
}

/// The mesh as GLB.
pub fn glb(m: &Mesh, a: Axis) -> Vec<u8> {
    let (json, bin) = gltf_parts(m, a, |_| None);
    let mut j = json.into_bytes();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut b = b"glTF".to_vec();
    for x in [2, total as u32, j.len() as u32, 0x4E4F_534A] {
        b.extend(x.to_le_bytes());
    }
    b.extend(j);
    b.extend((bin.len() as u32).to_le_bytes());
    b.extend(0x004E_4942u32.to_le_bytes());
    b.extend(bin);
    b
}

/// `mesh.gradient` over touch points (1 kHz), every tick's secant, fixed
/// range: intensity, fsq, slope, z, tri. Shared by the format and the
/// extreme-mesh tests.
pub fn gradient(dir: &Path, params: &str, x: &[f64], y: &[f64]) -> Result<Vec<Vec<f64>>, String> {
    let params = format!("{params}\nrange = \"fixed\"\nmin_step = 0.0");
    Single::new(&gradient_node::SPEC, &params)
        .input("x", x.to_vec(), 1000.0)
        .input("y", y.to_vec(), 1000.0)
        .outputs(["intensity", "fsq", "slope", "z", "tri"])
        .ticks(x.len() as u64)
        .base_dir(dir)
        .run()
}
