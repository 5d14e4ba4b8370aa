//! Joins the outputs of the shards of a sweep (`evflow run --shard K/N`)
//! into what one run would have written (`evflow merge`).
//!
//! The merge reads each shard's record ([`super::shard_record`]), checks
//! that the shards are one sweep's (same graph, same count, every K of N
//! once), copies the files the graphs wrote, and writes the CSV and JSON
//! tables with the same code as `evflow run` ([`super::tables`]), from the
//! runs in sweep order. With `--no-times` on the shards the tables are byte
//! for byte those of one run; with times, only the measured times differ.
//!
//! Folders of a model library built in shards (`evflow library build
//! --shard K/N`) merge the same way: their files copied, their indexes
//! joined in the library's order.
//!
//! A study report run in shards (`evflow report textures|live|narx --shard
//! K/N`) merges into its tables through one merge ([`study`]); each report
//! is its few lines ([`textures`], [`live`], [`narx`]) listed in
//! [`STUDIES`].
//!
//! A shard writes its record last; a folder without one is a task that did
//! not end ([`gaps`]). A merge refuses missing shards, naming each and
//! printing the commands that rerun them ([`rerun`]), unless asked to merge
//! the shards there are ([`Coverage::Partial`]): its output then holds
//! [`gaps::PARTIAL_NOTE`], which says what is missing.
//!
//! One file per kind of shard; [`error`], [`files`] and [`study`] are what
//! they share.

pub mod error;
pub mod files;
pub mod gaps;
#[cfg(feature = "synth")]
pub mod library;
#[cfg(feature = "synth")]
pub mod live;
#[cfg(feature = "synth")]
pub mod narx;
pub mod rerun;
#[cfg(feature = "synth")]
pub mod study;
pub mod sweep;
#[cfg(feature = "synth")]
pub mod textures;

pub use error::MergeError;
pub use files::Coverage;
pub use gaps::{Gaps, PARTIAL_NOTE};
#[cfg(feature = "synth")]
pub use library::{merge_library, LibraryMerge};
#[cfg(feature = "synth")]
pub use study::{StudyKind, StudyMerge};
pub use sweep::{merge_sweep, SweepMerge};

/// Every study report that runs in shards, in the order a folder's record
/// is looked for.
#[cfg(feature = "synth")]
pub static STUDIES: &[&dyn StudyKind] = &[&textures::Textures, &live::Live, &narx::Narx];

use std::path::{Path, PathBuf};

/// What a merge did: of a sweep or of a model library.
#[derive(Debug)]
pub enum Merged {
    /// The shards of `evflow run --shard`.
    Sweep(SweepMerge),
    /// The shards of `evflow library build --shard`.
    #[cfg(feature = "synth")]
    Library(LibraryMerge),
    /// The shards of a study report (`evflow report textures|live|narx --shard`).
    #[cfg(feature = "synth")]
    Study(StudyMerge),
}

/// What `evflow merge` did, and what it left out.
#[derive(Debug)]
pub struct Outcome {
    /// The merge of the shards there were.
    pub merged: Merged,
    /// With [`Coverage::Partial`], the shards that were missing (and the
    /// folders without a record), when there were any: the output is
    /// partial and its [`PARTIAL_NOTE`] says so.
    pub partial: Option<Gaps>,
}

/// Merges the shard folders `dirs` (in any order) into `out`. Folders
/// without a shard's record ([`gaps::survey`]) are not read: with
/// [`Coverage::All`] they, and any K of N no folder holds, refuse the
/// merge ([`MergeError::Incomplete`]); with [`Coverage::Partial`] the
/// shards there are merge, and `out` gets [`PARTIAL_NOTE`]. A complete
/// merge removes a note left by an earlier partial one.
pub fn merge(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<Outcome, MergeError> {
    let (done, gaps) = gaps::survey(dirs)?;
    if !gaps.is_empty() && coverage == Coverage::All {
        let missing = gaps.missing.iter().map(|g| g.k).collect();
        return Err(MergeError::Incomplete { missing, n: gaps.n, refusal: gaps.refusal() });
    }
    let merged = merge_shards(out, &done, coverage)?;
    let note = out.join(PARTIAL_NOTE);
    if gaps.is_empty() {
        match std::fs::remove_file(&note) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(MergeError::Write { path: note, source: e });
            }
            _ => {}
        }
        return Ok(Outcome { merged, partial: None });
    }
    files::write(&note, &format!("partial merge: {}\n{}", gaps.summary(), gaps.details()))?;
    Ok(Outcome { merged, partial: Some(gaps) })
}

/// Merges the folders `dirs`, each holding a shard's record, into `out`:
/// a study report's when a folder holds one of [`STUDIES`]' records, a model
/// library's when every folder is one (and none holds a sweep's shard
/// record), else a sweep's.
fn merge_shards(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<Merged, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    #[cfg(feature = "synth")]
    for kind in STUDIES {
        if dirs.iter().any(|d| kind.holds(d)) {
            return kind.merge(out, dirs, coverage).map(Merged::Study);
        }
    }
    #[cfg(feature = "synth")]
    if dirs.iter().all(|d| !d.join(super::shard_record::RECORD).exists() && evflow_study::library::is_library(d)) {
        return merge_library(out, dirs, coverage).map(Merged::Library);
    }
    merge_sweep(out, dirs, coverage).map(Merged::Sweep)
}
