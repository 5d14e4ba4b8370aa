//! A study shard's record as a file: written as JSON through a temporary
//! file (whole or absent), read back with the file named in every error,
//! and its slice checked against the range it says it holds. Every sharded
//! study's record is a [`StudyRecord`]: the texture study's
//! ([`super::saved`]), the live study's ([`super::live::saved`]) and
//! `report narx`'s ([`super::narx::saved`]); `evflow merge` reads them
//! through it.

use super::StudyError;
use evflow_engine::batch::{Shard, ShardError};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A step of a shard that failed, as its record saves it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedFailure {
    /// The step.
    pub step: String,
    /// Why.
    pub reason: String,
}

/// The failures of a shard's steps as one run lists them, each step
/// labelled with the shard (`K/N`) it failed in.
pub fn failures_of<'a>(shard: &str, failures: &'a [SavedFailure]) -> impl Iterator<Item = (String, String)> + 'a {
    let shard = shard.to_string();
    failures.iter().map(move |f| (format!("{} (shard {shard})", f.step), f.reason.clone()))
}

/// A saved folder: as saved when absolute, else taken from `base` (the
/// shard's output folder the record was read from).
pub fn under(base: &Path, dir: &Path) -> PathBuf {
    if dir.is_absolute() {
        dir.to_path_buf()
    } else {
        base.join(dir)
    }
}

/// Writes `value` to `dir/name` as JSON, through `dir/name.tmp`
/// (`evflow_engine::atomic_file`).
pub fn write<T: Serialize>(dir: &Path, name: &str, value: &T) -> Result<(), StudyError> {
    let path = dir.join(name);
    let io = |e: std::io::Error| StudyError::Io { path: path.clone(), message: e.to_string() };
    let text = serde_json::to_string_pretty(value).map_err(|e| io(e.into()))?;
    evflow_engine::atomic_file::write_atomically(&path, text).map_err(io)
}

/// Reads `dir/name`: `command` is what writes it (named when the file is
/// missing), `what` what it should be (named when it is not that).
pub fn read<T: DeserializeOwned>(dir: &Path, name: &str, command: &str, what: &str) -> Result<T, StudyError> {
    let path = dir.join(name);
    let text = evflow_engine::files::read_regular_to_string(&path).map_err(|e| StudyError::Io {
        path: path.clone(),
        message: format!("{e} (is it the --out of `{command}`?)"),
    })?;
    serde_json::from_str(&text).map_err(|e| StudyError::Io { path, message: format!("not {what}: {e}") })
}

/// The slice `shard` (`K/N`) of a record in `dir/name` over `total`
/// `unit`s, checked to hold exactly `range`.
pub fn slice(
    dir: &Path,
    name: &str,
    shard: &str,
    total: usize,
    range: [usize; 2],
    unit: &str,
) -> Result<Shard, StudyError> {
    let bad = |m: String| StudyError::Io { path: dir.join(name), message: m };
    let s = Shard::parse(shard).map_err(|e| bad(e.to_string()))?;
    let expected = s.range(total);
    if range != [expected.start, expected.end] {
        return Err(bad(format!("shard {s} of {total} {unit} should hold {unit} {expected:?}, not {range:?}")));
    }
    Ok(s)
}

/// The record a shard of a study (`evflow report … --shard K/N`) writes
/// last into its output folder: which slice of the study's units it ran,
/// and what it found. One implementation per sharded study; writing,
/// reading (checked against its slice) and finding it are shared.
pub trait StudyRecord: Serialize + DeserializeOwned + Sized {
    /// The record's file name in the shard's output folder.
    const RECORD: &'static str;
    /// The command whose shards write it, as a person types it
    /// (`evflow report live`).
    const COMMAND: &'static str;
    /// What a record is, named when a file is not one.
    const WHAT: &'static str;
    /// What the study's slices count (`cells`, `items`).
    const UNIT: &'static str;

    /// Which slice, `K/N`, as saved.
    fn shard(&self) -> &str;
    /// The study's units in all.
    fn total(&self) -> usize;
    /// The slice's units among them, `[start, end)`.
    fn range(&self) -> [usize; 2];
    /// Writes the record into `dir` (through a temporary file: whole or absent).
    fn write(&self, dir: &Path) -> Result<(), StudyError> {
        write(dir, Self::RECORD, self)
    }

    /// Reads the record in `dir`, checked: its range is its `K/N`'s slice
    /// (a study whose record holds more checks them too). Errors name the
    /// file and what is wrong.
    fn read(dir: &Path) -> Result<Self, StudyError> {
        let saved: Self = Self::read_unchecked(dir)?;
        slice(dir, Self::RECORD, saved.shard(), saved.total(), saved.range(), Self::UNIT)?;
        Ok(saved)
    }

    /// Reads the record in `dir` as JSON, nothing checked.
    fn read_unchecked(dir: &Path) -> Result<Self, StudyError> {
        read(dir, Self::RECORD, &format!("{} --shard", Self::COMMAND), Self::WHAT)
    }

    /// The record's K/N.
    fn slice(&self) -> Result<Shard, ShardError> {
        Shard::parse(self.shard())
    }

    /// Whether `dir` holds such a record.
    fn is_in(dir: &Path) -> bool {
        dir.join(Self::RECORD).is_file()
    }
}
