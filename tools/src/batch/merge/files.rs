//! What every merge does with the shards' folders: put them in K order,
//! copy their files into the output (every clash found first), write a
//! table through a temporary file.

use super::error::MergeError;
use evflow_engine::batch::Shard;
use std::path::{Path, PathBuf};

/// Whether a merge needs every K of N, or takes the shards there are
/// (`evflow merge --partial`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// Every K of N, each once.
    All,
    /// The K there are, each once.
    Partial,
}

/// Checks that the shards' K are each once, and with [`Coverage::All`]
/// that they are 1..=N; puts them in K order.
pub fn k_order<T>(
    mut shards: Vec<(PathBuf, Shard, T)>,
    coverage: Coverage,
) -> Result<Vec<(PathBuf, Shard, T)>, MergeError> {
    shards.sort_by_key(|(_, s, _)| s.k);
    let n = shards[0].1.n;
    for w in shards.windows(2) {
        if w[0].1.k == w[1].1.k {
            return Err(MergeError::SameShard { first: w[0].0.clone(), second: w[1].0.clone(), shard: w[0].1 });
        }
    }
    let have: Vec<usize> = shards.iter().map(|(_, s, _)| s.k).collect();
    let missing: Vec<String> = (1..=n).filter(|k| !have.contains(k)).map(|k| format!("{k}/{n}")).collect();
    if !missing.is_empty() && coverage == Coverage::All {
        return Err(MergeError::Missing { missing, given: shards.len(), n });
    }
    Ok(shards)
}

/// Reads every shard folder of `dirs` with `read` (its slice and record),
/// puts them in K order and checks that they are the N slices of one batch:
/// the same N, and nothing `differs` between the first's record and
/// another's (else what differs is named); every K of N, or those there
/// are ([`Coverage`]).
pub fn one_batch<T>(
    dirs: &[PathBuf],
    read: impl Fn(&Path) -> Result<(Shard, T), MergeError>,
    differs: impl Fn(&T, &T) -> Option<&'static str>,
    coverage: Coverage,
) -> Result<Vec<(PathBuf, Shard, T)>, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let mut shards = Vec::with_capacity(dirs.len());
    for d in dirs {
        let (shard, record) = read(d)?;
        shards.push((d.clone(), shard, record));
    }
    shards.sort_by_key(|(_, s, _)| s.k);
    let (first_dir, first_shard, first) = &shards[0];
    for (dir, shard, s) in &shards {
        let not_one = |what| MergeError::NotOneBatch { first: first_dir.clone(), other: dir.clone(), what };
        if shard.n != first_shard.n {
            return Err(not_one("the shard counts N"));
        }
        if let Some(what) = differs(first, s) {
            return Err(not_one(what));
        }
    }
    k_order(shards, coverage)
}

/// Every file under `dir`, as paths relative to it, sorted.
fn files_under(dir: &Path) -> Result<Vec<PathBuf>, MergeError> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        let here = dir.join(&rel);
        let list = |source| MergeError::List { dir: here.clone(), source };
        for e in std::fs::read_dir(&here).map_err(list)? {
            let e = e.map_err(list)?;
            let p = rel.join(e.file_name());
            if e.file_type().map_err(list)?.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Creates the folder `path` goes into.
fn prepare(path: &Path) -> Result<(), MergeError> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| MergeError::Create { dir: parent.to_path_buf(), source })?;
    }
    Ok(())
}

/// Copies `from` to `to` through a temporary file beside `to`
/// (`evflow_engine::atomic_file`).
fn copy(from: &Path, to: &Path) -> Result<(), MergeError> {
    prepare(to)?;
    evflow_engine::atomic_file::copy_atomically(from, to).map_err(|source| MergeError::Copy {
        from: from.to_path_buf(),
        to: to.to_path_buf(),
        source,
    })
}

/// Writes `text` to `path` through a temporary file beside it.
pub fn write(path: &Path, text: &str) -> Result<(), MergeError> {
    prepare(path)?;
    evflow_engine::atomic_file::write_atomically(path, text)
        .map_err(|source| MergeError::Write { path: path.to_path_buf(), source })
}

/// Copies every file under the shard folders into `out` (as relative
/// paths), leaving out `skip` and temporary files; two shards writing one
/// name must have written the same bytes. Returns how many were copied.
pub fn copy_files(out: &Path, dirs: &[&Path], skip: &[PathBuf]) -> Result<usize, MergeError> {
    // Every file and every clash first, so that a clash leaves `out`
    // untouched; then the copies.
    let mut planned: Vec<(PathBuf, PathBuf)> = Vec::new();
    for dir in dirs {
        for rel in files_under(dir)? {
            if skip.contains(&rel) || rel.file_name().is_some_and(|n| n.to_string_lossy().ends_with(".tmp")) {
                continue;
            }
            let from = dir.join(&rel);
            if let Some((_, earlier)) = planned.iter().find(|(r, _)| *r == rel) {
                let same = std::fs::read(earlier).ok() == std::fs::read(&from).ok();
                if !same {
                    return Err(MergeError::DifferentFiles { first: earlier.clone(), second: from });
                }
                continue;
            }
            planned.push((rel, from));
        }
    }
    for (rel, from) in &planned {
        copy(from, &out.join(rel))?;
    }
    Ok(planned.len())
}
