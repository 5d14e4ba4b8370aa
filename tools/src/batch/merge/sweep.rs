//! The merge of a sweep's shards (`evflow run --shard K/N`): the runs'
//! files copied, the CSV and JSON tables written from every run in sweep
//! order with the code `evflow run` uses.

use super::error::MergeError;
use super::files::{copy_files, k_order, write, Coverage};
use crate::batch::shard_record::{ShardRecord, RECORD};
use crate::batch::tables::{report_json, sweep_csv};
use evflow_engine::batch::Failures;
use std::path::{Path, PathBuf};

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
    /// The graph's plots of the whole sweep, drawn from every run: lines for
    /// people (files written, fits), and why a plot could not be drawn.
    pub plots: (Vec<String>, Vec<String>),
}
/// Merges the shards of a sweep (`evflow run --shard`) in `dirs` into
/// `out`: every K of N, or those there are ([`Coverage`]).
pub fn merge_sweep(out: &Path, dirs: &[PathBuf], coverage: Coverage) -> Result<SweepMerge, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::NoShards);
    }
    let shards = dirs.iter().map(|d| Ok((d.clone(), ShardRecord::read(d)?))).collect::<Result<Vec<_>, MergeError>>()?;
    let shards = in_order(shards, coverage)?;
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
    // A plot of the whole sweep is drawn here, from every run (the shards
    // draw none), as `evflow run` draws it.
    let plots = match evflow_engine::read_graph(Path::new(&first.graph)) {
        Ok(g) if !g.plots.is_empty() => crate::batch::sweep_plots::draw_plots(&g, &runs, &first.sets, out),
        Ok(_) => (Vec::new(), Vec::new()),
        Err(e) => (Vec::new(), vec![format!("the plots of {} are not drawn: {e}", first.graph)]),
    };
    Ok(SweepMerge {
        plots,
        shards: shards.len(),
        graph: first.graph,
        runs: runs.len(),
        total: first.total,
        files,
        tables,
        failures,
    })
}
/// The shards in K order, checked to be the N slices of one sweep (or
/// some of them, with [`Coverage::Partial`]).
fn in_order(
    mut shards: Vec<(PathBuf, ShardRecord)>,
    coverage: Coverage,
) -> Result<Vec<(PathBuf, ShardRecord)>, MergeError> {
    shards.sort_by_key(|(_, r)| r.shard.k);
    let (first_dir, first) = &shards[0];
    let n = first.shard.n;
    for (dir, r) in &shards {
        let differs =
            |what: &'static str| MergeError::NotOneBatch { first: first_dir.clone(), other: dir.clone(), what };
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
    let shards = k_order(shards.into_iter().map(|(d, r)| (d, r.shard, r)).collect(), coverage)?;
    Ok(shards.into_iter().map(|(d, _, r)| (d, r)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::shard_record::tests::{record, run};
    use crate::batch::tables::Timings;
    use evflow_engine::batch::Shard;

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
        let m = merge_sweep(&out, &dirs, Coverage::All).unwrap();
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
        let e = merge_sweep(&out, &dirs[..2], Coverage::All).unwrap_err();
        assert_eq!(e.to_string(), "shards missing: 3/3 (given 2 of 3)");
        let e = merge_sweep(&out, &[dirs[0].clone(), dirs[1].clone(), dirs[1].clone(), dirs[2].clone()], Coverage::All)
            .unwrap_err();
        assert_eq!(e.to_string(), format!("{} and {}: both are shard 2/3", dirs[1].display(), dirs[1].display()));
        assert!(matches!(merge_sweep(&out, &[], Coverage::All), Err(MergeError::NoShards)));

        let mut other = ShardRecord::read(&dirs[2]).unwrap();
        other.graph = "graphs/other.toml".into();
        other.write(&dirs[2]).unwrap();
        let e = merge_sweep(&out, &dirs, Coverage::All).unwrap_err();
        let (d0, d2) = (dirs[0].display(), dirs[2].display());
        assert_eq!(e.to_string(), format!("{d0} and {d2}: not shards of one batch (the graphs differ)"));

        let mut other = ShardRecord::read(&dirs[2]).unwrap();
        other.graph = "graphs/g.toml".into();
        other.range = 0..1;
        other.write(&dirs[2]).unwrap();
        let e = merge_sweep(&out, &dirs, Coverage::All).unwrap_err();
        assert_eq!(e.to_string(), format!("{d2}: shard 3/3 should hold runs 4..5 of 5"));
        assert!(!out.exists(), "a refused merge wrote {}", out.display());
    }

    #[test]
    fn two_shards_writing_one_name_must_agree() {
        let base = tempfile::tempdir().unwrap();
        let dirs = three_shards(base.path());
        std::fs::write(dirs[1].join("common.txt"), "differs").unwrap();
        let e = merge_sweep(&base.path().join("out"), &dirs, Coverage::All).unwrap_err();
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
