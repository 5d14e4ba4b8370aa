//! `evflow report narx` end to end on tiny sizes (3 epochs, one texture,
//! one gain): a failing setting does not lose the others and is listed
//! with its reason and a failing exit code; a texture whose recording fails
//! is left out of every score; shards merged by `evflow merge` give the
//! table of one run byte for byte.
#![cfg(feature = "synth")]

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
    // Every model as one run trains it, the default models under
    // models/base too (with --no-times no file records a training time).
    let (a, b) = (files(&one), files(&merged));
    assert_eq!(a, b);
    assert!(a.iter().any(|f| f.starts_with("models/base")), "{a:?}");
    for f in &a {
        assert_eq!(std::fs::read(one.join(f)).unwrap(), std::fs::read(merged.join(f)).unwrap(), "{}", f.display());
    }
}

/// The study as the library runs it: setting `a` (5 hidden, taps 1/10, LM)
/// with 2 seeds at 60 g, 5 cm/s on `samples`, in `work`.
fn study(samples: &[&str], out: &Path, work: &Path) -> Result<evflow_study::narx::run::NarxStudy, String> {
    use evflow_study::narx::run::{run, NarxConfig};
    use evflow_study::narx::scope::NarxScope;
    use evflow_study::narx::setting::Setting;
    use evflow_study::setup::Cond;
    let scope = NarxScope {
        condition: Cond { mass: 60.0, speed: 5.0 },
        settings: vec![Setting::parse("a=5/1/10/lm").unwrap()],
        samples: samples.iter().map(|s| s.to_string()).collect(),
        gains: vec![1.0],
        seeds: 2,
        epochs: 3,
        iterations: 3,
        times: false,
    };
    let cfg = NarxConfig {
        scope,
        graphs: root().join("graphs"),
        out: out.to_path_buf(),
        work: work.to_path_buf(),
        jobs: 2,
        shard: evflow_engine::batch::Shard::ALL,
    };
    run(&cfg, &mut |_| {}).map_err(|e| e.to_string())
}

#[test]
fn a_texture_whose_recording_fails_is_left_out_of_every_score() {
    // The recording of the felt fabric cannot be written: a folder holds its name.
    let base = tempfile::tempdir().unwrap();
    let work = base.path().join("work");
    let blocked = work.join("textures").join("felt-fabric-60g-5cms-r1.wav");
    std::fs::create_dir_all(&blocked).unwrap();
    let s = study(&["felt-fabric", "plastic-sheet"], &base.path().join("out"), &work).unwrap();
    assert_eq!(s.textures, ["plastic-sheet"]);
    assert_eq!(s.left_out.len(), 1);
    assert_eq!(s.left_out[0].0, "felt-fabric");
    assert!(s.left_out[0].1.contains("felt-fabric-60g-5cms-r1"), "{}", s.left_out[0].1);
    let labels: Vec<&str> = s.failures.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["texture felt-fabric"]);
    // The scores are those of a study of the plastic sheet alone, bit for bit.
    let alone = study(&["plastic-sheet"], &base.path().join("out-alone"), &base.path().join("work-alone")).unwrap();
    assert_eq!(s.items, alone.items);
    assert!(s.items.iter().all(|i| i.score.is_ok()));
    assert_eq!(s.scored[0].seeds, 2);
    assert_eq!(s.scored[0].es.to_bits(), alone.scored[0].es.to_bits());

    // With every texture left out nothing can be scored: an error naming each.
    let work = base.path().join("work-none");
    std::fs::create_dir_all(work.join("textures").join("felt-fabric-60g-5cms-r1.wav")).unwrap();
    let e = study(&["felt-fabric"], &base.path().join("out-none"), &work).unwrap_err();
    assert!(e.starts_with("every texture failed:\nfelt-fabric: "), "{e}");
}
