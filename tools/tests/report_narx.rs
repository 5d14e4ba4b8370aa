//! `evflow report narx` end to end on tiny sizes (3 epochs, one texture,
//! one gain): a failing setting does not lose the others and is listed
//! with its reason and a failing exit code; shards merged by `evflow merge`
//! give the table of one run byte for byte.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow(args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `report narx` on `settings` (2 seeds each) into `out`, with `extra` arguments.
fn report(out: &Path, settings: &str, extra: &[&str]) -> (bool, String, String) {
    let mut args = vec![
        "report",
        "narx",
        "--out",
        out.to_str().unwrap(),
        "--epochs",
        "3",
        "--iterations",
        "3",
        "--gains",
        "1.0",
        "--seeds",
        "2",
        "--samples",
        "plastic-sheet",
        "--settings",
        settings,
    ];
    args.extend_from_slice(extra);
    evflow(&args)
}

fn rows(md: &str) -> Vec<&str> {
    md.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| setting")).collect()
}

#[test]
fn a_setting_the_trainer_refuses_is_listed_and_the_others_are_scored() {
    // 1000 input taps make a network of 5036 weights, more than the 3066
    // samples of graphs/model-build.toml can train: narx.train refuses it.
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = report(dir.path(), "a=5/1/10/lm,broken=5/1/1000/lm,b=3/1/5/adam", &[]);
    assert!(!ok, "a failed setting must fail the command: {out}{err}");
    let md = std::fs::read_to_string(dir.path().join("narx.md")).unwrap_or_else(|e| panic!("{e}: {out}{err}"));
    let r = rows(&md);
    assert_eq!(r.len(), 3, "{md}");
    assert!(r[0].starts_with("| a | 5, k_y 1, k_x 10, LM | 2 of 2 | 86 | "), "{md}");
    assert_eq!(r[1], "| broken | 5, k_y 1, k_x 1000, LM | 0 of 2 | – | – | – | – | – | – | – | – |");
    assert!(r[2].starts_with("| b | 3, k_y 1, k_x 5, ADAM | 2 of 2 | 37 | "), "{md}");
    // The scored settings have numbers, and one of them is on the front.
    let es: f64 = r[0].split('|').nth(8).unwrap().trim().parse().unwrap_or_else(|_| panic!("{md}"));
    assert!(es > 0.0 && es.is_finite(), "{md}");
    assert!(r[0].ends_with("| yes |") || r[2].ends_with("| yes |"), "{md}");
    assert!(dir.path().join("narx-work-precision.png").is_file() || err.contains("warning"), "{out}{err}");
    assert!(err.contains("2 of 7 steps failed:"), "{err}");
    for seed in [1, 2] {
        let line =
            err.lines().find(|l| l.starts_with(&format!("  broken, seed {seed}: "))).unwrap_or_else(|| panic!("{err}"));
        assert!(line.contains("model-build.toml") && line.contains("the recording is too short"), "{line}");
    }
    assert!(!err.contains("  a, seed") && !err.contains("  b, seed"), "{err}");
}

/// Every file under `dir`, relative, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        for e in std::fs::read_dir(dir.join(&rel)).unwrap() {
            let e = e.unwrap();
            let p = rel.join(e.file_name());
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn shards_merged_out_of_order_give_the_table_of_one_run() {
    let base = tempfile::tempdir().unwrap();
    let settings = "a=5/1/10/lm,b=3/1/5/adam";
    let one = base.path().join("one");
    let (ok, out, err) = report(&one, settings, &["--no-times"]);
    assert!(ok, "{out}{err}");
    assert!(!one.join("narx-work-precision.png").exists(), "--no-times plots no training times");
    let shards: Vec<PathBuf> = (1..=3).map(|k| base.path().join(format!("s{k}"))).collect();
    for (k, dir) in shards.iter().enumerate() {
        let shard = format!("{}/3", k + 1);
        let (ok, out, err) = report(dir, settings, &["--no-times", "--shard", &shard, "--jobs", "2"]);
        assert!(ok, "{out}{err}");
        assert!(out.contains("evflow merge") && !dir.join("narx.md").exists(), "{out}");
        assert!(dir.join("narx-shard.json").is_file());
    }
    let merged = base.path().join("merged");
    let m = |dirs: &[&PathBuf]| {
        let mut args = vec!["merge", merged.to_str().unwrap()];
        args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
        evflow(&args)
    };
    // A missing shard is refused by name, before anything is written.
    let (ok, _, err) = m(&[&shards[2], &shards[0]]);
    assert!(!ok && err.contains("shards missing: 2/3 (given 2 of 3)"), "{err}");
    assert!(!merged.exists());
    let (ok, out, err) = m(&[&shards[2], &shards[0], &shards[1]]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("merged 3 shards of report narx: 4 of 4 models scored"), "{out}");
    let table = std::fs::read_to_string(merged.join("narx.md")).unwrap();
    assert_eq!(table, std::fs::read_to_string(one.join("narx.md")).unwrap());
    assert_eq!(rows(&table).len(), 2, "{table}");
    // The settings' models as one run trains them (the default models
    // under models/base record their build time, so only their names agree).
    let (a, b) = (files(&one), files(&merged));
    assert_eq!(a, b);
    for f in a.iter().filter(|f| !f.starts_with("models/base")) {
        assert_eq!(std::fs::read(one.join(f)).unwrap(), std::fs::read(merged.join(f)).unwrap(), "{}", f.display());
    }
}
