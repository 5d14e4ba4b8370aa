//! The merge of a live report's shards (`evflow report live --shard K/N`):
//! each shard saved the rows of its slice of the (profile, sample, user)
//! items ([`evflow_study::live::saved`]); the merge checks
//! that the shards are the N slices of one report, copies their files
//! (libraries, runs, floors), joins the rows in item order and writes
//! live.md, rows.csv and the figures with the code `evflow report live`
//! uses — one run's, byte for byte.

use super::error::MergeError;
use super::files::{copy_files, one_batch, write, Coverage};
use evflow_engine::batch::{Failures, Shard};
use evflow_study::live::saved::{LiveRecord, RECORD};
use evflow_study::tables::live::{csv, figures, markdown};
use evflow_study::StudyError;
use std::path::{Path, PathBuf};

/// What a merge of a live report's shards did.
#[derive(Debug)]
pub struct LiveMerge {
    /// Shards merged.
    pub shards: usize,
    /// Rows over all shards.
    pub rows: usize,
    /// Items of the whole report.
    pub items: usize,
    /// Files copied from the shards.
    pub files: usize,
    /// The tables and figures written.
    pub written: Vec<PathBuf>,
    /// The report's Markdown, as `evflow report live` prints it.
    pub markdown: String,
    /// The steps that failed in the shards, labelled with their shard.
    pub failures: Failures,
}

/// Whether `dir` holds a live report shard's record.
pub fn is_live_shard(dir: &Path) -> bool {
    LiveRecord::is_in(dir)
}

/// Merges the shards of `evflow report live --shard` in `dirs` (in any
/// order) into `out`.
pub fn merge_live(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<LiveMerge, MergeError> {
    let read = |d: &Path| -> Result<(Shard, LiveRecord), MergeError> {
        let saved = LiveRecord::read(d)?;
        let shard = saved.slice().map_err(|e| StudyError::Config(format!("{}: {e}", d.display())))?;
        Ok((shard, saved))
    };
    let shards = one_batch(
        dirs,
        read,
        |a, b| a.scope == b.scope && a.items == b.items,
        "the reports' settings: profiles, samples, users, gains, grid, epochs, iterations, seconds, floor or the \
         live synthesis' settings",
        coverage,
    )?;
    let folders: Vec<&Path> = shards.iter().map(|(d, _, _)| d.as_path()).collect();
    let files = copy_files(out, &folders, &[PathBuf::from(RECORD)])?;
    std::fs::create_dir_all(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    let base = std::fs::canonicalize(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    let saved: Vec<LiveRecord> = shards.into_iter().map(|(_, _, s)| s).collect();
    let study = LiveRecord::join(&saved, &base);
    let scope = &saved[0].scope;
    let md = markdown(&study, scope);
    let (md_path, csv_path) = (out.join("live.md"), out.join("rows.csv"));
    write(&md_path, &md)?;
    write(&csv_path, &csv(&study))?;
    let mut written = vec![md_path, csv_path];
    for (name, plot) in figures(&study, scope) {
        // A figure that cannot be drawn is not a failed merge (as in the report).
        if let Ok(w) = crate::plot::write_png(&plot, &out.join(name)) {
            written.push(w.path);
        }
    }
    Ok(LiveMerge {
        shards: saved.len(),
        rows: study.rows.len(),
        items: saved[0].items,
        files,
        written,
        markdown: md,
        failures: Failures { list: study.failures.clone() },
    })
}
