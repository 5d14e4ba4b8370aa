//! The shards of `evflow report narx --shard K/N`: each saved its items'
//! scores ([`evflow_study::narx::saved`]); merged ([`super::study`]) with
//! the models the shards trained into narx.md (and the figure, when times
//! were measured), with the code one run uses. With `--no-times` on the
//! shards narx.md is byte for byte that of one run.

use super::error::MergeError;
use super::files::write;
use super::study::{Slice, StudyMerge, StudyReport};
use crate::plot::write_png;
use evflow_engine::batch::Failures;
use evflow_study::narx::run::{aggregate, item_label, Item};
use evflow_study::narx::saved::NarxRecord;
use evflow_study::tables::narx::{figure, markdown, Table};
use std::path::Path;

/// The table `report narx` writes.
pub const NARX_TABLE: &str = "narx.md";

/// Its work-precision figure (written when times were measured).
pub const NARX_FIGURE: &str = "narx-work-precision.png";

/// `evflow report narx`, run in shards.
pub struct Narx;

impl StudyReport for Narx {
    type Record = NarxRecord;
    const SCRIPT: &'static str = "<the array's script, e.g. contrib/slurm/narx.sbatch>";
    const TABLES: &'static [&'static str] = &[NARX_TABLE, NARX_FIGURE];

    fn differs(a: &NarxRecord, b: &NarxRecord) -> Option<&'static str> {
        if a.scope != b.scope {
            return Some("the scopes of `report narx`");
        }
        let names = |r: &NarxRecord| r.left_out.iter().map(|t| t.0.clone()).collect::<Vec<_>>();
        (a.textures != b.textures || names(a) != names(b)).then_some("the textures scored")
    }

    fn tables(out: &Path, _base: &Path, shards: &[Slice<NarxRecord>], files: usize) -> Result<StudyMerge, MergeError> {
        let first = &shards[0].2;
        let a = &first.scope;
        let per_shard = shards.iter().map(|(_, _, r)| r.items()).collect::<Result<Vec<Vec<Item>>, _>>()?;
        let items: Vec<Item> = per_shard.iter().flatten().cloned().collect();
        let scored = aggregate(&a.settings, a.seeds, &items);
        let left_out: Vec<String> = first.left_out.iter().map(|(s, _)| s.clone()).collect();
        let md = markdown(&Table {
            condition: a.condition,
            textures: &first.textures,
            left_out: &left_out,
            gains: &a.gains,
            seeds: a.seeds,
            times: a.times,
            scored: &scored,
        });
        let table = out.join(NARX_TABLE);
        write(&table, &md)?;
        let (mut written, mut warnings) = (vec![format!("wrote {}", table.display())], Vec::new());
        if a.times {
            match write_png(&figure(&a.condition, &scored), &out.join(NARX_FIGURE)) {
                Ok(w) => written.push(format!(
                    "wrote {}{}",
                    w.path.display(),
                    if w.labelled { "" } else { " (no font found: unlabelled)" }
                )),
                Err(e) => warnings.push(e.to_string()),
            }
        }
        let mut failures = Failures::new();
        for (s, why) in &first.left_out {
            failures.push(format!("texture {s}"), why);
        }
        for ((_, shard, _), items) in shards.iter().zip(&per_shard) {
            for i in items {
                if let Err(why) = &i.score {
                    failures.push(format!("{} (shard {shard})", item_label(&a.settings, i)), why);
                }
            }
        }
        let scored = items.iter().filter(|i| i.score.is_ok()).count();
        Ok(StudyMerge {
            shards: shards.len(),
            markdown: String::new(),
            written,
            warnings,
            summary: format!(
                "merged {} shards of report narx: {scored} of {} models scored, {files} files copied",
                shards.len(),
                a.total()
            ),
            steps: a.samples.len() + a.total(),
            failures,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::files::Coverage;
    use super::super::study::merge_study;
    use super::*;
    use evflow_engine::batch::Shard;
    use evflow_study::narx::run::{NarxConfig, NarxStudy, SeedScore};
    use evflow_study::narx::saved::NARX_RECORD;
    use evflow_study::narx::scope::NarxScope;
    use evflow_study::narx::setting::Setting;
    use evflow_study::setup::Cond;
    use evflow_study::shard_file::StudyRecord;
    use std::path::PathBuf;

    /// Shard `shard` of 2 settings × 2 seeds, item 1 failed, felt-fabric left out.
    fn record(shard: Shard) -> (NarxRecord, Vec<Item>) {
        let scope = NarxScope {
            condition: Cond { mass: 60.0, speed: 0.1 + 0.2 },
            settings: ["a=5/1/10/lm", "b=3/1/5/adam"].iter().map(|s| Setting::parse(s).unwrap()).collect(),
            samples: vec!["plastic-sheet".into(), "felt-fabric".into()],
            gains: vec![1.0 / 3.0, 1.4],
            seeds: 2,
            epochs: 3,
            iterations: 3,
            times: false,
        };
        let cfg = NarxConfig { scope, graphs: "g".into(), out: "o".into(), work: "w".into(), jobs: 1, shard };
        let score = |index: usize| SeedScore {
            es: 1.0 / (index + 3) as f64,
            best: 5e-324,
            seconds: 0.0,
            epochs: 3,
            transitions: f64::NAN,
            weights: 86,
        };
        let items: Vec<Item> = cfg
            .range()
            .map(|index| Item {
                index,
                setting: index / 2,
                seed: (index % 2 + 1) as u32,
                score: if index == 1 { Err("it broke".into()) } else { Ok(score(index)) },
            })
            .collect();
        let study = NarxStudy {
            textures: vec!["plastic-sheet".into()],
            left_out: vec![("felt-fabric".into(), "no recording".into())],
            items: items.clone(),
            scored: Vec::new(),
            failures: Vec::new(),
        };
        (NarxRecord::of(&study, &cfg), items)
    }

    /// The three shards of the test record, written into `base/s1..s3`,
    /// each with the models it trained.
    fn three_shards(base: &Path) -> Vec<PathBuf> {
        (1..=3)
            .map(|k| {
                let dir = base.join(format!("s{k}"));
                let (r, _) = record(Shard { k, n: 3 });
                for i in &r.items {
                    let d = dir.join(format!("models/{}/seed-{}", i.setting, i.seed));
                    std::fs::create_dir_all(&d).unwrap();
                    std::fs::write(d.join("model.json"), format!("{}", i.index)).unwrap();
                }
                r.write(&dir).unwrap();
                dir
            })
            .collect()
    }

    #[test]
    fn shards_merge_into_the_table_of_one_run() {
        let base = tempfile::tempdir().unwrap();
        let mut dirs = three_shards(base.path());
        dirs.swap(0, 2);
        let out = base.path().join("out");
        let m = merge_study::<Narx>(&out, &dirs, Coverage::All).unwrap();
        let (all, items) = record(Shard::ALL);
        let a = &all.scope;
        let scored = aggregate(&a.settings, a.seeds, &items);
        let one = markdown(&Table {
            condition: a.condition,
            textures: &all.textures,
            left_out: &["felt-fabric".into()],
            gains: &a.gains,
            seeds: a.seeds,
            times: false,
            scored: &scored,
        });
        assert_eq!(std::fs::read_to_string(out.join(NARX_TABLE)).unwrap(), one);
        assert_eq!(m.shards, 3);
        assert_eq!(m.summary, "merged 3 shards of report narx: 3 of 4 models scored, 4 files copied");
        assert!(m.written.len() == 1 && !out.join(NARX_RECORD).exists());
        assert_eq!(std::fs::read_to_string(out.join("models/b/seed-2/model.json")).unwrap(), "3");
        let labels: Vec<&str> = m.failures.list.iter().map(|(l, _)| l.as_str()).collect();
        assert_eq!(labels, ["texture felt-fabric", "a, seed 2 (shard 1/3)"]);
    }

    #[test]
    fn shards_of_other_reports_or_missing_are_refused_by_name() {
        let base = tempfile::tempdir().unwrap();
        let dirs = three_shards(base.path());
        let out = base.path().join("out");
        let e = merge_study::<Narx>(&out, &dirs[..2], Coverage::All).unwrap_err();
        assert_eq!(e.to_string(), "shards missing: 3/3 (given 2 of 3)");
        let mut other = NarxRecord::read(&dirs[2]).unwrap();
        other.scope.epochs = 4;
        other.write(&dirs[2]).unwrap();
        let e = merge_study::<Narx>(&out, &dirs, Coverage::All).unwrap_err();
        let (d0, d2) = (dirs[0].display(), dirs[2].display());
        assert_eq!(
            e.to_string(),
            format!("{d0} and {d2}: not shards of one batch (the scopes of `report narx` differ)")
        );
        other.scope.epochs = 3;
        other.items.clear();
        other.write(&dirs[2]).unwrap();
        let e = merge_study::<Narx>(&out, &dirs, Coverage::All).unwrap_err();
        let record = dirs[2].join(NARX_RECORD);
        assert_eq!(e.to_string(), format!("{}: the items are not items 3..4 in order", record.display()));
        assert!(!out.exists(), "a refused merge wrote {}", out.display());
        let sweep = base.path().join("sweep");
        std::fs::create_dir_all(&sweep).unwrap();
        let e = merge_study::<Narx>(&out, &[dirs[0].clone(), sweep.clone()], Coverage::All).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: not a shard of `evflow report narx` as {d0} is (it holds no narx-shard.json)",
                sweep.display()
            )
        );
    }
}
