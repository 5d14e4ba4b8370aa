//! Errors of the NARX family: model files, training data, training.

use std::path::PathBuf;

/// Everything that can go wrong reading or writing a model, or training one.
#[derive(Debug, thiserror::Error)]
pub enum NarxError {
    /// A model file that cannot be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// A model file that is not valid JSON or not a NARX model.
    #[error("{path}: not a NARX model file: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said (with line and column).
        message: String,
    },
    /// A model file written by a newer or unknown version of the format.
    #[error("{path}: model format version {found} is not supported (this evflow reads version {supported}); retrain the model or update evflow")]
    Version {
        /// The file.
        path: PathBuf,
        /// The version in the file.
        found: u64,
        /// The version this code reads.
        supported: u64,
    },
    /// A field of a model file with a value that cannot be right.
    #[error("{path}: field `{field}`: {message}")]
    Field {
        /// The file.
        path: PathBuf,
        /// The field, as a dotted path (e.g. `normalization.x.min`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// Training data the network cannot be trained on (too short, constant, NaN).
    #[error("training data: {0}")]
    Data(String),
    /// A configuration that cannot work (e.g. no layer, no input tap).
    #[error("configuration: {0}")]
    Config(String),
}

impl NarxError {
    /// A field error for `path`.
    pub fn field(path: &std::path::Path, field: &str, message: impl Into<String>) -> Self {
        NarxError::Field { path: path.to_path_buf(), field: field.to_string(), message: message.into() }
    }
}

impl From<NarxError> for evflow_engine::NodeError {
    fn from(e: NarxError) -> Self {
        match e {
            NarxError::Io { path, message } => evflow_engine::NodeError::File { path, message },
            NarxError::Parse { ref path, .. }
            | NarxError::Version { ref path, .. }
            | NarxError::Field { ref path, .. } => {
                evflow_engine::NodeError::File { path: path.clone(), message: strip(&e.to_string(), path) }
            }
            NarxError::Data(m) => evflow_engine::NodeError::Data(format!("training data: {m}")),
            NarxError::Config(m) => evflow_engine::NodeError::Other(format!("configuration: {m}")),
        }
    }
}

/// The message without the leading `path: ` (the node error adds the path itself).
fn strip(s: &str, path: &std::path::Path) -> String {
    let prefix = format!("{}: ", path.display());
    s.strip_prefix(&prefix).unwrap_or(s).to_string()
}
