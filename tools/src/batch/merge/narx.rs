//! Joins the shards of `evflow report narx --shard K/N` into what one run
//! would have written (`evflow merge`): the models the shards trained, and
//! narx.md (and the figure, when times were measured) from every shard's
//! items, with the code one run uses. With `--no-times` on the shards
//! narx.md is byte for byte that of one run.

use super::error::MergeError;
use super::files::{copy_files, k_order, write};
use crate::batch::narx_shard::{NarxRecord, NARX_RECORD};
use crate::plot::{write_png, PlotError, Written};
use evflow_engine::batch::Failures;
use evflow_study::narx_settings::{aggregate, item_label};
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
pub fn merge_narx(out: &Path, dirs: &[PathBuf]) -> Result<NarxMerge, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    // A folder of another kind of shard among them: named, not "cannot read".
    if let (Some(narx), Some(other)) = (dirs.iter().find(|d| is_narx_shard(d)), dirs.iter().find(|d| !is_narx_shard(d)))
    {
        return Err(MergeError::NotNarx { dir: other.clone(), narx: narx.clone() });
    }
    let mut shards =
        dirs.iter().map(|d| Ok((d.clone(), NarxRecord::read(d)?))).collect::<Result<Vec<_>, MergeError>>()?;
    shards.sort_by_key(|(_, r)| r.shard.k);
    let (first_dir, first) = &shards[0];
    for (dir, r) in &shards {
        let differs =
            |what: &'static str| MergeError::NotOneBatch { first: first_dir.clone(), other: dir.clone(), what };
        if r.shard.n != first.shard.n {
            return Err(differs("the shard counts N"));
        }
        if r.arguments != first.arguments {
            return Err(differs("the arguments of `report narx`"));
        }
        if r.textures != first.textures || r.left_out.iter().map(|t| &t.0).ne(first.left_out.iter().map(|t| &t.0)) {
            return Err(differs("the textures scored"));
        }
        let total = r.arguments.total();
        let expected = r.shard.range(total);
        if !r.items.iter().map(|i| i.index).eq(expected.clone()) {
            return Err(MergeError::WrongRange { dir: dir.clone(), shard: r.shard, expected, total });
        }
    }
    let shards = k_order(shards.into_iter().map(|(d, r)| (d, r.shard, r)).collect())?;
    let folders: Vec<&Path> = shards.iter().map(|(d, _, _)| d.as_path()).collect();
    let skip = [NARX_RECORD, NARX_TABLE, NARX_FIGURE].map(PathBuf::from);
    let files = copy_files(out, &folders, &skip)?;
    let first = &shards[0].2;
    let a = &first.arguments;
    let items: Vec<_> = shards.iter().flat_map(|(_, _, r)| r.items.iter().cloned()).collect();
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
    for (_, shard, r) in &shards {
        for i in &r.items {
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
    use crate::batch::narx_shard::tests::record;
    use evflow_engine::batch::Shard;

    /// The three shards of the test record, written into `base/s1..s3`,
    /// each with the models it trained.
    fn three_shards(base: &Path) -> Vec<PathBuf> {
        (1..=3)
            .map(|k| {
                let shard = Shard { k, n: 3 };
                let dir = base.join(format!("s{k}"));
                let r = record(shard);
                for i in &r.items {
                    let d = dir.join(format!("models/{}/seed-{}", r.arguments.settings[i.setting].name, i.seed));
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
        let m = merge_narx(&out, &dirs).unwrap();
        let all = record(Shard::ALL);
        let a = &all.arguments;
        let scored = aggregate(&a.settings, a.seeds, &all.items);
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
        let e = merge_narx(&out, &dirs[..2]).unwrap_err();
        assert_eq!(e.to_string(), "shards missing: 3/3 (given 2 of 3)");
        let mut other = NarxRecord::read(&dirs[2]).unwrap();
        other.arguments.epochs = 4;
        other.write(&dirs[2]).unwrap();
        let e = merge_narx(&out, &dirs).unwrap_err();
        let (d0, d2) = (dirs[0].display(), dirs[2].display());
        assert_eq!(
            e.to_string(),
            format!("{d0} and {d2}: not shards of one batch (the arguments of `report narx` differ)")
        );
        other.arguments.epochs = 3;
        other.items.clear();
        other.write(&dirs[2]).unwrap();
        let e = merge_narx(&out, &dirs).unwrap_err();
        assert_eq!(e.to_string(), format!("{d2}: shard 3/3 should hold runs 3..4 of 4"));
        assert!(!out.exists(), "a refused merge wrote {}", out.display());
        let sweep = base.path().join("sweep");
        std::fs::create_dir_all(&sweep).unwrap();
        let e = merge_narx(&out, &[dirs[0].clone(), sweep.clone()]).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: not a shard of `evflow report narx` as {d0} is (it holds no narx-shard.json)",
                sweep.display()
            )
        );
    }
}
