//! The merge of a study report's shards (`evflow report textures|live|narx
//! --shard K/N`), one for every sharded study: each shard saved its slice
//! in a record ([`evflow_study::shard_file::StudyRecord`]); the merge
//! checks that the shards are the N slices of one report, copies the files
//! they wrote, and hands the records, in K order, to the report's
//! [`StudyReport::tables`], which writes what one run would have written
//! with the code the report uses.
//!
//! A sharded report is its study's record and a [`StudyReport`] of a few
//! lines ([`super::textures`], [`super::live`], [`super::narx`]), listed
//! in [`super::STUDIES`]; finding the missing shards ([`super::gaps`]) and
//! printing the merge (`evflow merge`) come with it.

use super::error::MergeError;
use super::files::{copy_files, one_batch, Coverage};
use evflow_engine::batch::{Failures, Shard};
use evflow_study::shard_file::StudyRecord;
use evflow_study::StudyError;
use std::path::{Path, PathBuf};

/// A shard in K order: its folder, its K/N, its record.
pub type Slice<R> = (PathBuf, Shard, R);

/// A study report that runs in shards: its record, and how the merged
/// tables are written from the records.
pub trait StudyReport: Sync {
    /// What each shard saved.
    type Record: StudyRecord;
    /// The Slurm array script that runs the report's shards, as far as it is known.
    const SCRIPT: &'static str;
    /// Files in a shard's folder that the merge writes itself, not copied.
    const TABLES: &'static [&'static str] = &[];

    /// What differs between the first shard's record and another's, when
    /// they are not one report's (named in the refusal).
    fn differs(first: &Self::Record, other: &Self::Record) -> Option<&'static str>;

    /// Writes the report's tables into `out` (whose canonical path is
    /// `base`) from the shards' records in K order; `files` were copied
    /// from the shards' folders.
    fn tables(out: &Path, base: &Path, shards: &[Slice<Self::Record>], files: usize) -> Result<StudyMerge, MergeError>;
}

/// What a merge of a study report's shards did, as `evflow merge` prints
/// it. Steps that failed in the shards are in `failures`; the merge still
/// wrote the tables of everything that ran.
#[derive(Debug)]
pub struct StudyMerge {
    /// Shards merged.
    pub shards: usize,
    /// The report's Markdown, as the report prints it (empty when it prints none).
    pub markdown: String,
    /// What was written, one line each (`wrote PATH`).
    pub written: Vec<String>,
    /// What could not be drawn, one line each (a warning, not a failed merge).
    pub warnings: Vec<String>,
    /// The closing line: shards, rows and files.
    pub summary: String,
    /// Steps of the whole report, the failures' denominator.
    pub steps: usize,
    /// The steps that failed in the shards, labelled with their shard.
    pub failures: Failures,
}

/// Merges the shards of `S`'s report in `dirs` (in any order) into `out`.
pub fn merge_study<S: StudyReport>(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<StudyMerge, MergeError> {
    type R<S> = <S as StudyReport>::Record;
    // A folder of another kind of shard among them: named, not "cannot read".
    let ours = |d: &&PathBuf| R::<S>::is_in(d);
    if let (Some(first), Some(other)) = (dirs.iter().find(ours), dirs.iter().find(|d| !ours(d))) {
        return Err(MergeError::NotOfReport {
            dir: other.clone(),
            first: first.clone(),
            command: R::<S>::COMMAND,
            record: R::<S>::RECORD,
        });
    }
    let shards = one_batch(dirs, read_slice::<R<S>>, S::differs, coverage)?;
    let folders: Vec<&Path> = shards.iter().map(|(d, _, _)| d.as_path()).collect();
    let skip: Vec<PathBuf> =
        std::iter::once(R::<S>::RECORD).chain(S::TABLES.iter().copied()).map(PathBuf::from).collect();
    let files = copy_files(out, &folders, &skip)?;
    std::fs::create_dir_all(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    let base = std::fs::canonicalize(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    S::tables(out, &base, &shards, files)
}

/// The record of a study shard in `dir`, checked, and its K/N.
fn read_slice<R: StudyRecord>(dir: &Path) -> Result<(Shard, R), MergeError> {
    let record = R::read(dir)?;
    let shard = record.slice().map_err(|e| StudyError::Config(format!("{}: {e}", dir.display())))?;
    Ok((shard, record))
}

/// A sharded study report seen through one interface, whatever its record
/// (what [`super::gaps`] and [`super::merge`] need of it).
pub trait StudyKind: Sync {
    /// The record's file name.
    fn record(&self) -> &'static str;
    /// The command that writes such shards, as a person types it.
    fn command(&self) -> &'static str;
    /// The array's script, as far as it is known.
    fn script(&self) -> &'static str;
    /// Whether `dir` holds such a record.
    fn holds(&self, dir: &Path) -> bool;
    /// The K/N of the shard in `dir`, read from its record.
    fn slice(&self, dir: &Path) -> Result<Shard, MergeError>;
    /// Merges the shards in `dirs` into `out` ([`merge_study`]).
    fn merge(&self, out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<StudyMerge, MergeError>;
}

impl<S: StudyReport> StudyKind for S {
    fn record(&self) -> &'static str {
        S::Record::RECORD
    }

    fn command(&self) -> &'static str {
        S::Record::COMMAND
    }

    fn script(&self) -> &'static str {
        S::SCRIPT
    }

    fn holds(&self, dir: &Path) -> bool {
        S::Record::is_in(dir)
    }

    fn slice(&self, dir: &Path) -> Result<Shard, MergeError> {
        read_slice::<S::Record>(dir).map(|(shard, _)| shard)
    }

    fn merge(&self, out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<StudyMerge, MergeError> {
        merge_study::<S>(out, dirs, coverage)
    }
}
