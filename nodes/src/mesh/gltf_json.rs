//! The glTF 2.0 JSON as serde reads it: the fields the mesh loader uses,
//! as the file spells them (unknown fields, `extras` and `extensions` are
//! skipped). Nothing is checked here but the JSON types; indices, enum
//! codes and sizes are checked by [`super::gltf_doc`], which turns these
//! into its document.
//!
//! The enum codes and indices are read with the "expected …" texts that
//! the `gltf` crate (which this replaces) gave, so that a wrong JSON type
//! is reported in the same words.

use serde::de::{self, Deserializer, IgnoredAny, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;

/// The root object of a glTF document.
#[derive(Deserialize)]
pub(super) struct Root {
    /// `accessors`.
    #[serde(default)]
    pub accessors: Vec<Accessor>,
    /// `asset` (required).
    pub asset: Asset,
    /// `buffers`.
    #[serde(default)]
    pub buffers: Vec<Buffer>,
    /// `bufferViews`.
    #[serde(default, rename = "bufferViews")]
    pub buffer_views: Vec<View>,
    /// `scene`: the default scene.
    pub scene: Option<Index>,
    /// `extensionsRequired`.
    #[serde(default, rename = "extensionsRequired")]
    pub extensions_required: Vec<String>,
    /// `meshes`.
    #[serde(default)]
    pub meshes: Vec<Mesh>,
    /// `nodes`.
    #[serde(default)]
    pub nodes: Vec<Node>,
    /// `scenes`.
    #[serde(default)]
    pub scenes: Vec<Scene>,
}

/// `asset`.
#[derive(Deserialize)]
pub(super) struct Asset {
    /// `version` (required), e.g. "2.0".
    pub version: String,
}

/// `scenes[i]`.
#[derive(Deserialize)]
pub(super) struct Scene {
    /// `nodes`: the root nodes.
    #[serde(default)]
    pub nodes: Vec<Index>,
}

/// `nodes[i]`.
#[derive(Deserialize)]
pub(super) struct Node {
    /// `children`.
    pub children: Option<Vec<Index>>,
    /// `matrix`: column-major 4×4.
    pub matrix: Option<[f32; 16]>,
    /// `mesh`.
    pub mesh: Option<Index>,
    /// `rotation`: unit quaternion x, y, z, w.
    pub rotation: Option<[f32; 4]>,
    /// `scale`.
    pub scale: Option<[f32; 3]>,
    /// `translation`.
    pub translation: Option<[f32; 3]>,
}

/// `meshes[i]`.
#[derive(Deserialize)]
pub(super) struct Mesh {
    /// `primitives` (required).
    pub primitives: Vec<Primitive>,
}

/// `meshes[i].primitives[j]`.
#[derive(Deserialize)]
pub(super) struct Primitive {
    /// `attributes` (required): semantic name → accessor.
    pub attributes: BTreeMap<String, Index>,
    /// `indices`.
    pub indices: Option<Index>,
    /// `mode`, a GL code (4, triangles, when absent).
    #[serde(default = "triangles", deserialize_with = "mode")]
    pub mode: u64,
}

/// `buffers[i]`.
#[derive(Deserialize)]
pub(super) struct Buffer {
    /// `uri`: a data URI or a relative path; absent in a GLB for the BIN chunk.
    pub uri: Option<String>,
    /// `byteLength` (0 when absent, as the `gltf` crate took it).
    #[serde(default, rename = "byteLength")]
    pub byte_length: u64,
}

/// `bufferViews[i]`.
#[derive(Deserialize)]
pub(super) struct View {
    /// `buffer` (required).
    pub buffer: Index,
    /// `byteLength` (required).
    #[serde(rename = "byteLength")]
    pub byte_length: u64,
    /// `byteOffset`.
    #[serde(rename = "byteOffset")]
    pub byte_offset: Option<u64>,
    /// `byteStride`.
    #[serde(rename = "byteStride")]
    pub byte_stride: Option<usize>,
}

/// `accessors[i]`.
#[derive(Deserialize)]
pub(super) struct Accessor {
    /// `bufferView`.
    #[serde(rename = "bufferView")]
    pub buffer_view: Option<Index>,
    /// `byteOffset`.
    #[serde(rename = "byteOffset")]
    pub byte_offset: Option<u64>,
    /// `count` (required).
    pub count: u64,
    /// `componentType` (required), a GL code.
    #[serde(rename = "componentType", deserialize_with = "component_type")]
    pub component_type: u64,
    /// `type` (required): SCALAR, VEC3…
    #[serde(rename = "type", deserialize_with = "accessor_type")]
    pub type_: String,
    /// `normalized`.
    #[serde(default)]
    pub normalized: bool,
    /// `sparse`: only whether it is there (sparse accessors are refused).
    pub sparse: Option<IgnoredAny>,
}

/// An index into one of the root's arrays, as written (checked later).
#[derive(Clone, Copy)]
pub(super) struct Index(pub u64);

impl<'de> Deserialize<'de> for Index {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_u64(Unsigned("index into child of root")).map(Index)
    }
}

/// The default primitive mode: triangles.
fn triangles() -> u64 {
    4
}

/// A primitive mode code.
fn mode<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    d.deserialize_u64(Unsigned("any of: [0, 1, 2, 3, 4, 5, 6]"))
}

/// An accessor component type code.
fn component_type<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    d.deserialize_u64(Unsigned("any of: [5120, 5121, 5122, 5123, 5125, 5126]"))
}

/// An accessor type name.
fn accessor_type<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    d.deserialize_str(Text(r#"any of: ["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"]"#))
}

/// A visitor of a non-negative integer, expecting what it names.
struct Unsigned(&'static str);

impl Visitor<'_> for Unsigned {
    type Value = u64;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.0)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<u64, E> {
        Ok(v)
    }
}

/// A visitor of a string, expecting what it names.
struct Text(&'static str);

impl Visitor<'_> for Text {
    type Value = String;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.0)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<String, E> {
        Ok(v.to_owned())
    }
}
