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

use super::shard_record::{RecordError, ShardRecord, RECORD};
use super::tables::{report_json, sweep_csv};
use evflow_engine::batch::{Failures, Shard};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Why shards could not be merged; each names the folders or files and
/// what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A shard's record could not be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// No shard folders were given.
    #[error("no shards to merge")]
    NoShards,
    /// Two shards are not of one sweep.
    #[error("{} and {}: not shards of one sweep ({what} differ)", first.display(), other.display())]
    NotOneSweep {
        /// The folder of the shard with the lowest K.
        first: PathBuf,
        /// The folder of the shard that differs from it.
        other: PathBuf,
        /// What differs.
        what: &'static str,
    },
    /// A shard's record holds other runs than its K of N.
    #[error("{}: shard {shard} should hold runs {expected:?} of {total}", dir.display())]
    WrongRange {
        /// The shard's folder.
        dir: PathBuf,
        /// Its K/N.
        shard: Shard,
        /// The runs a K/N of `total` holds.
        expected: Range<usize>,
        /// Runs in the whole sweep.
        total: usize,
    },
    /// Two folders are the same K.
    #[error("{} and {}: both are shard {shard}", first.display(), second.display())]
    SameShard {
        /// One folder.
        first: PathBuf,
        /// The other.
        second: PathBuf,
        /// Their K/N.
        shard: Shard,
    },
    /// Some K of N were not given.
    #[error("shards missing: {} (given {given} of {n})", missing.join(", "))]
    Missing {
        /// The missing K/N, as text.
        missing: Vec<String>,
        /// How many shards were given.
        given: usize,
        /// N.
        n: usize,
    },
    /// Two shards wrote different files of one name.
    #[error("{} and {}: two shards wrote different files of one name", first.display(), second.display())]
    DifferentFiles {
        /// The file as the earlier shard wrote it.
        first: PathBuf,
        /// The file as a later shard wrote it.
        second: PathBuf,
    },
    /// A shard's folder could not be listed.
    #[error("{}: cannot list", dir.display())]
    List {
        /// The folder.
        dir: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// A folder of the output could not be created.
    #[error("{}: cannot create", dir.display())]
    Create {
        /// The folder.
        dir: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// A file could not be copied into the output.
    #[error("{} → {}: cannot copy", from.display(), to.display())]
    Copy {
        /// The shard's file.
        from: PathBuf,
        /// Where it was to go.
        to: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// A merged table could not be written.
    #[error("{}: cannot write", path.display())]
    Write {
        /// The table's path.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// A folder among the shards of `evflow report narx` that is not one of them.
    #[error("{}: not a shard of `evflow report narx` as {} is (it holds no narx-shard.json)", dir.display(), narx.display())]
    NotNarx {
        /// The folder without the record.
        dir: PathBuf,
        /// A folder with it.
        narx: PathBuf,
    },
    /// The shards of a model library could not be read or their indexes joined.
    #[cfg(feature = "synth")]
    #[error(transparent)]
    Library(#[from] evflow_nodes::synth::study::StudyError),
}

/// What a merge of a sweep's shards did. Runs that failed in the shards
/// are listed in `failures`; the merge itself still wrote everything.
#[derive(Debug)]
pub struct SweepMerge {
    /// Shards merged.
    pub shards: usize,
    /// The graph file, as the shards were given it.
    pub graph: String,
    /// Runs that succeeded, over all shards.
    pub runs: usize,
    /// Runs in the whole sweep.
    pub total: usize,
    /// Files the graphs wrote, copied into the output folder.
    pub files: usize,
    /// The tables written into the output folder (CSV first, then JSON).
    pub tables: Vec<PathBuf>,
    /// The runs that failed in the shards, labelled with their shard.
    pub failures: Failures,
}

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

/// What a merge did: of a sweep or of a model library.
#[derive(Debug)]
pub enum Merged {
    /// The shards of `evflow run --shard`.
    Sweep(SweepMerge),
    /// The shards of `evflow library build --shard`.
    Library(LibraryMerge),
    /// The shards of `evflow report narx --shard`.
    #[cfg(feature = "synth")]
    Narx(super::merge_narx::NarxMerge),
}

/// Merges the shard folders `dirs` (in any order) into `out`: a `report
/// narx`'s when a folder holds its record ([`super::merge_narx`]), a model
/// library's when every folder is one (and none holds a shard record),
/// else a sweep's.
pub fn merge(out: &Path, dirs: &[PathBuf]) -> Result<Merged, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    #[cfg(feature = "synth")]
    if dirs.iter().any(|d| super::merge_narx::is_narx_shard(d)) {
        return super::merge_narx::merge_narx(out, dirs).map(Merged::Narx);
    }
    #[cfg(feature = "synth")]
    if dirs.iter().all(|d| !d.join(RECORD).exists() && evflow_nodes::synth::study::library::is_library(d)) {
        return merge_library(out, dirs).map(Merged::Library);
    }
    merge_sweep(out, dirs).map(Merged::Sweep)
}

/// Merges the shards of a sweep (`evflow run --shard`) in `dirs` into `out`.
pub fn merge_sweep(out: &Path, dirs: &[PathBuf]) -> Result<SweepMerge, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let shards = dirs.iter().map(|d| Ok((d.clone(), ShardRecord::read(d)?))).collect::<Result<Vec<_>, MergeError>>()?;
    let shards = in_order(shards)?;
    let first = shards[0].1.clone();
    // The files the graphs wrote: each once; two shards writing the same
    // name must have written the same bytes.
    let skip: Vec<PathBuf> = [Some(RECORD.to_string()), first.csv.clone(), first.json.clone()]
        .into_iter()
        .flatten()
        .map(PathBuf::from)
        .collect();
    let folders: Vec<&Path> = shards.iter().map(|(d, _)| d.as_path()).collect();
    let files = copy_files(out, &folders, &skip)?;
    let mut runs = Vec::new();
    let mut failures = Failures::new();
    for (_, r) in &shards {
        runs.extend(r.runs.iter().cloned());
        for (l, why) in &r.failures {
            failures.push(format!("{l} (shard {})", r.shard), why);
        }
    }
    // A table the shards wrote outside their --out goes into OUT by its file name.
    let inside = |p: &str| {
        let p = Path::new(p);
        if p.is_absolute() {
            out.join(p.file_name().unwrap_or_default())
        } else {
            out.join(p)
        }
    };
    let mut tables = Vec::new();
    if let Some(csv) = &first.csv {
        let path = inside(csv);
        write(&path, &sweep_csv(&runs, first.timings))?;
        tables.push(path);
    }
    if let Some(json) = &first.json {
        let path = inside(json);
        write(&path, &report_json(&runs, first.sweep, first.timings))?;
        tables.push(path);
    }
    Ok(SweepMerge {
        shards: shards.len(),
        graph: first.graph,
        runs: runs.len(),
        total: first.total,
        files,
        tables,
        failures,
    })
}

/// Merges the shards of a model library (`evflow library build --shard`)
/// in `dirs` into `out`: their files copied, their indexes joined.
#[cfg(feature = "synth")]
pub fn merge_library(out: &Path, dirs: &[PathBuf]) -> Result<LibraryMerge, MergeError> {
    use evflow_nodes::synth::study::library::{merge_index, read_shard};
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let shards = dirs
        .iter()
        .map(|d| Ok(read_shard(d).map(|s| (d.clone(), s.shard, s))?))
        .collect::<Result<Vec<_>, MergeError>>()?;
    let shards = k_order(shards)?;
    let n = shards.len();
    let indexes: Vec<_> = shards.into_iter().map(|(_, _, s)| s).collect();
    let folders: Vec<&Path> = indexes.iter().map(|s| s.dir.as_path()).collect();
    let files = copy_files(out, &folders, &[PathBuf::from("index.json")])?;
    let entries = merge_index(out, &indexes)?;
    Ok(LibraryMerge { shards: n, entries, files, index: out.join("index.json") })
}

/// The shards in K order, checked to be the N slices of one sweep.
fn in_order(mut shards: Vec<(PathBuf, ShardRecord)>) -> Result<Vec<(PathBuf, ShardRecord)>, MergeError> {
    shards.sort_by_key(|(_, r)| r.shard.k);
    let (first_dir, first) = &shards[0];
    let n = first.shard.n;
    for (dir, r) in &shards {
        let differs =
            |what: &'static str| MergeError::NotOneSweep { first: first_dir.clone(), other: dir.clone(), what };
        if r.shard.n != n {
            return Err(differs("the shard counts N"));
        }
        if r.graph != first.graph {
            return Err(differs("the graphs"));
        }
        if r.total != first.total || r.sweep != first.sweep {
            return Err(differs("the numbers of runs"));
        }
        if r.timings != first.timings || r.csv != first.csv || r.json != first.json {
            return Err(differs("--no-times, --csv or --json"));
        }
        if r.range != r.shard.range(r.total) {
            return Err(MergeError::WrongRange {
                dir: dir.clone(),
                shard: r.shard,
                expected: r.shard.range(r.total),
                total: r.total,
            });
        }
    }
    let shards = k_order(shards.into_iter().map(|(d, r)| (d, r.shard, r)).collect())?;
    Ok(shards.into_iter().map(|(d, _, r)| (d, r)).collect())
}

/// Checks that the shards' K are 1..=N, each once, and puts them in K order.
pub(crate) fn k_order<T>(mut shards: Vec<(PathBuf, Shard, T)>) -> Result<Vec<(PathBuf, Shard, T)>, MergeError> {
    shards.sort_by_key(|(_, s, _)| s.k);
    let n = shards[0].1.n;
    for w in shards.windows(2) {
        if w[0].1.k == w[1].1.k {
            return Err(MergeError::SameShard { first: w[0].0.clone(), second: w[1].0.clone(), shard: w[0].1 });
        }
    }
    let have: Vec<usize> = shards.iter().map(|(_, s, _)| s.k).collect();
    let missing: Vec<String> = (1..=n).filter(|k| !have.contains(k)).map(|k| format!("{k}/{n}")).collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing { missing, given: shards.len(), n });
    }
    Ok(shards)
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

/// Creates the folder `path` goes into; returns the temporary name beside `path`.
fn prepare(path: &Path) -> Result<PathBuf, MergeError> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| MergeError::Create { dir: parent.to_path_buf(), source })?;
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(path.with_file_name(format!(".{name}.merge-tmp")))
}

/// Copies `from` to `to` through a temporary file beside `to`.
fn copy(from: &Path, to: &Path) -> Result<(), MergeError> {
    let tmp = prepare(to)?;
    std::fs::copy(from, &tmp).and_then(|_| std::fs::rename(&tmp, to)).map_err(|source| MergeError::Copy {
        from: from.to_path_buf(),
        to: to.to_path_buf(),
        source,
    })
}

/// Writes `text` to `path` through a temporary file beside it.
pub(crate) fn write(path: &Path, text: &str) -> Result<(), MergeError> {
    let tmp = prepare(path)?;
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|source| MergeError::Write { path: path.to_path_buf(), source })
}

/// Copies every file under the shard folders into `out` (as relative
/// paths), leaving out `skip` and temporary files; two shards writing one
/// name must have written the same bytes. Returns how many were copied.
pub(crate) fn copy_files(out: &Path, dirs: &[&Path], skip: &[PathBuf]) -> Result<usize, MergeError> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::shard_record::tests::{record, run};
    use crate::batch::tables::Timings;

    /// Three shards of a five-run sweep, written into `base/s1..s3`, each
    /// with the files its graph wrote.
    fn three_shards(base: &Path) -> Vec<PathBuf> {
        let all: Vec<_> = (0..5).map(|i| run(i as f64 * 0.1, 1000 + i)).collect();
        (1..=3)
            .map(|k| {
                let shard = Shard { k, n: 3 };
                let dir = base.join(format!("s{k}"));
                std::fs::create_dir_all(dir.join("wav")).unwrap();
                std::fs::write(dir.join(format!("wav/run{k}.wav")), [k as u8; 3]).unwrap();
                std::fs::write(dir.join("common.txt"), "same").unwrap();
                std::fs::write(dir.join("t.csv"), "the shard's own table").unwrap();
                let mut r = record(shard, 5, all[shard.range(5)].to_vec());
                r.failures = vec![(format!("f{k}"), "why".into())];
                r.write(&dir).unwrap();
                dir
            })
            .collect()
    }

    #[test]
    fn shards_merge_into_the_tables_of_one_run() {
        let base = tempfile::tempdir().unwrap();
        let mut dirs = three_shards(base.path());
        dirs.reverse();
        let out = base.path().join("out");
        let m = merge_sweep(&out, &dirs).unwrap();
        let all: Vec<_> = (0..5).map(|i| run(i as f64 * 0.1, 1000 + i)).collect();
        assert_eq!(std::fs::read_to_string(out.join("t.csv")).unwrap(), sweep_csv(&all, Timings::Show));
        assert_eq!((m.shards, m.runs, m.total, m.files, m.graph.as_str()), (3, 5, 5, 4, "graphs/g.toml"));
        assert_eq!(m.tables, vec![out.join("t.csv")]);
        let labels: Vec<&str> = m.failures.list.iter().map(|(l, _)| l.as_str()).collect();
        assert_eq!(labels, ["f1 (shard 1/3)", "f2 (shard 2/3)", "f3 (shard 3/3)"]);
        for k in 1..=3 {
            assert_eq!(std::fs::read(out.join(format!("wav/run{k}.wav"))).unwrap(), [k as u8; 3]);
        }
        assert!(!out.join(RECORD).exists());
    }

    #[test]
    fn shards_that_do_not_make_one_sweep_are_refused_by_name() {
        let base = tempfile::tempdir().unwrap();
        let dirs = three_shards(base.path());
        let out = base.path().join("out");
        let e = merge_sweep(&out, &dirs[..2]).unwrap_err();
        assert_eq!(e.to_string(), "shards missing: 3/3 (given 2 of 3)");
        let e = merge_sweep(&out, &[dirs[0].clone(), dirs[1].clone(), dirs[1].clone(), dirs[2].clone()]).unwrap_err();
        assert_eq!(e.to_string(), format!("{} and {}: both are shard 2/3", dirs[1].display(), dirs[1].display()));
        assert!(matches!(merge_sweep(&out, &[]), Err(MergeError::NoShards)));

        let mut other = ShardRecord::read(&dirs[2]).unwrap();
        other.graph = "graphs/other.toml".into();
        other.write(&dirs[2]).unwrap();
        let e = merge_sweep(&out, &dirs).unwrap_err();
        let (d0, d2) = (dirs[0].display(), dirs[2].display());
        assert_eq!(e.to_string(), format!("{d0} and {d2}: not shards of one sweep (the graphs differ)"));

        let mut other = ShardRecord::read(&dirs[2]).unwrap();
        other.graph = "graphs/g.toml".into();
        other.range = 0..1;
        other.write(&dirs[2]).unwrap();
        let e = merge_sweep(&out, &dirs).unwrap_err();
        assert_eq!(e.to_string(), format!("{d2}: shard 3/3 should hold runs 4..5 of 5"));
        assert!(!out.exists(), "a refused merge wrote {}", out.display());
    }

    #[test]
    fn two_shards_writing_one_name_must_agree() {
        let base = tempfile::tempdir().unwrap();
        let dirs = three_shards(base.path());
        std::fs::write(dirs[1].join("common.txt"), "differs").unwrap();
        let e = merge_sweep(&base.path().join("out"), &dirs).unwrap_err();
        let (a, b) = (dirs[0].join("common.txt"), dirs[1].join("common.txt"));
        assert_eq!(
            e.to_string(),
            format!("{} and {}: two shards wrote different files of one name", a.display(), b.display())
        );
        // Refused before anything is copied: no half-merged folder.
        let out = base.path().join("out");
        assert!(!out.join("wav/run1.wav").exists() && !out.join("common.txt").exists());
    }
}
