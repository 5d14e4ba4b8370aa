//! The texture-rendering study (dissertation chapter 5, and beyond it): per
//! lab profile, texture and condition, every synthesis method — the inverse
//! NARX model on binary and on multilevel excitation, the optimized
//! synthesis through a forward model, record-and-playback normalized per
//! recording — played on the display and scored the same way: the same
//! gain sweep and rules ([`gains`]), E_s in two readings, beside the repeat
//! baseline, the display floor and the achievable floor ([`floor`]).
//!
//! One module computes every row; `evflow report textures`, `evflow report
//! narx`, the interpolation cross-validation (`evflow report interp
//! --cells …`: [`xval`], [`forces_first`]) and the tests call it. The
//! cells of the live texture grids are cut from its runs ([`cells`]).

pub mod cells;
pub mod constant_speed;
pub mod crossval;
pub mod exact;
pub mod floor;
pub mod forces_first;
pub mod gains;
pub mod graphs;
pub mod grid_plan;
pub mod library;
pub mod live;
pub mod models;
pub mod narx_settings;
pub mod recordings;
pub mod row;
pub mod run;
pub mod saved;
pub mod setup;
pub mod shard_file;
pub mod spectrum;
pub mod summary;
pub mod twin;
pub mod xval;

use std::path::PathBuf;

/// Why a study could not run.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A graph that could not be loaded or run.
    #[error("{file}: {message}")]
    Graph {
        /// The graph file.
        file: PathBuf,
        /// What went wrong.
        message: String,
    },
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
    Narx(#[from] crate::narx::error::NarxError),
    /// A synthesis step failed.
    #[error(transparent)]
    Synth(#[from] super::error::SynthError),
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
