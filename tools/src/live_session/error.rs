//! Why a live session could not be set up, run to its end, recorded or
//! read back. Each error names the file, folder, option or thread it is
//! about; `{:#}` prints its cause after it (as `evflow` does).

use std::path::PathBuf;

/// What went wrong with a live session.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// A file or folder of the session could not be read, written or created.
    #[error("{}: {what}", path.display())]
    File {
        /// The file or folder.
        path: PathBuf,
        /// What could not be done (`cannot read`, …).
        what: &'static str,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A JSON file of the session could not be read or written as JSON.
    #[error("{}: {what}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// What is wrong (`not valid JSON`, …).
        what: &'static str,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// A recorded session's files do not hold what a session writes (the
    /// message names the file, and the line where there is one).
    #[error("{0}")]
    Recording(String),
    /// The graph, an option or the live plan refuses the session (the
    /// message names which).
    #[error("{0}")]
    Setup(String),
    /// The studio could not serve the session.
    #[cfg(feature = "studio")]
    #[error(transparent)]
    Studio(#[from] crate::studio::StudioError),
    /// A thread of the session could not start, or ended in a panic.
    #[error("{0}")]
    Thread(String),
    /// The session ended in a node's failure or a fault, or its nodes could
    /// not finish.
    #[error("{0}")]
    Run(String),
}

impl SessionError {
    /// A file error: `what` could not be done to `path`.
    pub fn file(path: impl Into<PathBuf>, what: &'static str) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| SessionError::File { path, what, source }
    }

    /// A JSON error of `path`.
    pub fn json(path: impl Into<PathBuf>, what: &'static str) -> impl FnOnce(serde_json::Error) -> Self {
        let path = path.into();
        move |source| SessionError::Json { path, what, source }
    }

    /// A thread that could not start.
    pub fn spawn(e: std::io::Error) -> Self {
        SessionError::Thread(e.to_string())
    }
}
