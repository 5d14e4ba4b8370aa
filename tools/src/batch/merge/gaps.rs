//! The shards that are not there. A shard writes its record (`shard.json`,
//! `textures-shard.json`, …) last, so a folder without one is a task that
//! was killed, cancelled, failed before its end or is still running: its
//! files are not read. Before a merge, [`survey`] sorts the folders given
//! into the shards that finished and the gaps — every K of N with no
//! record, with its folder when one was given (a folder named by its K, as
//! the Slurm scripts name them), and folders with no record that are none
//! of them — and says how to rerun the missing shards: with Slurm
//! ([`super::rerun::slurm`]) and by hand (a sweep shard's own command,
//! [`super::rerun::by_hand`]).

use super::error::MergeError;
use super::rerun;
use crate::batch::shard_record::{ShardRecord, RECORD};
use evflow_engine::batch::Shard;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The name of the note a partial merge (`evflow merge --partial`) leaves
/// in its output folder: which shards are missing and how to rerun them.
/// A complete merge into the folder removes it.
pub const PARTIAL_NOTE: &str = "PARTIAL.txt";

/// Which command wrote a shard, known by its record.
#[derive(Clone, Copy)]
pub enum Kind {
    /// `evflow run --shard` (`shard.json`).
    Sweep,
    /// `evflow library build --shard` (`index.json`).
    #[cfg(feature = "synth")]
    Library,
    /// A study report's (`evflow report textures|live|narx --shard`), one of
    /// [`super::STUDIES`].
    #[cfg(feature = "synth")]
    Study(&'static dyn super::StudyKind),
}

impl PartialEq for Kind {
    fn eq(&self, other: &Kind) -> bool {
        self.record() == other.record()
    }
}

impl std::fmt::Debug for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Kind({})", self.record())
    }
}

impl Kind {
    /// The kind of shard whose record `dir` holds, if it holds one.
    pub fn of(dir: &Path) -> Option<Kind> {
        #[cfg(feature = "synth")]
        if let Some(kind) = super::STUDIES.iter().find(|k| k.holds(dir)) {
            return Some(Kind::Study(*kind));
        }
        if dir.join(RECORD).is_file() {
            return Some(Kind::Sweep);
        }
        #[cfg(feature = "synth")]
        if evflow_study::library::is_library(dir) {
            return Some(Kind::Library);
        }
        None
    }

    /// The record's file name.
    pub fn record(self) -> &'static str {
        match self {
            Kind::Sweep => RECORD,
            #[cfg(feature = "synth")]
            Kind::Library => "index.json",
            #[cfg(feature = "synth")]
            Kind::Study(k) => k.record(),
        }
    }

    /// The command that writes such shards, as a person types it.
    fn command(self) -> &'static str {
        match self {
            Kind::Sweep => "evflow run GRAPH",
            #[cfg(feature = "synth")]
            Kind::Library => "evflow library build",
            #[cfg(feature = "synth")]
            Kind::Study(k) => k.command(),
        }
    }

    /// The array's script, as far as the kind tells it.
    fn script(self) -> &'static str {
        match self {
            Kind::Sweep => "<the array's script, e.g. contrib/slurm/model-grid.sbatch>",
            #[cfg(feature = "synth")]
            Kind::Library => "<the array's script>",
            #[cfg(feature = "synth")]
            Kind::Study(k) => k.script(),
        }
    }

    /// The K/N of the shard in `dir`, read from its record.
    fn slice(self, dir: &Path) -> Result<Shard, MergeError> {
        match self {
            Kind::Sweep => Ok(ShardRecord::read(dir)?.shard),
            #[cfg(feature = "synth")]
            Kind::Library => Ok(evflow_study::library::read_shard(dir)?.shard),
            #[cfg(feature = "synth")]
            Kind::Study(k) => k.slice(dir),
        }
    }
}

/// A K of N that no folder given holds a record of.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    /// Its K.
    pub k: usize,
    /// Its folder, when one was given (named by its K) without a record.
    pub folder: Option<PathBuf>,
    /// The command that runs it by hand, when a shard's record keeps its
    /// own command (sweeps) and the folder to write into is known.
    pub by_hand: Option<String>,
}

/// What is missing from the shards given to a merge.
#[derive(Debug, Clone)]
pub struct Gaps {
    /// The kind of the shards that finished.
    pub kind: Kind,
    /// N.
    pub n: usize,
    /// The shards that finished (folders with a record).
    pub given: usize,
    /// The K of N without a record, in K order.
    pub missing: Vec<Gap>,
    /// Folders given without a record that are none of the missing K.
    pub strays: Vec<PathBuf>,
}

/// The folders that hold a shard's record, and what is missing.
pub fn survey(dirs: &[PathBuf]) -> Result<(Vec<PathBuf>, Gaps), MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let (done, unfinished): (Vec<PathBuf>, Vec<PathBuf>) = dirs.iter().cloned().partition(|d| Kind::of(d).is_some());
    let Some(kind) = done.first().and_then(|d| Kind::of(d)) else {
        return Err(MergeError::NoRecords { dirs: unfinished });
    };
    let mut slices = Vec::with_capacity(done.len());
    for d in &done {
        // A folder of another kind is refused by the merge itself, by name.
        if Kind::of(d) == Some(kind) {
            slices.push((kind.slice(d)?, d));
        }
    }
    slices.sort_by_key(|(s, _)| s.k);
    let n = slices[0].0.n;
    let mut gaps = Gaps { kind, n, given: done.len(), missing: Vec::new(), strays: Vec::new() };
    // Shards of other N: the merge refuses them by name; no gaps to count.
    if slices.iter().any(|(s, _)| s.n != n) {
        gaps.strays = unfinished;
        return Ok((done, gaps));
    }
    let have: Vec<usize> = slices.iter().map(|(s, _)| s.k).collect();
    gaps.missing = (1..=n).filter(|k| !have.contains(k)).map(|k| Gap { k, folder: None, by_hand: None }).collect();
    for d in unfinished {
        let named = d.file_name().and_then(|f| f.to_str()).and_then(|f| f.parse::<usize>().ok());
        match gaps.missing.iter_mut().find(|g| Some(g.k) == named && g.folder.is_none()) {
            Some(g) => g.folder = Some(d),
            None => gaps.strays.push(d),
        }
    }
    // A sweep shard keeps its command line: the others' commands are it with K and folder changed.
    let (first, first_dir) = (slices[0].0, slices[0].1);
    let command = match kind {
        Kind::Sweep => ShardRecord::read(first_dir)?.command,
        #[cfg(feature = "synth")]
        _ => Vec::new(),
    };
    for g in &mut gaps.missing {
        let to = g.folder.as_ref().map(|f| f.display().to_string()).or_else(|| {
            let out = rerun::out_of(&command)?;
            rerun::sibling(out, first.k, g.k)
        });
        g.by_hand = to.and_then(|to| rerun::by_hand(&command, g.k, n, &to));
    }
    Ok((done, gaps))
}

impl Gaps {
    /// Whether every shard is there and every folder given holds one.
    pub fn is_empty(&self) -> bool {
        self.missing.is_empty() && self.strays.is_empty()
    }

    /// The missing K, as `6, 8`.
    fn ks(&self) -> String {
        self.missing.iter().map(|g| g.k.to_string()).collect::<Vec<_>>().join(", ")
    }

    /// One line: `shards 6, 8 of 9 missing`, and the folders without a
    /// record that are no shard.
    pub fn summary(&self) -> String {
        let mut s = match self.missing.len() {
            0 => String::new(),
            1 => format!("shard {} of {} missing", self.ks(), self.n),
            _ => format!("shards {} of {} missing", self.ks(), self.n),
        };
        if !self.strays.is_empty() {
            let strays: Vec<String> = self.strays.iter().map(|d| d.display().to_string()).collect();
            let sep = if s.is_empty() { "" } else { "; " };
            let _ = write!(s, "{sep}left out, holding no {}: {}", self.kind.record(), strays.join(", "));
        }
        s
    }

    /// Every gap on a line of its own, then how to rerun the missing shards.
    pub fn details(&self) -> String {
        let record = self.kind.record();
        let unfinished = "(its task was killed or cancelled, failed before its end, or is still running; \
                          a shard writes it last)";
        let mut s = String::new();
        for g in &self.missing {
            let _ = match &g.folder {
                Some(f) => {
                    writeln!(s, "  {}/{}: {} does not exist {unfinished}", g.k, self.n, f.join(record).display())
                }
                None => writeln!(s, "  {}/{}: no folder given holds it", g.k, self.n),
            };
        }
        for d in &self.strays {
            let _ = writeln!(
                s,
                "  {}: holds no {} (not a shard folder of these, or its --shard task did not end; a shard writes it \
                 last)",
                d.display(),
                d.join(record).display()
            );
        }
        if self.missing.is_empty() {
            return s;
        }
        let ks: Vec<usize> = self.missing.iter().map(|g| g.k).collect();
        let _ = writeln!(s, "Rerun {} into {}, then merge again:", self.what(), self.where_());
        let _ = writeln!(
            s,
            "  with Slurm, from the folder the array ran in, with the options it was submitted with:\n    {}",
            rerun::slurm(&ks, self.n, self.kind.script())
        );
        let _ = writeln!(s, "  by hand, from the folder the shards ran in:");
        for g in &self.missing {
            let _ = match &g.by_hand {
                Some(c) => writeln!(s, "    {c}"),
                None => writeln!(
                    s,
                    "    {} --shard {}/{} --out {} with the options of the other shards",
                    self.kind.command(),
                    g.k,
                    self.n,
                    g.folder.as_ref().map(|f| f.display().to_string()).unwrap_or_else(|| "DIR".into())
                ),
            };
        }
        s
    }

    /// Why a merge (without `--partial`) refuses these gaps: each named,
    /// how to rerun the missing shards, and how to merge what is there.
    pub fn refusal(&self) -> String {
        let mut s = if self.missing.is_empty() {
            "folders without a shard's record among the shards; nothing was merged:\n".to_string()
        } else {
            let ks: Vec<String> = self.missing.iter().map(|g| format!("{}/{}", g.k, self.n)).collect();
            format!("shards missing: {} (given {} of {}); nothing was merged:\n", ks.join(", "), self.given, self.n)
        };
        s.push_str(&self.details());
        let _ = write!(
            s,
            "Or merge the {} shards there are, the output marked partial (its {PARTIAL_NOTE}) and exit status 3: \
             evflow merge --partial OUT FOLDERS…",
            self.given
        );
        s
    }

    /// `shard 6` or `shards 6, 8`.
    fn what(&self) -> String {
        format!("{} {}", if self.missing.len() == 1 { "shard" } else { "shards" }, self.ks())
    }

    /// Where the reruns write.
    fn where_(&self) -> &'static str {
        if self.missing.len() == 1 {
            "its folder"
        } else {
            "their folders"
        }
    }
}
