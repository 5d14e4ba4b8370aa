//! Why a study could not run: one error type for every study step.

use std::path::PathBuf;

/// Why a study could not run.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A graph that could not be loaded or run.
    #[error(transparent)]
    Graph(#[from] crate::graphs::GraphError),
    /// A file or folder that cannot be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// A file a step should have written and did not.
    #[error("{0}: missing (run from the repository root, or is --graphs right?)")]
    Missing(PathBuf),
    /// A recording that cannot be used.
    #[error("recording: {0}")]
    Recording(String),
    /// Settings that cannot work.
    #[error("{0}")]
    Config(String),
    /// A NARX model that cannot be read.
    #[error(transparent)]
    Narx(#[from] evflow_nodes::narx::error::NarxError),
    /// A synthesis step failed.
    #[error(transparent)]
    Synth(#[from] evflow_nodes::synth::error::SynthError),
    /// An error in one step, with the step named.
    #[error("{what}: {error}")]
    At {
        /// The step (e.g. "felt-fabric at 85 g, 5 cm/s, improved scheme").
        what: String,
        /// What went wrong there.
        error: Box<StudyError>,
    },
}

impl StudyError {
    /// This error, in the step `what`.
    pub fn at(self, what: String) -> Self {
        StudyError::At { what, error: Box::new(self) }
    }
}

/// An [`StudyError::Io`] about the file or folder `path`.
pub(crate) fn io(path: &std::path::Path, message: impl std::fmt::Display) -> StudyError {
    StudyError::Io { path: path.to_path_buf(), message: message.to_string() }
}
