//! Errors of the NARX family: model files, training data, training.

use crate::model_file_error::{ModelFileError, ModelFileErrors, ModelFormat};

/// The NARX model format, as its errors name it.
pub const MODEL_FORMAT: ModelFormat = ModelFormat { file: "NARX model", name: "model", redo: "retrain" };

/// Everything that can go wrong reading or writing a model, or training one.
#[derive(Debug, thiserror::Error)]
pub enum NarxError {
    /// A model file that cannot be read, written or used.
    #[error(transparent)]
    File(#[from] ModelFileError),
    /// Training data the network cannot be trained on (too short, constant, NaN).
    #[error("training data: {0}")]
    Data(String),
    /// A configuration that cannot work (e.g. no layer, no input tap).
    #[error("configuration: {0}")]
    Config(String),
}

impl ModelFileErrors for NarxError {
    const FORMAT: ModelFormat = MODEL_FORMAT;
}

impl From<NarxError> for evflow_engine::NodeError {
    fn from(e: NarxError) -> Self {
        match e {
            NarxError::File(e) => e.into(),
            NarxError::Data(m) => evflow_engine::NodeError::Data(format!("training data: {m}")),
            NarxError::Config(m) => evflow_engine::NodeError::Other(format!("configuration: {m}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn model_file_messages_name_the_narx_format() {
        let p = Path::new("m.json");
        assert_eq!(
            NarxError::version(p, 3, 1).to_string(),
            "m.json: model format version 3 is not supported (this evflow reads version 1); retrain the model or update evflow"
        );
        assert_eq!(NarxError::parse(p, "EOF").to_string(), "m.json: not a NARX model file: EOF");
        assert_eq!(NarxError::io(p, "denied").to_string(), "m.json: denied");
        assert_eq!(
            NarxError::field(p, "delays.input", "negative").to_string(),
            "m.json: field `delays.input`: negative"
        );
        let e: evflow_engine::NodeError = NarxError::Data("constant".into()).into();
        assert!(matches!(e, evflow_engine::NodeError::Data(m) if m == "training data: constant"));
    }
}
