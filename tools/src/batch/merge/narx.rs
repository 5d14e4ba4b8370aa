//! Joins the shards of `evflow report narx --shard K/N` into what one run
//! would have written (`evflow merge`): the models the shards trained, and
//! narx.md (and the figure, when times were measured) from every shard's
//! items, with the code one run uses. With `--no-times` on the shards
//! narx.md is byte for byte that of one run.

use super::error::MergeError;
use super::files::{copy_files, k_order, write, Coverage};
use crate::plot::{write_png, PlotError, Written};
use evflow_engine::batch::Failures;
use evflow_study::narx::run::{aggregate, item_label, Item};
use evflow_study::narx::saved::{NarxRecord, NARX_RECORD};
use evflow_study::tables::narx::{figure, markdown, Table};
use std::path::{Path, PathBuf};

/// The name of the table in the output folder.
pub const NARX_TABLE: &str = "narx.md";

/// The name of the figure in the output folder.
pub const NARX_FIGURE: &str = "narx-work-precision.png";

/// What a merge of `report narx` shards did.
#[derive(Debug)]
pub struct NarxMerge {
    /// Shards merged.
    pub shards: usize,
    /// Items scored, over all shards.
    pub scored: usize,
    /// Items in the whole report.
    pub total: usize,
    /// Texture samples of the report (each a step before the items).
    pub samples: usize,
    /// Files copied (the models).
    pub files: usize,
    /// The table written.
    pub table: PathBuf,
    /// The figure (only when the shards measured training times).
    pub figure: Option<Result<Written, PlotError>>,
    /// The textures left out and the items that failed, with why.
    pub failures: Failures,
}

/// Whether `dir` is the output folder of a shard of `report narx`.
pub fn is_narx_shard(dir: &Path) -> bool {
    dir.join(NARX_RECORD).is_file()
}

/// Merges the shards of `evflow report narx --shard` in `dirs` (any order) into `out`.
pub fn merge_narx(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<NarxMerge, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    // A folder of another kind of shard among them: named, not "cannot read".
    if let (Some(narx), Some(other)) = (dirs.iter().find(|d| is_narx_shard(d)), dirs.iter().find(|d| !is_narx_shard(d)))
    {
        return Err(MergeError::NotNarx { dir: other.clone(), narx: narx.clone() });
    }
    // Each record is read checked: its items are its K/N's slice, of its scope's settings.
    let mut shards = dirs
        .iter()
        .map(|d| {
            let r = NarxRecord::read(d)?;
            let shard = r.slice().map_err(|e| evflow_study::StudyError::Config(e.to_string()))?;
            let items = r.items()?;
            Ok((d.clone(), shard, r, items))
        })
        .collect::<Result<Vec<_>, MergeError>>()?;
    shards.sort_by_key(|(_, s, _, _)| s.k);
    let (first_dir, first_shard, first, _) = &shards[0];
    for (dir, shard, r, _) in &shards {
        let differs =
            |what: &'static str| MergeError::NotOneBatch { first: first_dir.clone(), other: dir.clone(), what };
        if shard.n != first_shard.n {
            return Err(differs("the shard counts N"));
        }
        if r.scope != first.scope {
            return Err(differs("the scopes of `report narx`"));
        }
        if r.textures != first.textures || r.left_out.iter().map(|t| &t.0).ne(first.left_out.iter().map(|t| &t.0)) {
            return Err(differs("the textures scored"));
        }
    }
    let shards = k_order(shards.into_iter().map(|(d, s, r, items)| (d, s, (r, items))).collect(), coverage)?;
    let folders: Vec<&Path> = shards.iter().map(|(d, _, _)| d.as_path()).collect();
    let skip = [NARX_RECORD, NARX_TABLE, NARX_FIGURE].map(PathBuf::from);
    let files = copy_files(out, &folders, &skip)?;
    let first = &shards[0].2 .0;
    let a = &first.scope;
    let items: Vec<Item> = shards.iter().flat_map(|(_, _, (_, items))| items.iter().cloned()).collect();
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
    let figure = a.times.then(|| write_png(&figure(&a.condition, &scored), &out.join(NARX_FIGURE)));
    let mut failures = Failures::new();
    for (s, why) in &first.left_out {
        failures.push(format!("texture {s}"), why);
    }
    for (_, shard, (_, items)) in &shards {
        for i in items {
            if let Err(why) = &i.score {
                failures.push(format!("{} (shard {shard})", item_label(&a.settings, i)), why);
            }
        }
    }
    Ok(NarxMerge {
        shards: shards.len(),
        scored: items.iter().filter(|i| i.score.is_ok()).count(),
        total: a.total(),
        samples: a.samples.len(),
        files,
        table,
        figure,
        failures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::batch::Shard;
    use evflow_study::narx::run::{NarxConfig, NarxStudy, SeedScore};
    use evflow_study::narx::scope::NarxScope;
    use evflow_study::narx::setting::Setting;
    use evflow_study::setup::Cond;

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
        let m = merge_narx(&out, &dirs, Coverage::All).unwrap();
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
        assert_eq!((m.shards, m.scored, m.total, m.files), (3, 3, 4, 4));
        assert!(m.figure.is_none() && !out.join(NARX_RECORD).exists());
        assert_eq!(std::fs::read_to_string(out.join("models/b/seed-2/model.json")).unwrap(), "3");
        let labels: Vec<&str> = m.failures.list.iter().map(|(l, _)| l.as_str()).collect();
        assert_eq!(labels, ["texture felt-fabric", "a, seed 2 (shard 1/3)"]);
    }

    #[test]
    fn shards_of_other_reports_or_missing_are_refused_by_name() {
        let base = tempfile::tempdir().unwrap();
        let dirs = three_shards(base.path());
        let out = base.path().join("out");
        let e = merge_narx(&out, &dirs[..2], Coverage::All).unwrap_err();
        assert_eq!(e.to_string(), "shards missing: 3/3 (given 2 of 3)");
        let mut other = NarxRecord::read(&dirs[2]).unwrap();
        other.scope.epochs = 4;
        other.write(&dirs[2]).unwrap();
        let e = merge_narx(&out, &dirs, Coverage::All).unwrap_err();
        let (d0, d2) = (dirs[0].display(), dirs[2].display());
        assert_eq!(
            e.to_string(),
            format!("{d0} and {d2}: not shards of one batch (the scopes of `report narx` differ)")
        );
        other.scope.epochs = 3;
        other.items.clear();
        other.write(&dirs[2]).unwrap();
        let e = merge_narx(&out, &dirs, Coverage::All).unwrap_err();
        let record = dirs[2].join(NARX_RECORD);
        assert_eq!(e.to_string(), format!("{}: the items are not items 3..4 in order", record.display()));
        assert!(!out.exists(), "a refused merge wrote {}", out.display());
        let sweep = base.path().join("sweep");
        std::fs::create_dir_all(&sweep).unwrap();
        let e = merge_narx(&out, &[dirs[0].clone(), sweep.clone()], Coverage::All).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: not a shard of `evflow report narx` as {d0} is (it holds no narx-shard.json)",
                sweep.display()
            )
        );
    }
}
