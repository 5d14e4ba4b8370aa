//! A sweep's shard record (`shard.json`, [`super::shard_record`]) as a JSON
//! file: written through a temporary file, read back with every error
//! naming the file and what is wrong.

use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::error::Category;
use std::path::{Path, PathBuf};

/// Why a shard's record could not be written or read; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The record could not be written.
    #[error("{}: cannot write the shard's record", path.display())]
    Write {
        /// The record's path.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// The record could not be read (often: the folder is not a shard's).
    #[error("{}: cannot read (is it the --out of a run with `--shard`?)", path.display())]
    Read {
        /// The record's path.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// The record is not JSON.
    #[error("{}: {error}", path.display())]
    Json {
        /// The record's path.
        path: PathBuf,
        /// Where and what the JSON fault is.
        error: serde_json::Error,
    },
    /// The record is JSON but not a shard's record: a field is missing or
    /// of the wrong kind.
    #[error("{}: {what}", path.display())]
    Invalid {
        /// The record's path.
        path: PathBuf,
        /// Which field (and run) and what is wrong with it.
        what: String,
    },
}

/// Writes `doc` as `dir/name` through a temporary file beside it, so a
/// record is whole or absent.
pub fn write_doc<T: Serialize>(dir: &Path, name: &str, doc: &T) -> Result<(), RecordError> {
    let path = dir.join(name);
    serde_json::to_string_pretty(doc)
        .map_err(std::io::Error::from)
        .and_then(|text| evflow_engine::atomic_file::write_atomically(&path, text))
        .map_err(|source| RecordError::Write { path, source })
}

/// Reads `dir/name` as the JSON of a `T` and `check`s what it holds; errors
/// name the file and what is wrong: not JSON at all ([`RecordError::Json`]),
/// or JSON that is not the record (a field missing or of the wrong kind, or
/// refused by `check`: [`RecordError::Invalid`]).
pub fn read_doc<T: DeserializeOwned, R>(
    dir: &Path,
    name: &str,
    check: impl Fn(T) -> Result<R, String>,
) -> Result<R, RecordError> {
    let path = dir.join(name);
    let text = match evflow_engine::files::read_regular_to_string(&path) {
        Ok(text) => text,
        Err(source) => return Err(RecordError::Read { path, source }),
    };
    let doc: T = match serde_json::from_str(&text) {
        Ok(doc) => doc,
        Err(error) if error.classify() == Category::Data => {
            return Err(RecordError::Invalid { path, what: error.to_string() })
        }
        Err(error) => return Err(RecordError::Json { path, error }),
    };
    check(doc).map_err(|what| RecordError::Invalid { path, what })
}
