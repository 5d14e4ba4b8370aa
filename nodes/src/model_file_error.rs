//! Errors of the model files the families write and read (`narx`'s NARX
//! models, `synth`'s forward models): what can be wrong with such a file,
//! and how it reaches a node's error, defined once; each format gives its
//! name and its advice for a file of another version as data
//! ([`ModelFormat`]), and its family's error wraps a [`ModelFileError`].

use std::path::{Path, PathBuf};

/// A model-file format, as its errors name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelFormat {
    /// What a file of the format is, in "not a … file" (e.g. `NARX model`).
    pub file: &'static str,
    /// The format's name, in "… format version" (e.g. `model`).
    pub name: &'static str,
    /// What to do with a model of another version, in "… the model or
    /// update evflow" (e.g. `retrain`).
    pub redo: &'static str,
}

/// Everything that can be wrong reading or writing a model file.
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// A file that cannot be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// A file that is not valid JSON or not a model of its format.
    #[error("{path}: not a {} file: {message}", .format.file)]
    Parse {
        /// The format the file should be in.
        format: ModelFormat,
        /// The file.
        path: PathBuf,
        /// What the parser said (with line and column).
        message: String,
    },
    /// A file written by a newer or unknown version of the format.
    #[error(
        "{path}: {} format version {found} is not supported (this evflow reads version {supported}); {} the model or update evflow",
        .format.name,
        .format.redo
    )]
    Version {
        /// The format the file is in.
        format: ModelFormat,
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
}

impl ModelFileError {
    /// A field error for `path`.
    pub fn field(path: &Path, field: &str, message: impl Into<String>) -> Self {
        ModelFileError::Field { path: path.to_path_buf(), field: field.to_string(), message: message.into() }
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ModelFileError::Io { path, .. }
            | ModelFileError::Parse { path, .. }
            | ModelFileError::Version { path, .. }
            | ModelFileError::Field { path, .. } => path,
        }
    }
}

impl From<ModelFileError> for evflow_engine::NodeError {
    /// A file error naming the file; its message without the leading
    /// `path: ` (the node error adds the path itself).
    fn from(e: ModelFileError) -> Self {
        let path = e.path().to_path_buf();
        let text = e.to_string();
        let message = text.strip_prefix(&format!("{}: ", path.display())).unwrap_or(&text).to_string();
        evflow_engine::NodeError::File { path, message }
    }
}

/// A family error that wraps [`ModelFileError`] for its format: the
/// constructors every model-file format's errors need, written once.
pub trait ModelFileErrors: From<ModelFileError> {
    /// The family's model-file format.
    const FORMAT: ModelFormat;

    /// A file at `path` that cannot be read or written.
    fn io(path: &Path, message: impl Into<String>) -> Self {
        ModelFileError::Io { path: path.to_path_buf(), message: message.into() }.into()
    }

    /// A file at `path` that is not valid JSON or not a model of the format.
    fn parse(path: &Path, message: impl Into<String>) -> Self {
        ModelFileError::Parse { format: Self::FORMAT, path: path.to_path_buf(), message: message.into() }.into()
    }

    /// A model at `path` of format version `found`; this code reads `supported`.
    fn version(path: &Path, found: u64, supported: u64) -> Self {
        ModelFileError::Version { format: Self::FORMAT, path: path.to_path_buf(), found, supported }.into()
    }

    /// A field of the model at `path` with a value that cannot be right.
    fn field(path: &Path, field: &str, message: impl Into<String>) -> Self {
        ModelFileError::field(path, field, message).into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FORMAT: ModelFormat = ModelFormat { file: "test model", name: "test-model", redo: "rebuild" };

    #[test]
    fn messages_name_the_file_and_the_format() {
        let path = PathBuf::from("m.json");
        let version = ModelFileError::Version { format: FORMAT, path: path.clone(), found: 9, supported: 1 };
        assert_eq!(
            version.to_string(),
            "m.json: test-model format version 9 is not supported (this evflow reads version 1); rebuild the model or update evflow"
        );
        let parse = ModelFileError::Parse { format: FORMAT, path: path.clone(), message: "EOF".into() };
        assert_eq!(parse.to_string(), "m.json: not a test model file: EOF");
        match evflow_engine::NodeError::from(ModelFileError::field(&path, "a.b", "negative")) {
            evflow_engine::NodeError::File { path: p, message } => {
                assert_eq!((p, message.as_str()), (path, "field `a.b`: negative"))
            }
            other => panic!("{other:?}"),
        }
    }
}
