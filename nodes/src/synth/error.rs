//! Errors of the synthesis family: forward-model files, identification
//! data, synthesis targets.

use crate::model_file_error::{ModelFileError, ModelFileErrors, ModelFormat};

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

impl ModelFileErrors for SynthError {
    const FORMAT: ModelFormat = MODEL_FORMAT;
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
    use std::path::Path;

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
