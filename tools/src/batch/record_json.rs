//! A sweep's shard record (`shard.json`, [`super::shard_record`]) as a JSON
//! document: written through a temporary file, read back with every error
//! naming the file, and its fields read with the fault named.

use serde_json::Value as Json;
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

/// What is wrong inside a record, before the file's name is put to it.
pub type Fault<T> = Result<T, String>;

/// The field `key` of `v`.
pub fn field<'a>(v: &'a Json, key: &str) -> Fault<&'a Json> {
    v.get(key).ok_or_else(|| format!("missing `{key}`"))
}

/// The text field `key` of `v`.
pub fn text<'a>(v: &'a Json, key: &str) -> Fault<&'a str> {
    field(v, key)?.as_str().ok_or_else(|| format!("`{key}` is not text"))
}

/// The whole-number field `key` of `v`.
pub fn count(v: &Json, key: &str) -> Fault<u64> {
    field(v, key)?.as_u64().ok_or_else(|| format!("`{key}` is not a whole number"))
}

/// The list field `key` of `v`.
pub fn list<'a>(v: &'a Json, key: &str) -> Fault<&'a Vec<Json>> {
    field(v, key)?.as_array().ok_or_else(|| format!("`{key}` is not a list"))
}

/// Writes `doc` as `dir/name` through a temporary file beside it, so a
/// record is whole or absent.
pub fn write_doc(dir: &Path, name: &str, doc: &Json) -> Result<(), RecordError> {
    let path = dir.join(name);
    let tmp = dir.join(format!(".{name}.tmp"));
    serde_json::to_string_pretty(doc)
        .map_err(std::io::Error::from)
        .and_then(|text| std::fs::write(&tmp, text))
        .and_then(|_| std::fs::rename(&tmp, &path))
        .map_err(|source| RecordError::Write { path, source })
}

/// Reads `dir/name` as JSON and `parse`s it; errors name the file and what
/// is wrong.
pub fn read_doc<T>(dir: &Path, name: &str, parse: impl Fn(&Json) -> Fault<T>) -> Result<T, RecordError> {
    let path = dir.join(name);
    let text = match evflow_engine::files::read_regular_to_string(&path) {
        Ok(text) => text,
        Err(source) => return Err(RecordError::Read { path, source }),
    };
    let doc: Json = match serde_json::from_str(&text) {
        Ok(doc) => doc,
        Err(error) => return Err(RecordError::Json { path, error }),
    };
    parse(&doc).map_err(|what| RecordError::Invalid { path, what })
}
