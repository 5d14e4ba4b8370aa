//! Errors of the synthesis family: forward-model files, identification
//! data, synthesis targets.

use std::path::PathBuf;

/// Everything that can go wrong identifying a forward model, reading or
/// writing its file, or synthesizing an actuation through it.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// A file that cannot be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// A model file that is not valid JSON or not a forward model.
    #[error("{path}: not a forward-model file: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said (with line and column).
        message: String,
    },
    /// A model file written by a newer or unknown version of the format.
    #[error("{path}: forward-model format version {found} is not supported (this evflow reads version {supported}); re-identify the model or update evflow")]
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
        /// The field, as a dotted path (e.g. `kernel.linear`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// Identification or synthesis data that cannot be used (too short,
    /// constant, non-finite).
    #[error("data: {0}")]
    Data(String),
    /// A configuration that cannot work (e.g. a memory of 0 samples).
    #[error("configuration: {0}")]
    Config(String),
}

impl SynthError {
    /// A field error for `path`.
    pub fn field(path: &std::path::Path, field: &str, message: impl Into<String>) -> Self {
        SynthError::Field { path: path.to_path_buf(), field: field.to_string(), message: message.into() }
    }
}

impl From<SynthError> for evflow_engine::NodeError {
    fn from(e: SynthError) -> Self {
        match e {
            SynthError::Io { path, message } => evflow_engine::NodeError::File { path, message },
            SynthError::Parse { ref path, .. }
            | SynthError::Version { ref path, .. }
            | SynthError::Field { ref path, .. } => {
                let prefix = format!("{}: ", path.display());
                let text = e.to_string();
                let message = text.strip_prefix(&prefix).unwrap_or(&text).to_string();
                evflow_engine::NodeError::File { path: path.clone(), message }
            }
            SynthError::Data(m) => evflow_engine::NodeError::Data(m),
            SynthError::Config(m) => evflow_engine::NodeError::Other(format!("configuration: {m}")),
        }
    }
}
