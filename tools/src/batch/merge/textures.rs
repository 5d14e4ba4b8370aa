//! The merge of a texture report's shards (`evflow report textures --shard
//! K/N`): each shard saved its (profile, condition) cells' rows and models
//! ([`evflow_study::saved`]); the merge checks that the
//! shards are the N slices of one report, copies their files (models,
//! recordings, runs, spectra), joins the saved studies in study order with
//! every path put under the output folder, and writes textures.md and
//! rows.csv with the code `evflow report textures` uses. With `--no-times`
//! on the shards they are byte for byte one run's.

use super::error::MergeError;
use super::files::{copy_files, one_batch, write, Coverage};
use evflow_engine::batch::{Failures, Shard};
use evflow_study::run::StudyConfig;
use evflow_study::saved::{SavedStudy, RECORD};
use evflow_study::tables::textures::{csv, markdown, Timings};
use evflow_study::StudyError;
use std::path::{Path, PathBuf};

/// What a merge of a texture report's shards did. Steps that failed in the
/// shards are listed in `failures`; the merge itself still wrote the tables
/// of every row that was run.
#[derive(Debug)]
pub struct TexturesMerge {
    /// Shards merged.
    pub shards: usize,
    /// Rows over all shards.
    pub rows: usize,
    /// Steps of the whole report: every cell's models and every row.
    pub steps: usize,
    /// Files copied from the shards (models, recordings, runs, spectra).
    pub files: usize,
    /// The tables written (textures.md, rows.csv).
    pub tables: Vec<PathBuf>,
    /// The report's Markdown, as `evflow report textures` prints it.
    pub markdown: String,
    /// The steps that failed in the shards, labelled with their shard.
    pub failures: Failures,
}

/// Merges the shards of `evflow report textures --shard` in `dirs` (in any
/// order) into `out`.
pub fn merge_textures(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<TexturesMerge, MergeError> {
    let read = |d: &Path| -> Result<(Shard, SavedStudy), MergeError> {
        let saved = SavedStudy::read(d)?;
        let shard = saved.slice().map_err(|e| StudyError::Config(format!("{}: {e}", d.display())))?;
        Ok((shard, saved))
    };
    let shards = one_batch(
        dirs,
        read,
        |a, b| a.scope == b.scope && a.cells == b.cells,
        "the reports' settings: samples, conditions, profiles, gains, epochs, iterations, objective, floor, \
         multilevel or --no-times",
        coverage,
    )?;
    let folders: Vec<&Path> = shards.iter().map(|(d, _, _)| d.as_path()).collect();
    let files = copy_files(out, &folders, &[PathBuf::from(RECORD)])?;
    std::fs::create_dir_all(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    let base = std::fs::canonicalize(out).map_err(|source| MergeError::Create { dir: out.to_path_buf(), source })?;
    let saved: Vec<SavedStudy> = shards.into_iter().map(|(_, _, s)| s).collect();
    let study = SavedStudy::join(&saved, &base);
    let scope = &saved[0].scope;
    let cfg = StudyConfig::merged(scope.clone(), &base, Shard::ALL);
    let timings = if scope.times { Timings::Show } else { Timings::Leave };
    let md = markdown(&study, &cfg, timings);
    let (md_path, csv_path) = (out.join("textures.md"), out.join("rows.csv"));
    write(&md_path, &md)?;
    write(&csv_path, &csv(&study, timings))?;
    let failures = Failures { list: study.failures.clone() };
    let cells = saved[0].cells;
    Ok(TexturesMerge {
        shards: saved.len(),
        rows: study.rows.len(),
        steps: cells + cells * scope.samples.len(),
        files,
        tables: vec![md_path, csv_path],
        markdown: md,
        failures,
    })
}
