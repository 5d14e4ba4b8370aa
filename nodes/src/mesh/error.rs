//! Errors of the mesh family: loading, generating and calibrating meshes.

use std::path::PathBuf;

/// What can go wrong with a mesh before a node runs.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum MeshError {
    /// The mesh file could not be read.
    #[error("{path}: cannot read: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        message: String,
    },
    /// A line of a text mesh file (OBJ, ASCII STL, a PLY header or ASCII
    /// body, glTF JSON) is malformed.
    #[error("{path}:{line}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The 1-based line number.
        line: usize,
        /// What is wrong on that line.
        message: String,
    },
    /// tobj refused the file for a reason the line check did not catch.
    #[error("{path}: {message}")]
    Obj {
        /// The file.
        path: PathBuf,
        /// tobj's message.
        message: String,
    },
    /// The mesh has nothing a ray can hit.
    #[error("{what}: the mesh has no triangles")]
    Empty {
        /// The file or scene.
        what: String,
    },
    /// Every triangle of the mesh has zero area (collapsed by the weld or
    /// with collinear corners): nothing a ray can hit.
    #[error("{what}: all {triangles} triangles have zero area (degenerate); nothing to touch")]
    Degenerate {
        /// The file or scene.
        what: String,
        /// How many triangles were read.
        triangles: usize,
    },
    /// A binary file (STL, binary PLY, GLB or a glTF buffer) ends before
    /// the data its header announces.
    #[error("{path}: byte {offset}: the file ends inside {what} ({available} bytes left)")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Byte offset where the incomplete item starts.
        offset: u64,
        /// The item cut short.
        what: String,
        /// Bytes left in the file from `offset`.
        available: u64,
    },
    /// A binary file does not start with its format's magic bytes.
    #[error("{path}: byte 0: {format} files start with {expected:?}, this one with {found:?}")]
    Magic {
        /// The file.
        path: PathBuf,
        /// The format the file's extension names.
        format: &'static str,
        /// The magic the format requires.
        expected: String,
        /// The bytes found (lossily as text).
        found: String,
    },
    /// A value in a binary file is wrong (a non-finite coordinate, a
    /// vertex index out of range, an inconsistent length).
    #[error("{path}: byte {offset}: {message}")]
    Binary {
        /// The file.
        path: PathBuf,
        /// Byte offset of the value.
        offset: u64,
        /// What is wrong there.
        message: String,
    },
    /// A PLY header is malformed or lacks what a mesh needs (line named).
    #[error("{path}:{line}: PLY header: {message}")]
    PlyHeader {
        /// The file.
        path: PathBuf,
        /// The 1-based line of the header.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A glTF document is valid JSON but not a mesh this loader can read:
    /// a glTF validation error (with its JSON path), an unsupported
    /// required extension, a sparse or non-float position accessor.
    #[error("{path}: glTF: {message}")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the JSON path of the object.
        message: String,
    },
    /// The file's extension names no mesh format this build reads.
    #[error("{path}: unknown mesh format (extension .obj, .stl, .ply, .gltf or .glb)")]
    Format {
        /// The file.
        path: PathBuf,
    },
    /// A generated scene's parameters are out of range.
    #[error("scene: {0}")]
    Scene(String),
    /// The calibration cache could not be written.
    #[error("{path}: cannot write the calibration cache: {message}")]
    Cache {
        /// The cache file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}
