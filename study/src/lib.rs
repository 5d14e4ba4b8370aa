//! The evflow studies: experiments that run graphs through the node
//! library and turn what they measure into rows, tables and shard records.
//!
//! This crate sits between the node library (`evflow-nodes`, components
//! only) and the command-line program (`evflow`, which parses, calls and
//! prints); the CLI, the tests and the benchmarks share it
//! (docs/architecture.md).
//!
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
#![deny(missing_docs)]

pub mod figure;
pub mod graphs;
pub mod precision;
pub mod stability;
pub mod tables;

#[cfg(feature = "synth")]
pub mod cells;
#[cfg(feature = "synth")]
pub mod constant_speed;
#[cfg(feature = "synth")]
pub mod crossval;
pub mod exact;
#[cfg(feature = "synth")]
pub mod floor;
#[cfg(feature = "synth")]
pub mod forces_first;
#[cfg(feature = "synth")]
pub mod from_recordings;
#[cfg(feature = "synth")]
pub mod gains;
#[cfg(feature = "synth")]
pub mod grid_plan;
#[cfg(feature = "synth")]
pub mod library;
#[cfg(feature = "synth")]
pub mod live;
#[cfg(feature = "synth")]
pub mod models;
#[cfg(feature = "synth")]
pub mod narx;
#[cfg(feature = "synth")]
pub mod recordings;
#[cfg(feature = "synth")]
pub mod row;
#[cfg(feature = "synth")]
pub mod run;
#[cfg(feature = "synth")]
pub mod saved;
#[cfg(feature = "synth")]
pub mod scope;
#[cfg(feature = "synth")]
pub mod score;
#[cfg(feature = "synth")]
pub mod setup;
#[cfg(feature = "synth")]
pub mod shard_file;
#[cfg(feature = "synth")]
pub mod spectrum;
#[cfg(feature = "synth")]
pub(crate) mod starts;
#[cfg(feature = "synth")]
pub mod summary;
#[cfg(feature = "synth")]
pub mod twin;
#[cfg(feature = "synth")]
pub mod xval;

#[cfg(feature = "synth")]
pub mod error;
#[cfg(feature = "synth")]
pub use error::StudyError;
