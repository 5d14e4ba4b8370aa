//! Why shards could not be merged.

use super::super::shard_record::RecordError;
use evflow_engine::batch::Shard;
use std::ops::Range;
use std::path::PathBuf;

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
    /// Two shards are not of one batch (sweep, library or report).
    #[error("{} and {}: not shards of one batch ({what} differ)", first.display(), other.display())]
    NotOneBatch {
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
    /// Some K of N have no record among the folders given, or some
    /// folders hold none (`evflow merge` without `--partial`): each named,
    /// with the commands that rerun them (`gaps::Gaps::refusal`).
    #[error("{refusal}")]
    Incomplete {
        /// The K without a record.
        missing: Vec<usize>,
        /// N.
        n: usize,
        /// The whole message: every gap, the commands that rerun them.
        refusal: String,
    },
    /// No folder given holds a shard's record.
    #[error(
        "none of {} holds a shard's record (shard.json, or a report's *-shard.json; a shard writes it last): \
         their tasks were killed or cancelled, failed before their end, or are still running. Rerun them \
         (with Slurm: EVFLOW_SHARDS=N sbatch --array=K,… <the array's script>; by hand: the same command with \
         --shard K/N), then merge again",
        dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    NoRecords {
        /// The folders given.
        dirs: Vec<PathBuf>,
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
    /// A folder among the shards of a study report that is not one of them.
    #[error("{}: not a shard of `{command}` as {} is (it holds no {record})", dir.display(), first.display())]
    NotOfReport {
        /// The folder without the record.
        dir: PathBuf,
        /// A folder with it.
        first: PathBuf,
        /// The report's command.
        command: &'static str,
        /// Its record's file name.
        record: &'static str,
    },
    /// The shards of a model library or of a texture report could not be
    /// read, or their indexes joined.
    #[cfg(feature = "synth")]
    #[error(transparent)]
    Study(#[from] evflow_study::StudyError),
}
