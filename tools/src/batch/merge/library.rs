//! The merge of a model library's shards (`evflow library build --shard
//! K/N`): their files copied, their indexes joined in the library's order.

use super::error::MergeError;
use super::files::{copy_files, k_order, Coverage};
use std::path::{Path, PathBuf};

/// What a merge of a model library's shards did.
#[derive(Debug)]
pub struct LibraryMerge {
    /// Shards merged.
    pub shards: usize,
    /// Entries in the joined index.
    pub entries: usize,
    /// Files copied (the shards' indexes left out).
    pub files: usize,
    /// The joined index.
    pub index: PathBuf,
}

/// Merges the shards of a model library (`evflow library build --shard`)
/// in `dirs` into `out`: their files copied, their indexes joined; every
/// K of N, or those there are ([`Coverage`]).
pub fn merge_library(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<LibraryMerge, MergeError> {
    use evflow_study::library::{merge_index, read_shard};
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let shards = dirs
        .iter()
        .map(|d| Ok(read_shard(d).map(|s| (d.clone(), s.shard, s))?))
        .collect::<Result<Vec<_>, MergeError>>()?;
    let shards = k_order(shards, coverage)?;
    let n = shards.len();
    let indexes: Vec<_> = shards.into_iter().map(|(_, _, s)| s).collect();
    let folders: Vec<&Path> = indexes.iter().map(|s| s.dir.as_path()).collect();
    let files = copy_files(out, &folders, &[PathBuf::from("index.json")])?;
    let entries = merge_index(out, &indexes)?;
    Ok(LibraryMerge { shards: n, entries, files, index: out.join("index.json") })
}
