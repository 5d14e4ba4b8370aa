//! glTF 2.0 loading, `.gltf` (JSON, buffers as base64 data URIs or files
//! beside it) and `.glb` (binary container). The JSON document is read by
//! our own serde types and checked in [`super::gltf_doc`] (every index in
//! range, known enum codes, no required extension); this module walks its
//! scene graph.
//!
//! The GLB container (12-byte header, JSON chunk, BIN chunk) is split
//! here so that a wrong magic, version or length names its byte; the
//! buffers are fetched here, and the accessors are read here, after
//! checking that each lies inside its buffer view and buffer, so a bad
//! index or a non-finite coordinate names its byte.
//!
//! **What is read.** The default scene (else the first; without scenes,
//! every mesh once, untransformed), each node's mesh placed by the
//! product of the node transforms down to it (in f64), every primitive
//! of mode triangles, triangle strip or triangle fan (points and lines are
//! ignored), its `POSITION` (float VEC3) and its indices (u8/u16/u32, or
//! none: consecutive vertices). Sparse or quantized positions and
//! required extensions are refused by name. glTF is y-up and in metres
//! by its specification. [`Mesh::new`] welds the vertices.

use super::error::MeshError;
use super::gltf_doc::{self, DataType, Dimensions, DocError, Document, Mode, Transform};
use super::trimesh::Mesh;
use base64::Engine;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// GLB chunk type of the JSON chunk ("JSON", little-endian).
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// GLB chunk type of the binary chunk ("BIN\0").
const CHUNK_BIN: u32 = 0x004E_4942;
/// Deepest node hierarchy followed (a deeper one is taken for a cycle).
const MAX_DEPTH: usize = 256;

/// Loads a `.gltf` or `.glb` file (by content: a file starting with
/// `glTF` is a GLB).
pub fn load_gltf(path: &Path, weld: f64) -> Result<Mesh, MeshError> {
    let bytes = evflow_engine::files::read_regular(path)
        .map_err(|e| MeshError::Io { path: path.into(), message: e.to_string() })?;
    let glb = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    parse_gltf(path, &bytes, glb, weld)
}

/// Parses glTF bytes: a GLB when `glb` (the magic is then required) or
/// when they start with the GLB magic `glTF`, else JSON. External buffer
/// files are looked up beside `path`.
pub fn parse_gltf(path: &Path, bytes: &[u8], glb: bool, weld: f64) -> Result<Mesh, MeshError> {
    let (json, bin, json_at) = if glb || bytes.starts_with(b"glTF") {
        let c = split_glb(path, bytes)?;
        (c.json, c.bin, Some(c.json_at))
    } else {
        (bytes, None, None)
    };
    let doc = gltf_doc::parse(json).map_err(|e| gltf_error(path, e, json_at))?;
    let buffers = fetch_buffers(path, &doc, bin)?;
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut add = |mesh: usize, m: &Mat| -> Result<(), MeshError> {
        for (k, prim) in doc.meshes[mesh].iter().enumerate() {
            let what = format!("meshes[{mesh}].primitives[{k}]");
            let Some(pos) = prim.position else { continue };
            if matches!(prim.mode, Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
                continue;
            }
            let base = vertices.len() as u64;
            for p in read_positions(path, &buffers, &doc, pos, &what)? {
                let q = m.apply(p);
                if !q.iter().all(|x| x.is_finite()) {
                    return Err(gltf_msg(path, format!("{what}: a node transform takes {p:?} to {q:?}")));
                }
                vertices.push(q);
            }
            let n = doc.accessors[pos].count;
            let idx: Vec<u32> = match prim.indices {
                Some(a) => read_indices(path, &buffers, &doc, a, &what, n)?,
                None => (0..n as u32).collect(),
            };
            let tri = |a: u32, b: u32, c: u32| [a, b, c].map(|i| (base + i as u64) as u32);
            match prim.mode {
                Mode::TriangleStrip => {
                    for k in 2..idx.len() {
                        let (a, b, c) = (idx[k - 2], idx[k - 1], idx[k]);
                        triangles.push(if k % 2 == 0 { tri(a, b, c) } else { tri(b, a, c) });
                    }
                }
                Mode::TriangleFan => {
                    for k in 2..idx.len() {
                        triangles.push(tri(idx[0], idx[k - 1], idx[k]));
                    }
                }
                _ => {
                    if !idx.len().is_multiple_of(3) {
                        return Err(gltf_msg(
                            path,
                            format!("{what}: {} indices is not a whole number of triangles", idx.len()),
                        ));
                    }
                    triangles.extend(idx.chunks_exact(3).map(|t| tri(t[0], t[1], t[2])));
                }
            }
            if vertices.len() > u32::MAX as usize {
                return Err(gltf_msg(path, "more than 2³² vertices".into()));
            }
        }
        Ok(())
    };
    let scene = doc.scene.or(if doc.scenes.is_empty() { None } else { Some(0) });
    match scene {
        Some(scene) => {
            let mut stack: Vec<(usize, Mat, usize)> =
                doc.scenes[scene].iter().map(|&n| (n, Mat::IDENTITY, 0)).collect();
            while let Some((k, parent, depth)) = stack.pop() {
                if depth > MAX_DEPTH {
                    return Err(gltf_msg(
                        path,
                        format!("nodes[{k}]: node hierarchy deeper than {MAX_DEPTH} (a cycle?)"),
                    ));
                }
                let node = &doc.nodes[k];
                let m = parent.then(&Mat::of(node.transform));
                if let Some(mesh) = node.mesh {
                    add(mesh, &m)?;
                }
                stack.extend(node.children.iter().map(|&c| (c, m, depth + 1)));
            }
        }
        None => {
            for mesh in 0..doc.meshes.len() {
                add(mesh, &Mat::IDENTITY)?;
            }
        }
    }
    Mesh::from_faces(&path.display().to_string(), vertices, triangles, weld)
}

/// A glTF error without a byte offset.
fn gltf_msg(path: &Path, message: String) -> MeshError {
    MeshError::Gltf { path: path.into(), message }
}

/// A document error as a mesh error: JSON errors by line (of the file,
/// or of the GLB's JSON chunk), validation errors by JSON path.
fn gltf_error(path: &Path, e: DocError, json_at: Option<u64>) -> MeshError {
    match e {
        DocError::Syntax(j) => {
            let inside = json_at.map_or(String::new(), |at| format!(" of the JSON chunk (from byte {at})"));
            MeshError::Syntax {
                path: path.into(),
                line: j.line(),
                message: format!("column {}{inside}: {j}", j.column()),
            }
        }
        DocError::Invalid(all) => gltf_msg(path, format!("invalid document: {}", all.join("; "))),
    }
}

/// A little-endian u32 at `at`.
fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The chunks of a GLB.
struct Chunks<'a> {
    /// The JSON chunk's bytes.
    json: &'a [u8],
    /// The JSON chunk's offset in the file.
    json_at: u64,
    /// The BIN chunk's bytes and offset, if there is one.
    bin: Option<(&'a [u8], u64)>,
}

/// Splits a GLB into its chunks, checking the header and chunk lengths.
fn split_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<Chunks<'a>, MeshError> {
    let truncated = |offset: usize, what: &str| MeshError::Truncated {
        path: path.into(),
        offset: offset as u64,
        what: what.into(),
        available: (bytes.len() - offset) as u64,
    };
    if !bytes.starts_with(b"glTF") {
        let found = String::from_utf8_lossy(&bytes[..bytes.len().min(4)]).into_owned();
        return Err(MeshError::Magic { path: path.into(), format: "GLB", expected: "glTF".into(), found });
    }
    if bytes.len() < 12 {
        return Err(truncated(0, "the 12-byte GLB header"));
    }
    let version = u32_at(bytes, 4);
    if version != 2 {
        return Err(MeshError::Binary {
            path: path.into(),
            offset: 4,
            message: format!("GLB version {version}; only glTF 2 is read"),
        });
    }
    let length = u32_at(bytes, 8) as usize;
    if length != bytes.len() {
        let message = format!(
            "the header gives a length of {length} bytes, the file has {}{}",
            bytes.len(),
            if length > bytes.len() { " (truncated?)" } else { "" }
        );
        return Err(MeshError::Binary { path: path.into(), offset: 8, message });
    }
    let mut json = None;
    let mut bin = None;
    let mut at = 12;
    while at < bytes.len() {
        if bytes.len() - at < 8 {
            return Err(truncated(at, "a chunk header (8 bytes)"));
        }
        let (len, ty) = (u32_at(bytes, at) as usize, u32_at(bytes, at + 4));
        let data = at + 8;
        if bytes.len() - data < len {
            let what = match ty {
                CHUNK_JSON => "the JSON chunk",
                CHUNK_BIN => "the BIN chunk",
                _ => "a chunk",
            };
            return Err(truncated(data, &format!("{what} ({len} bytes)")));
        }
        match ty {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some((&bytes[data..data + len], data as u64)),
            CHUNK_JSON => {
                return Err(MeshError::Binary {
                    path: path.into(),
                    offset: at as u64 + 4,
                    message: "a second JSON chunk".into(),
                })
            }
            CHUNK_BIN if bin.is_none() && json.is_some() => bin = Some((&bytes[data..data + len], data as u64)),
            _ if json.is_none() => {
                return Err(MeshError::Binary {
                    path: path.into(),
                    offset: at as u64 + 4,
                    message: format!("the first chunk must be JSON (type 0x{:08x}), found 0x{ty:08x}", CHUNK_JSON),
                })
            }
            _ => {} // Unknown chunks are skipped, as the specification asks.
        }
        at = data + len;
    }
    let Some((json, json_at)) = json else {
        return Err(truncated(12, "the JSON chunk"));
    };
    Ok(Chunks { json, json_at, bin })
}

/// A buffer's bytes and where they came from (for errors).
struct Buffer<'a> {
    /// The bytes.
    data: Cow<'a, [u8]>,
    /// The file they are in and the offset of byte 0 in it, or `None`
    /// for a base64 data URI.
    file: Option<(PathBuf, u64)>,
}

/// Fetches every buffer: the GLB's BIN chunk, a base64 data URI or a
/// file relative to the glTF file.
fn fetch_buffers<'a>(path: &Path, doc: &Document, bin: Option<(&'a [u8], u64)>) -> Result<Vec<Buffer<'a>>, MeshError> {
    let mut out = Vec::new();
    for (k, b) in doc.buffers.iter().enumerate() {
        let buf = match b.uri.as_deref() {
            None => {
                let (data, at) = bin.ok_or_else(|| {
                    gltf_msg(path, format!("buffers[{k}] refers to the GLB's BIN chunk, which is missing"))
                })?;
                Buffer { data: Cow::Borrowed(data), file: Some((path.into(), at)) }
            }
            Some(uri) if uri.starts_with("data:") => {
                let (head, payload) = uri
                    .split_once(',')
                    .ok_or_else(|| gltf_msg(path, format!("buffers[{k}]: a data URI without `,`")))?;
                if !head.ends_with(";base64") {
                    return Err(gltf_msg(path, format!("buffers[{k}]: only base64 data URIs are read, not `{head}`")));
                }
                let data = base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .map_err(|e| gltf_msg(path, format!("buffers[{k}]: data URI: {e}")))?;
                Buffer { data: Cow::Owned(data), file: None }
            }
            Some(uri) => {
                let file = path.parent().unwrap_or(Path::new("")).join(percent_decode(uri));
                let data = evflow_engine::files::read_regular(&file).map_err(|e| MeshError::Io {
                    path: file.clone(),
                    message: format!("buffers[{k}] of {}: {e}", path.display()),
                })?;
                Buffer { data: Cow::Owned(data), file: Some((file, 0)) }
            }
        };
        if buf.data.len() < b.length {
            let message = format!("buffers[{k}] declares {} bytes, its data has {}", b.length, buf.data.len());
            return Err(match &buf.file {
                Some((file, at)) => MeshError::Truncated {
                    path: file.clone(),
                    offset: at + buf.data.len() as u64,
                    what: format!("buffers[{k}] ({message})"),
                    available: 0,
                },
                None => gltf_msg(path, message),
            });
        }
        out.push(buf);
    }
    Ok(out)
}

/// `%XX` escapes of a relative URI decoded.
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// An error at byte `at` of buffer `buffer`.
fn at_byte(path: &Path, buffers: &[Buffer], buffer: usize, at: usize, message: String) -> MeshError {
    match &buffers[buffer].file {
        Some((file, start)) => MeshError::Binary { path: file.clone(), offset: start + at as u64, message },
        None => gltf_msg(path, format!("buffers[{buffer}] (data URI), byte {at}: {message}")),
    }
}

/// The bytes of each element of an accessor: (buffer index, start of the
/// first element, stride), checked to lie inside its view and buffer.
fn layout(
    path: &Path,
    buffers: &[Buffer],
    doc: &Document,
    k: usize,
    what: &str,
    elem: usize,
) -> Result<(usize, usize, usize), MeshError> {
    let a = &doc.accessors[k];
    let name = format!("{what}: accessors[{k}]");
    if a.sparse {
        return Err(gltf_msg(path, format!("{name} is sparse, which this loader does not read")));
    }
    let v = a.view.ok_or_else(|| gltf_msg(path, format!("{name} has no buffer view")))?;
    let view = &doc.views[v];
    let stride = view.stride.unwrap_or(elem);
    let buffer = view.buffer;
    let len = buffers[buffer].data.len();
    let view_end = view.offset.checked_add(view.length).filter(|&e| e <= len).ok_or_else(|| {
        gltf_msg(
            path,
            format!(
                "{name}: bufferViews[{v}] ({} bytes from byte {}) runs past the end of buffers[{buffer}] ({len} bytes)",
                view.length, view.offset
            ),
        )
    })?;
    let start = view.offset.checked_add(a.offset);
    let need = if a.count == 0 { Some(0) } else { (a.count - 1).checked_mul(stride).and_then(|b| b.checked_add(elem)) };
    match start.zip(need).and_then(|(s, n)| s.checked_add(n).map(|e| (s, e))) {
        Some((start, end)) if end <= view_end => Ok((buffer, start, stride)),
        _ => Err(gltf_msg(
            path,
            format!(
                "{name}: {} elements of {elem} bytes (stride {stride}) from byte {} run past the end of bufferViews[{v}]",
                a.count, a.offset
            ),
        )),
    }
}

/// The positions of an accessor (float VEC3), each finite.
fn read_positions(
    path: &Path,
    buffers: &[Buffer],
    doc: &Document,
    k: usize,
    what: &str,
) -> Result<Vec<[f64; 3]>, MeshError> {
    let a = &doc.accessors[k];
    if a.dimensions != Dimensions::Vec3 || a.data_type != DataType::F32 {
        return Err(gltf_msg(
            path,
            format!(
                "{what}: POSITION is {:?} {:?}; float VEC3 is read (quantized positions are not)",
                a.data_type, a.dimensions
            ),
        ));
    }
    let (buffer, start, stride) = layout(path, buffers, doc, k, what, 12)?;
    let data = &buffers[buffer].data;
    (0..a.count)
        .map(|k| {
            let mut p = [0.0; 3];
            for (i, x) in p.iter_mut().enumerate() {
                let at = start + k * stride + 4 * i;
                let v = f32::from_le_bytes([data[at], data[at + 1], data[at + 2], data[at + 3]]);
                if !v.is_finite() {
                    return Err(at_byte(
                        path,
                        buffers,
                        buffer,
                        at,
                        format!("{what}: vertex {k}: {} is {v}", ["x", "y", "z"][i]),
                    ));
                }
                *x = v as f64;
            }
            Ok(p)
        })
        .collect()
}

/// The indices of an accessor (unsigned SCALAR), each below `n`.
fn read_indices(
    path: &Path,
    buffers: &[Buffer],
    doc: &Document,
    k: usize,
    what: &str,
    n: usize,
) -> Result<Vec<u32>, MeshError> {
    let a = &doc.accessors[k];
    let size = match (a.dimensions, a.data_type) {
        (Dimensions::Scalar, DataType::U8) => 1,
        (Dimensions::Scalar, DataType::U16) => 2,
        (Dimensions::Scalar, DataType::U32) => 4,
        (d, t) => return Err(gltf_msg(path, format!("{what}: indices are {t:?} {d:?}; unsigned SCALAR is read"))),
    };
    let (buffer, start, stride) = layout(path, buffers, doc, k, what, size)?;
    let data = &buffers[buffer].data;
    (0..a.count)
        .map(|k| {
            let at = start + k * stride;
            let i = match size {
                1 => data[at] as u32,
                2 => u16::from_le_bytes([data[at], data[at + 1]]) as u32,
                _ => u32_at(data, at),
            };
            if i as usize >= n {
                return Err(at_byte(
                    path,
                    buffers,
                    buffer,
                    at,
                    format!("{what}: index {k} is {i}, out of range (0..{n})"),
                ));
            }
            Ok(i)
        })
        .collect()
}

/// An affine transform in f64: 3×3 linear part (row-major) and translation.
#[derive(Debug, Clone, Copy)]
struct Mat {
    /// Linear part, rows.
    m: [[f64; 3]; 3],
    /// Translation.
    t: [f64; 3],
}

impl Mat {
    /// The identity.
    const IDENTITY: Mat = Mat { m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], t: [0.0; 3] };

    /// A node's transform (glTF: column-major matrix, or T·R·S with R a
    /// unit quaternion x, y, z, w).
    fn of(t: Transform) -> Mat {
        match t {
            Transform::Matrix(c) => Mat {
                m: [0, 1, 2].map(|r| [0, 1, 2].map(|k| c[4 * k + r] as f64)),
                t: [c[12] as f64, c[13] as f64, c[14] as f64],
            },
            Transform::Decomposed { translation, rotation, scale } => {
                let [x, y, z, w] = rotation.map(|v| v as f64);
                let n = (x * x + y * y + z * z + w * w).sqrt();
                let (x, y, z, w) = if n > 0.0 { (x / n, y / n, z / n, w / n) } else { (0.0, 0.0, 0.0, 1.0) };
                let r = [
                    [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                    [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                    [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
                ];
                let s = scale.map(|v| v as f64);
                Mat { m: [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[i][j] * s[j])), t: translation.map(|v| v as f64) }
            }
        }
    }

    /// self ∘ other (other applied first).
    fn then(&self, o: &Mat) -> Mat {
        let m = [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| self.m[i][k] * o.m[k][j]).sum()));
        Mat { m, t: self.apply(o.t) }
    }

    /// The transformed point.
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| self.m[i][0] * p[0] + self.m[i][1] * p[1] + self.m[i][2] * p[2] + self.t[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of two triangles (u16 indices) and a third triangle, in one
    /// buffer: 5 positions (60 bytes) then 9 indices (18 bytes, padded to 20).
    fn buffer() -> Vec<u8> {
        let mut b = Vec::new();
        for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, -1.0], [0.0, 0.0, -1.0], [2.0, 1.0, 0.0]] {
            for x in p {
                b.extend(x.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3, 1, 4, 2] {
            b.extend(i.to_le_bytes());
        }
        b.extend([0, 0]);
        b
    }

    fn json(uri: Option<&str>, node: &str) -> String {
        let uri = uri.map_or(String::new(), |u| format!(r#""uri":"{u}","#));
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0{node}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{{uri}"byteLength":80}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":60}},{{"buffer":0,"byteOffset":60,"byteLength":18}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,-1],"max":[2,1,0]}},
{{"bufferView":1,"componentType":5123,"count":9,"type":"SCALAR"}}]}}"#
        )
    }

    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let total = 12 + 8 + j.len() + 8 + bin.len();
        let mut b = b"glTF".to_vec();
        b.extend(2u32.to_le_bytes());
        b.extend((total as u32).to_le_bytes());
        b.extend((j.len() as u32).to_le_bytes());
        b.extend(CHUNK_JSON.to_le_bytes());
        b.extend(j);
        b.extend((bin.len() as u32).to_le_bytes());
        b.extend(CHUNK_BIN.to_le_bytes());
        b.extend(bin);
        b
    }

    fn embedded(node: &str) -> String {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(buffer())
        );
        json(Some(&uri), node)
    }

    #[test]
    fn gltf_with_a_data_uri_and_glb_read_the_same_mesh() {
        let p = Path::new("t.gltf");
        let a = parse_gltf(p, embedded("").as_bytes(), false, 0.0).unwrap();
        assert_eq!((a.vertices.len(), a.triangles.len()), (5, 3));
        let b = parse_gltf(Path::new("t.glb"), &glb(&json(None, ""), &buffer()), true, 0.0).unwrap();
        assert_eq!(a, b);
        // A node transform: translated, turned a quarter about x (y → z), scaled 2.
        let node = r#","translation":[10,0,0],"rotation":[0.7071067811865476,0,0,0.7071067811865476],"scale":[2,2,2]"#;
        let t = parse_gltf(p, embedded(node).as_bytes(), false, 0.0).unwrap();
        let far = t.vertices.iter().find(|v| v[0] > 13.0).unwrap();
        // (2, 1, 0) → scaled (4, 2, 0) → turned (4, 0, 2) → moved (14, 0, 2).
        for (x, e) in far.iter().zip([14.0, 0.0, 2.0]) {
            assert!((x - e).abs() < 1e-6, "{far:?}");
        }
    }

    #[test]
    fn external_buffers_strips_and_fans() {
        let dir = tempfile::tempdir().unwrap();
        // A buffer file beside the .gltf, its name percent-encoded in the URI.
        std::fs::write(dir.path().join("mesh data.bin"), buffer()).unwrap();
        let path = dir.path().join("t.gltf");
        std::fs::write(&path, json(Some("mesh%20data.bin"), "")).unwrap();
        let a = load_gltf(&path, 0.0).unwrap();
        assert_eq!(a.triangles.len(), 3);
        // The square as a strip (0 1 3 2) and as a fan (0 1 2 3): the same two triangles.
        for (mode, idx) in [(5, [0u16, 1, 3, 2]), (6, [0, 1, 2, 3])] {
            let mut b = buffer();
            for (k, i) in idx.iter().enumerate() {
                b[60 + 2 * k..62 + 2 * k].copy_from_slice(&i.to_le_bytes());
            }
            std::fs::write(dir.path().join("mesh data.bin"), b).unwrap();
            let text = json(Some("mesh%20data.bin"), "")
                .replace(r#""indices":1"#, &format!(r#""indices":1,"mode":{mode}"#))
                .replace(r#""count":9"#, r#""count":4"#);
            std::fs::write(&path, text).unwrap();
            let m = load_gltf(&path, 0.0).unwrap();
            assert_eq!(m.triangles.len(), 2, "mode {mode}");
            let area: f64 = (0..2)
                .map(|t| {
                    let [p, q, r] = m.corners(t);
                    0.5 * ((q[0] - p[0]) * (r[2] - p[2]) - (r[0] - p[0]) * (q[2] - p[2])).abs()
                })
                .sum();
            assert!((area - 1.0).abs() < 1e-12, "mode {mode}: {area}");
        }
    }

    #[test]
    fn glb_bytes_under_any_name_and_primitives_without_positions() {
        // GLB bytes are a GLB whatever the file is called.
        let a = parse_gltf(Path::new("t.gltf"), &glb(&json(None, ""), &buffer()), false, 0.0).unwrap();
        assert_eq!((a.vertices.len(), a.triangles.len()), (5, 3));
        // A primitive without POSITION adds nothing; the others are read.
        let two = r#""primitives":[{"attributes":{"NORMAL":0}},{"attributes":{"POSITION":0},"indices":1}]"#;
        let text = embedded("").replace(r#""primitives":[{"attributes":{"POSITION":0},"indices":1}]"#, two);
        let b = parse_gltf(Path::new("t.gltf"), text.as_bytes(), false, 0.0).unwrap();
        assert_eq!(a, b);
        // A node matrix (column-major): x doubled, then moved by (10, 0, 0).
        let m = r#","matrix":[2,0,0,0,0,1,0,0,0,0,1,0,10,0,0,1]"#;
        let c = parse_gltf(Path::new("t.gltf"), embedded(m).as_bytes(), false, 0.0).unwrap();
        assert!(c.vertices.contains(&[14.0, 1.0, 0.0]), "{:?}", c.vertices);
    }

    #[test]
    fn malformed_files_name_the_byte_line_or_json_path() {
        let p = Path::new("t.glb");
        let good = glb(&json(None, ""), &buffer());
        let e = |b: &[u8]| parse_gltf(p, b, true, 0.0).unwrap_err().to_string();
        let mut bad = good.clone();
        bad[..4].copy_from_slice(b"GLTF");
        assert_eq!(e(&bad), r#"t.glb: byte 0: GLB files start with "glTF", this one with "GLTF""#);
        let mut bad = good.clone();
        bad[4] = 1;
        assert_eq!(e(&bad), "t.glb: byte 4: GLB version 1; only glTF 2 is read");
        let s = e(&good[..good.len() - 10]);
        assert!(s.starts_with("t.glb: byte 8: the header gives a length of"), "{s}");
        // Header length fixed up, so the chunk itself is short.
        let mut cut = good[..good.len() - 10].to_vec();
        let n = cut.len() as u32;
        cut[8..12].copy_from_slice(&n.to_le_bytes());
        let s = e(&cut);
        assert!(s.contains("the file ends inside the BIN chunk (80 bytes)"), "{s}");
        // An index out of range: the byte in the file.
        let mut bad = good.clone();
        let bin_at = good.len() - 80;
        bad[bin_at + 60 + 2 * 7] = 9;
        assert_eq!(
            e(&bad),
            format!("t.glb: byte {}: meshes[0].primitives[0]: index 7 is 9, out of range (0..5)", bin_at + 74)
        );
        // A NaN coordinate.
        let mut bad = good.clone();
        bad[bin_at + 16..bin_at + 20].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(e(&bad), format!("t.glb: byte {}: meshes[0].primitives[0]: vertex 1: y is NaN", bin_at + 16));
        // JSON: syntax by line, validation by path, an accessor past its view.
        let g = Path::new("t.gltf");
        let e = |t: String| parse_gltf(g, t.as_bytes(), false, 0.0).unwrap_err().to_string();
        let s = e(embedded("").replacen("\"scene\":0,", "\"scene\":0,,", 1));
        assert!(s.starts_with("t.gltf:1: column"), "{s}");
        let s = e(embedded("").replace(r#""indices":1"#, r#""indices":7"#));
        assert!(s.starts_with("t.gltf: glTF: invalid document: meshes[0].primitives[0].indices"), "{s}");
        let s = e(embedded("").replace(r#""count":9"#, r#""count":12"#));
        assert!(
            s.contains("accessors[1]: 12 elements of 2 bytes") && s.contains("run past the end of bufferViews[1]"),
            "{s}"
        );
        let s = e(embedded("").replace("\"asset\"", r#""extensionsRequired":["KHR_draco_mesh_compression"],"extensionsUsed":["KHR_draco_mesh_compression"],"asset""#));
        assert!(s.contains("extensionsRequired"), "{s}");
        let s = e(embedded("").replace(";base64,", ";base64,%%"));
        assert!(s.contains("buffers[0]: data URI"), "{s}");
        // Nine nested nodes scaled 10³⁸ each: the product overflows f64.
        let chain: Vec<String> =
            (0..9).map(|k| format!(r#"{{"children":[{}],"scale":[1e38,1e38,1e38]}}"#, k + 1)).collect();
        let nested =
            embedded("").replace(r#""nodes":[{"mesh":0}]"#, &format!(r#""nodes":[{},{{"mesh":0}}]"#, chain.join(",")));
        let s = e(nested);
        assert!(s.contains("meshes[0].primitives[0]: a node transform takes"), "{s}");
        let s = e(json(Some("missing.bin"), ""));
        assert!(s.contains("missing.bin") && s.contains("buffers[0] of t.gltf"), "{s}");
    }
}
