//! The texture report's shards (`evflow report textures --shard K/N`): each
//! saved its (profile, condition) cells' rows and models
//! ([`evflow_study::saved`]); merged ([`super::study`]) with every path put
//! under the output folder into textures.md and rows.csv, with the code
//! `evflow report textures` uses. With `--no-times` on the shards they are
//! byte for byte one run's.

use super::error::MergeError;
use super::files::write;
use super::study::{Slice, StudyMerge, StudyReport};
use evflow_engine::batch::{Failures, Shard};
use evflow_study::run::StudyConfig;
use evflow_study::saved::SavedStudy;
use evflow_study::tables::textures::{csv, markdown, Timings};
use std::path::Path;

/// `evflow report textures`, run in shards.
pub struct Textures;

impl StudyReport for Textures {
    type Record = SavedStudy;
    const SCRIPT: &'static str = "<the array's script, e.g. contrib/slurm/textures.sbatch>";

    fn differs(a: &SavedStudy, b: &SavedStudy) -> Option<&'static str> {
        (a.scope != b.scope || a.cells != b.cells).then_some(
            "the reports' settings: samples, conditions, profiles, gains, epochs, iterations, objective, floor, \
             multilevel or --no-times",
        )
    }

    fn tables(out: &Path, base: &Path, shards: &[Slice<SavedStudy>], files: usize) -> Result<StudyMerge, MergeError> {
        let first = &shards[0].2;
        let study = SavedStudy::join(shards.iter().map(|(_, _, s)| s), base);
        let scope = &first.scope;
        let cfg = StudyConfig::merged(scope.clone(), base, Shard::ALL);
        let timings = if scope.times { Timings::Show } else { Timings::Leave };
        let md = markdown(&study, &cfg, timings);
        let (md_path, csv_path) = (out.join("textures.md"), out.join("rows.csv"));
        write(&md_path, &md)?;
        write(&csv_path, &csv(&study, timings))?;
        let cells = first.cells;
        Ok(StudyMerge {
            shards: shards.len(),
            markdown: md,
            written: [md_path, csv_path].iter().map(|p| format!("wrote {}", p.display())).collect(),
            warnings: Vec::new(),
            summary: format!(
                "merged {} shards of a texture report: {} rows, {files} files the shards wrote",
                shards.len(),
                study.rows.len()
            ),
            steps: cells + cells * scope.samples.len(),
            failures: Failures { list: study.failures },
        })
    }
}
