//! The glTF 2.0 document the mesh loader walks, read by our own serde types
//! (`gltf_json`, the fields the loader uses) and checked here: every index
//! in range, the enum codes known, the byte stride and sizes sane, the
//! version 2.x, no required extension, no node with both a matrix and
//! translation/rotation/scale. A [`Document`] therefore only holds indices
//! that exist.
//!
//! Each problem is reported as `<JSON path>: <what>`, e.g.
//! `meshes[0].primitives[0].indices: Index out of bounds`, in the words of
//! the `gltf` crate this replaces; a JSON syntax or type error (a missing
//! required field too) is serde's, with its line and column.

use super::gltf_json as json;

/// A glTF document, checked: every index refers to an existing object.
#[derive(Debug, Clone, PartialEq)]
pub struct Document {
    /// The default scene (`scene`).
    pub scene: Option<usize>,
    /// The scenes, each its root nodes.
    pub scenes: Vec<Vec<usize>>,
    /// The nodes.
    pub nodes: Vec<Node>,
    /// The meshes, each its primitives.
    pub meshes: Vec<Vec<Primitive>>,
    /// The buffers.
    pub buffers: Vec<Buffer>,
    /// The buffer views.
    pub views: Vec<View>,
    /// The accessors.
    pub accessors: Vec<Accessor>,
}

/// A node of the scene graph.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Its mesh, if any.
    pub mesh: Option<usize>,
    /// Its child nodes.
    pub children: Vec<usize>,
    /// Its transform relative to its parent.
    pub transform: Transform,
}

/// A node's transform, as the file gives it (f32).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transform {
    /// A 4×4 matrix, column-major (`matrix`).
    Matrix([f32; 16]),
    /// Translation · rotation · scale, each defaulted (0; 0, 0, 0, 1; 1).
    Decomposed {
        /// `translation`.
        translation: [f32; 3],
        /// `rotation`: quaternion x, y, z, w.
        rotation: [f32; 4],
        /// `scale`.
        scale: [f32; 3],
    },
}

/// A primitive of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    /// Its `POSITION` accessor, if any.
    pub position: Option<usize>,
    /// Its index accessor, if any.
    pub indices: Option<usize>,
    /// How its vertices form primitives.
    pub mode: Mode,
}

/// A primitive's topology (`mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// 0.
    Points,
    /// 1.
    Lines,
    /// 2.
    LineLoop,
    /// 3.
    LineStrip,
    /// 4, the default.
    Triangles,
    /// 5.
    TriangleStrip,
    /// 6.
    TriangleFan,
}

/// A buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct Buffer {
    /// Its URI (data URI or relative path); `None`: the GLB's BIN chunk.
    pub uri: Option<String>,
    /// Its declared length in bytes.
    pub length: usize,
}

/// A buffer view: a byte range of a buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Its buffer.
    pub buffer: usize,
    /// First byte in the buffer.
    pub offset: usize,
    /// Length in bytes.
    pub length: usize,
    /// Bytes between elements, if given (4 to 252, a multiple of 4).
    pub stride: Option<usize>,
}

/// An accessor: typed elements in a buffer view.
#[derive(Debug, Clone, PartialEq)]
pub struct Accessor {
    /// Its buffer view (`None` only for a sparse accessor).
    pub view: Option<usize>,
    /// First byte in the view.
    pub offset: usize,
    /// Number of elements.
    pub count: usize,
    /// Component type.
    pub data_type: DataType,
    /// Components per element.
    pub dimensions: Dimensions,
    /// Whether integer components stand for [0, 1] or [−1, 1].
    pub normalized: bool,
    /// Whether the accessor is sparse (not read by the loader).
    pub sparse: bool,
}

/// An accessor's component type (`componentType`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataType {
    /// 5120, byte.
    I8,
    /// 5121, unsigned byte.
    U8,
    /// 5122, short.
    I16,
    /// 5123, unsigned short.
    U16,
    /// 5125, unsigned int.
    U32,
    /// 5126, float.
    F32,
}

/// An accessor's element type (`type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimensions {
    /// SCALAR.
    Scalar,
    /// VEC2.
    Vec2,
    /// VEC3.
    Vec3,
    /// VEC4.
    Vec4,
    /// MAT2.
    Mat2,
    /// MAT3.
    Mat3,
    /// MAT4.
    Mat4,
}

/// Why a document was not read.
#[derive(Debug)]
pub enum DocError {
    /// Not JSON, a wrong JSON type or a missing required field.
    Syntax(serde_json::Error),
    /// Valid JSON but not a valid document: each problem as
    /// `<JSON path>: <what>`, in document order.
    Invalid(Vec<String>),
}

/// Reads and checks a glTF JSON document.
pub fn parse(bytes: &[u8]) -> Result<Document, DocError> {
    let root: json::Root = serde_json::from_slice(bytes).map_err(DocError::Syntax)?;
    let mut c = Check::default();
    let doc = c.document(&root);
    if c.errors.is_empty() {
        Ok(doc)
    } else {
        Err(DocError::Invalid(c.errors))
    }
}

/// The problems found so far.
#[derive(Default)]
struct Check {
    /// `<JSON path>: <what>` each.
    errors: Vec<String>,
}

/// An index past its array's end (this and the next three: the words of
/// the `gltf` crate's validation errors).
const OUT_OF_BOUNDS: &str = "Index out of bounds";
/// An unknown enum code or a value out of its range.
const INVALID: &str = "Invalid value";
/// A required reference absent.
const MISSING: &str = "Missing data";
/// A size that does not fit in `usize`.
const OVERSIZE: &str = "Size exceeds system limits";

impl Check {
    /// Records a problem.
    fn report(&mut self, path: impl FnOnce() -> String, what: &str) {
        self.errors.push(format!("{}: {what}", path()));
    }

    /// An index, checked against its array's length (0 when out of range:
    /// the document is then refused anyway).
    fn index(&mut self, i: json::Index, len: usize, path: impl FnOnce() -> String) -> usize {
        match usize::try_from(i.0) {
            Ok(k) if k < len => k,
            _ => {
                self.report(path, OUT_OF_BOUNDS);
                0
            }
        }
    }

    /// A byte size or count, checked to fit in `usize`.
    fn size(&mut self, v: u64, path: impl FnOnce() -> String) -> usize {
        usize::try_from(v).unwrap_or_else(|_| {
            self.report(path, OVERSIZE);
            0
        })
    }

    /// The whole document, in the order the `gltf` crate checked it.
    fn document(&mut self, r: &json::Root) -> Document {
        let accessors = r.accessors.iter().enumerate().map(|(k, a)| self.accessor(r, k, a)).collect();
        if !r.asset.version.starts_with("2.") {
            let v = &r.asset.version;
            self.report(|| "asset.version".into(), &format!("{v:?} is not glTF 2 (only 2.x is read)"));
        }
        let buffers = r
            .buffers
            .iter()
            .enumerate()
            .map(|(k, b)| Buffer {
                uri: b.uri.clone(),
                length: self.size(b.byte_length, || format!("buffers[{k}].byteLength")),
            })
            .collect();
        let views = r.buffer_views.iter().enumerate().map(|(k, v)| self.view(r, k, v)).collect();
        let scene = r.scene.map(|s| self.index(s, r.scenes.len(), || "scene".into()));
        let meshes = r.meshes.iter().enumerate().map(|(k, m)| self.mesh(r, k, m)).collect();
        let nodes = r.nodes.iter().enumerate().map(|(k, n)| self.node(r, k, n)).collect();
        let scenes = r
            .scenes
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let path = |i: usize| move || format!("scenes[{k}].nodes[{i}]");
                s.nodes.iter().enumerate().map(|(i, &n)| self.index(n, r.nodes.len(), path(i))).collect()
            })
            .collect();
        for (i, ext) in r.extensions_required.iter().enumerate() {
            self.report(|| format!("extensionsRequired[{i}] = \"{ext}\""), "Unsupported extension");
        }
        Document { scene, scenes, nodes, meshes, buffers, views, accessors }
    }

    /// `accessors[k]`.
    fn accessor(&mut self, r: &json::Root, k: usize, a: &json::Accessor) -> Accessor {
        let p = |field: &'static str| move || format!("accessors[{k}].{field}");
        let view = a.buffer_view.map(|v| self.index(v, r.buffer_views.len(), p("bufferView")));
        let offset = self.size(a.byte_offset.unwrap_or(0), p("byteOffset"));
        let count = self.size(a.count, p("count"));
        let data_type = match a.component_type {
            5120 => DataType::I8,
            5121 => DataType::U8,
            5122 => DataType::I16,
            5123 => DataType::U16,
            5125 => DataType::U32,
            5126 => DataType::F32,
            _ => {
                self.report(p("componentType"), INVALID);
                DataType::F32
            }
        };
        let dimensions = match a.type_.as_str() {
            "SCALAR" => Dimensions::Scalar,
            "VEC2" => Dimensions::Vec2,
            "VEC3" => Dimensions::Vec3,
            "VEC4" => Dimensions::Vec4,
            "MAT2" => Dimensions::Mat2,
            "MAT3" => Dimensions::Mat3,
            "MAT4" => Dimensions::Mat4,
            _ => {
                self.report(p("type"), INVALID);
                Dimensions::Scalar
            }
        };
        let sparse = a.sparse.is_some();
        if !sparse && view.is_none() {
            self.report(p("bufferView"), MISSING);
        }
        Accessor { view, offset, count, data_type, dimensions, normalized: a.normalized, sparse }
    }

    /// `bufferViews[k]`.
    fn view(&mut self, r: &json::Root, k: usize, v: &json::View) -> View {
        let p = |field: &'static str| move || format!("bufferViews[{k}].{field}");
        let buffer = self.index(v.buffer, r.buffers.len(), p("buffer"));
        let length = self.size(v.byte_length, p("byteLength"));
        let offset = self.size(v.byte_offset.unwrap_or(0), p("byteOffset"));
        if let Some(s) = v.byte_stride {
            if !(4..=252).contains(&s) {
                self.report(p("byteStride"), INVALID);
            } else if s % 4 != 0 {
                self.report(p("byteStride"), &format!("{s} is not a multiple of 4"));
            }
        }
        View { buffer, offset, length, stride: v.byte_stride }
    }

    /// `meshes[k]`.
    fn mesh(&mut self, r: &json::Root, k: usize, m: &json::Mesh) -> Vec<Primitive> {
        let mut out = Vec::with_capacity(m.primitives.len());
        for (j, prim) in m.primitives.iter().enumerate() {
            let p = move |field: &str| format!("meshes[{k}].primitives[{j}].{field}");
            let mut position = None;
            for (name, &a) in &prim.attributes {
                let i = self.index(a, r.accessors.len(), || p(&format!("attributes[{name:?}]")));
                if name == "POSITION" {
                    position = Some(i);
                }
            }
            let indices = prim.indices.map(|a| self.index(a, r.accessors.len(), || p("indices")));
            let mode = match prim.mode {
                0 => Mode::Points,
                1 => Mode::Lines,
                2 => Mode::LineLoop,
                3 => Mode::LineStrip,
                4 => Mode::Triangles,
                5 => Mode::TriangleStrip,
                6 => Mode::TriangleFan,
                _ => {
                    self.report(|| p("mode"), INVALID);
                    Mode::Triangles
                }
            };
            out.push(Primitive { position, indices, mode });
        }
        out
    }

    /// `nodes[k]`.
    fn node(&mut self, r: &json::Root, k: usize, n: &json::Node) -> Node {
        let children = n.children.as_deref().unwrap_or_default();
        let children = children
            .iter()
            .enumerate()
            .map(|(i, &c)| self.index(c, r.nodes.len(), || format!("nodes[{k}].children[{i}]")))
            .collect();
        let mesh = n.mesh.map(|m| self.index(m, r.meshes.len(), || format!("nodes[{k}].mesh")));
        let trs = n.translation.is_some() || n.rotation.is_some() || n.scale.is_some();
        let transform = match n.matrix {
            Some(m) => {
                if trs {
                    self.report(
                        || format!("nodes[{k}].matrix"),
                        "a node has either a matrix or translation/rotation/scale, not both",
                    );
                }
                Transform::Matrix(m)
            }
            None => Transform::Decomposed {
                translation: n.translation.unwrap_or([0.0; 3]),
                rotation: n.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]),
                scale: n.scale.unwrap_or([1.0; 3]),
            },
        };
        Node { mesh, children, transform }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A document with one of everything: a scene of two nodes (a matrix,
    /// then TRS with a child), a mesh of one primitive, a buffer, two views,
    /// two accessors; `edit` rewrites its text first.
    fn doc(edit: impl Fn(String) -> String) -> Result<Document, DocError> {
        let text = r#"{"asset":{"version":"2.0","generator":"t"},"scene":0,"scenes":[{"nodes":[0,1]}],
"nodes":[{"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,5,6,7,1]},{"children":[0],"translation":[1,2,3],"extras":{}}],
"meshes":[{"primitives":[{"attributes":{"NORMAL":0,"POSITION":0},"indices":1,"material":3}]}],
"buffers":[{"byteLength":48}],
"bufferViews":[{"buffer":0,"byteLength":36,"byteStride":12},{"buffer":0,"byteOffset":36,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
{"bufferView":1,"byteOffset":0,"componentType":5125,"count":3,"type":"SCALAR"}]}"#;
        parse(edit(text.to_string()).as_bytes())
    }

    /// The problems of an invalid document, joined.
    fn invalid(edit: impl Fn(String) -> String) -> String {
        match doc(edit) {
            Err(DocError::Invalid(e)) => e.join("; "),
            other => panic!("{other:?}"),
        }
    }

    /// The serde message of a malformed document.
    fn syntax(edit: impl Fn(String) -> String) -> String {
        match doc(edit) {
            Err(DocError::Syntax(e)) => e.to_string(),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_valid_document_and_its_defaults() {
        let d = doc(|t| t).unwrap();
        assert_eq!((d.scene, d.scenes.clone()), (Some(0), vec![vec![0, 1]]));
        assert_eq!(
            d.nodes[0].transform,
            Transform::Matrix([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 5., 6., 7., 1.])
        );
        let trs = Transform::Decomposed { translation: [1., 2., 3.], rotation: [0., 0., 0., 1.], scale: [1.; 3] };
        assert_eq!((d.nodes[1].transform, d.nodes[1].children.clone(), d.nodes[1].mesh), (trs, vec![0], None));
        assert_eq!(d.meshes[0], vec![Primitive { position: Some(0), indices: Some(1), mode: Mode::Triangles }]);
        assert_eq!(d.buffers[0], Buffer { uri: None, length: 48 });
        assert_eq!(d.views[1], View { buffer: 0, offset: 36, length: 12, stride: None });
        let a = &d.accessors[0];
        assert_eq!(
            (a.view, a.offset, a.count, a.data_type, a.dimensions),
            (Some(0), 0, 3, DataType::F32, Dimensions::Vec3)
        );
        assert!(!a.sparse && !a.normalized);
        // Scenes without nodes, unknown fields, extensions used but not required.
        let d =
            doc(|t| t.replace(r#"{"nodes":[0,1]}"#, "{}").replace("\"asset\"", r#""extensionsUsed":["X"],"asset""#));
        assert_eq!(d.unwrap().scenes, vec![Vec::<usize>::new()]);
    }

    #[test]
    fn every_reference_is_checked_with_its_path() {
        let cases = [
            (r#""scene":0"#, r#""scene":1"#, "scene: Index out of bounds"),
            (r#""nodes":[0,1]"#, r#""nodes":[0,2]"#, "scenes[0].nodes[1]: Index out of bounds"),
            (r#""children":[0]"#, r#""children":[0,5]"#, "nodes[1].children[1]: Index out of bounds"),
            (r#""mesh":0"#, r#""mesh":1"#, "nodes[0].mesh: Index out of bounds"),
            (
                r#""POSITION":0"#,
                r#""POSITION":2"#,
                r#"meshes[0].primitives[0].attributes["POSITION"]: Index out of bounds"#,
            ),
            (
                r#""NORMAL":0"#,
                r#""NORMAL":4294967296"#,
                r#"meshes[0].primitives[0].attributes["NORMAL"]: Index out of bounds"#,
            ),
            (r#""indices":1"#, r#""indices":7"#, "meshes[0].primitives[0].indices: Index out of bounds"),
            (r#""bufferView":1"#, r#""bufferView":2"#, "accessors[1].bufferView: Index out of bounds"),
            (
                r#"{"buffer":0,"byteOffset""#,
                r#"{"buffer":1,"byteOffset""#,
                "bufferViews[1].buffer: Index out of bounds",
            ),
        ];
        for (from, to, expected) in cases {
            assert_eq!(invalid(|t| t.replacen(from, to, 1)), expected);
        }
        // Every problem, in document order.
        let s = invalid(|t| t.replace(r#""indices":1"#, r#""indices":7"#).replace(r#""scene":0"#, r#""scene":3"#));
        assert_eq!(s, "scene: Index out of bounds; meshes[0].primitives[0].indices: Index out of bounds");
    }

    #[test]
    fn codes_sizes_version_extensions_and_transforms_are_checked() {
        let cases = [
            (r#""componentType":5125"#, r#""componentType":5124"#, "accessors[1].componentType: Invalid value"),
            (r#""type":"VEC3""#, r#""type":"VEC5""#, "accessors[0].type: Invalid value"),
            (r#""indices":1"#, r#""indices":1,"mode":7"#, "meshes[0].primitives[0].mode: Invalid value"),
            (r#""byteStride":12"#, r#""byteStride":2"#, "bufferViews[0].byteStride: Invalid value"),
            (r#""byteStride":12"#, r#""byteStride":256"#, "bufferViews[0].byteStride: Invalid value"),
            (r#""byteStride":12"#, r#""byteStride":14"#, "bufferViews[0].byteStride: 14 is not a multiple of 4"),
            (r#""bufferView":1,"#, "", "accessors[1].bufferView: Missing data"),
            (r#""version":"2.0""#, r#""version":"1.0""#, r#"asset.version: "1.0" is not glTF 2 (only 2.x is read)"#),
            (
                r#","extras":{}"#,
                r#","matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]"#,
                "nodes[1].matrix: a node has either a matrix or translation/rotation/scale, not both",
            ),
            (
                r#""asset""#,
                r#""extensionsRequired":["KHR_draco_mesh_compression","EXT_x"],"asset""#,
                r#"extensionsRequired[0] = "KHR_draco_mesh_compression": Unsupported extension; extensionsRequired[1] = "EXT_x": Unsupported extension"#,
            ),
        ];
        for (from, to, expected) in cases {
            assert_eq!(invalid(|t| t.replacen(from, to, 1)), expected, "{to}");
        }
        // A sparse accessor needs no view (the loader refuses it by name).
        let d = doc(|t| t.replacen(r#""bufferView":1,"#, r#""sparse":{"count":1},"#, 1)).unwrap();
        assert!(d.accessors[1].sparse && d.accessors[1].view.is_none());
        assert_eq!(
            doc(|t| t.replacen(r#""byteStride":12"#, r#""byteStride":252"#, 1)).unwrap().views[0].stride,
            Some(252)
        );
    }

    #[test]
    fn json_types_and_required_fields_are_serde_errors() {
        let s = syntax(|t| t.replacen(r#""count":3,"#, "", 1));
        assert!(s.starts_with("missing field `count` at line 6"), "{s}");
        let s = syntax(|t| t.replacen(r#""asset":{"version":"2.0","generator":"t"},"#, "", 1));
        assert!(s.starts_with("missing field `asset`"), "{s}");
        // The "expected" texts of the `gltf` crate.
        let s = syntax(|t| t.replacen(r#""indices":1"#, r#""indices":-1"#, 1));
        assert!(s.starts_with("invalid type: integer `-1`, expected index into child of root"), "{s}");
        let s = syntax(|t| t.replacen(r#""componentType":5125"#, r#""componentType":"u32""#, 1));
        assert!(
            s.starts_with(r#"invalid type: string "u32", expected any of: [5120, 5121, 5122, 5123, 5125, 5126]"#),
            "{s}"
        );
        let s = syntax(|t| t.replacen(r#""type":"VEC3""#, r#""type":3"#, 1));
        assert!(s.starts_with(r#"invalid type: integer `3`, expected any of: ["SCALAR", "VEC2""#), "{s}");
        let s = syntax(|t| t.replacen(r#""indices":1"#, r#""indices":1,"mode":4.0"#, 1));
        assert!(s.starts_with("invalid type: floating point `4.0`, expected any of: [0, 1, 2, 3, 4, 5, 6]"), "{s}");
        let s = syntax(|t| t.replacen(r#""translation":[1,2,3]"#, r#""translation":[1,2]"#, 1));
        assert!(s.starts_with("invalid length 2, expected an array of length 3"), "{s}");
    }
}
