//! Errors of the synthesis family: forward-model files, identification
//! data, synthesis targets.

use crate::model_file_error::{ModelFileError, ModelFormat};
use std::path::Path;

/// The forward-model format, as its errors name it.
pub const MODEL_FORMAT: ModelFormat = ModelFormat { file: "forward-model", name: "forward-model", redo: "re-identify" };

/// Everything that can go wrong identifying a forward model, reading or
/// writing its file, or synthesizing an actuation through it.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// A model file that cannot be read, written or used.
    #[error(transparent)]
    File(#[from] ModelFileError),
    /// Identification or synthesis data that cannot be used (too short,
    /// constant, non-finite).
    #[error("data: {0}")]
    Data(String),
    /// A configuration that cannot work (e.g. a memory of 0 samples).
    #[error("configuration: {0}")]
    Config(String),
}

impl SynthError {
    /// A file at `path` that cannot be read or written.
    pub fn io(path: &Path, message: impl Into<String>) -> Self {
        ModelFileError::Io { path: path.to_path_buf(), message: message.into() }.into()
    }

    /// A file at `path` that is not valid JSON or not a forward model.
    pub fn parse(path: &Path, message: impl Into<String>) -> Self {
        ModelFileError::Parse { format: MODEL_FORMAT, path: path.to_path_buf(), message: message.into() }.into()
    }

    /// A model at `path` of format version `found`; this code reads `supported`.
    pub fn version(path: &Path, found: u64, supported: u64) -> Self {
        ModelFileError::Version { format: MODEL_FORMAT, path: path.to_path_buf(), found, supported }.into()
    }

    /// A field error for `path`.
    pub fn field(path: &Path, field: &str, message: impl Into<String>) -> Self {
        ModelFileError::field(path, field, message).into()
    }
}

impl From<SynthError> for evflow_engine::NodeError {
    fn from(e: SynthError) -> Self {
        match e {
            SynthError::File(e) => e.into(),
            SynthError::Data(m) => evflow_engine::NodeError::Data(m),
            SynthError::Config(m) => evflow_engine::NodeError::Other(format!("configuration: {m}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_file_messages_name_the_forward_model_format() {
        let p = Path::new("f.json");
        assert_eq!(
            SynthError::version(p, 3, 1).to_string(),
            "f.json: forward-model format version 3 is not supported (this evflow reads version 1); re-identify the model or update evflow"
        );
        assert_eq!(SynthError::parse(p, "EOF").to_string(), "f.json: not a forward-model file: EOF");
        let e: evflow_engine::NodeError = SynthError::version(p, 3, 1).into();
        assert!(
            matches!(e, evflow_engine::NodeError::File { message, .. } if message.starts_with("forward-model format version 3"))
        );
        let e: evflow_engine::NodeError = SynthError::Data("constant".into()).into();
        assert!(matches!(e, evflow_engine::NodeError::Data(m) if m == "constant"));
    }
}
