//! Errors of the mesh family: loading, generating and calibrating meshes.

use std::path::PathBuf;

/// What can go wrong with a mesh before a node runs.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum MeshError {
    /// The OBJ file could not be read.
    #[error("{path}: cannot read: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        message: String,
    },
    /// A line of the OBJ file is malformed.
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
