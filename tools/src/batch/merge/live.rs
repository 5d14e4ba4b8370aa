//! The live report's shards (`evflow report live --shard K/N`): each saved
//! the rows of its slice of the (profile, sample, user) items
//! ([`evflow_study::live::saved`]); merged ([`super::study`]) in item order
//! into live.md, rows.csv and the figures, with the code `evflow report
//! live` uses — one run's, byte for byte.

use super::error::MergeError;
use super::files::write;
use super::study::{Slice, StudyMerge, StudyReport};
use evflow_engine::batch::Failures;
use evflow_study::live::saved::LiveRecord;
use evflow_study::tables::live::{csv, figures, markdown};
use std::path::Path;

/// `evflow report live`, run in shards.
pub struct Live;

impl StudyReport for Live {
    type Record = LiveRecord;
    const SCRIPT: &'static str = "<the array's script, e.g. contrib/slurm/live.sbatch>";

    fn differs(a: &LiveRecord, b: &LiveRecord) -> Option<&'static str> {
        (a.scope != b.scope || a.items != b.items).then_some(
            "the reports' settings: profiles, samples, users, gains, grid, epochs, iterations, seconds, floor or the \
             live synthesis' settings",
        )
    }

    fn tables(out: &Path, base: &Path, shards: &[Slice<LiveRecord>], files: usize) -> Result<StudyMerge, MergeError> {
        let first = &shards[0].2;
        let study = LiveRecord::join(shards.iter().map(|(_, _, s)| s), base);
        let scope = &first.scope;
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
        let items = first.items;
        Ok(StudyMerge {
            shards: shards.len(),
            markdown: md,
            written: written.iter().map(|p| format!("wrote {}", p.display())).collect(),
            warnings: Vec::new(),
            summary: format!(
                "merged {} shards of a live report: {} rows of {items} items, {files} files the shards wrote",
                shards.len(),
                study.rows.len()
            ),
            steps: items,
            failures: Failures { list: study.failures },
        })
    }
}
