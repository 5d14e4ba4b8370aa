//! Tests of `recording.out`: whole graphs (harness feeds → the sink) run by
//! the offline driver, and the files read back.

use super::SPEC;
use crate::recording::format::Recording;
use evflow_engine::harness::{Single, FEED};
use evflow_engine::params::toml_float;
use evflow_engine::run::RunError;
use evflow_engine::{check, graph::parse_graph, run_offline, Plan, PlanOptions, Registry, RunOptions, RunReport};
use std::path::Path;

/// Two awkward signals: extremes of f64, subnormals, negative zero.
fn signals(n: usize) -> (Vec<f64>, Vec<f64>) {
    let specials = [f64::MAX, f64::MIN_POSITIVE, -0.0, 5e-324, -f64::MAX, 1.0 / 3.0];
    let a = (0..n).map(|i| if i < specials.len() { specials[i] } else { (i as f64 * 0.013).sin() * 0.7 }).collect();
    let b = (0..n).map(|i| (i as f64).ln_1p() - 3.0).collect();
    (a, b)
}

/// A graph file: one `harness.feed` per channel → `recording.out` named `rec`.
fn graph(rate: f64, chans: &[(&str, &[f64])], sink: &str) -> String {
    let names: Vec<String> = chans.iter().map(|(n, _)| format!("\"{n}\"")).collect();
    let mut g = format!("[graph]\nformat = 1\nname = \"t\"\nrate = {}\nconnections = [\n", toml_float(rate));
    for (n, _) in chans {
        g += &format!("  \"f_{n}.out -> rec.{n}\",\n");
    }
    g += &format!("]\n[nodes.rec]\ntype = \"recording.out\"\nchannels = [{}]\n{sink}\n", names.join(", "));
    for (n, v) in chans {
        let vals: Vec<String> = v.iter().map(|x| toml_float(*x)).collect();
        g += &format!(
            "[nodes.f_{n}]\ntype = \"harness.feed\"\nrate = {}\nvalues = [{}]\n",
            toml_float(rate),
            vals.join(",")
        );
    }
    g
}

fn plan(dir: &Path, doc: &str, block: usize) -> Result<Plan, String> {
    plan_for(dir, doc, block, false)
}

fn plan_for(dir: &Path, doc: &str, block: usize, check_only: bool) -> Result<Plan, String> {
    let mut reg = Registry::new();
    reg.add(&SPEC).add(&FEED);
    let g = parse_graph(&dir.join("g.toml"), doc).map_err(|d| d.to_string())?;
    let checked = check(&g, &reg, &[]).map_err(|d| d.to_string())?;
    let opts = PlanOptions {
        max_block: block,
        seed: None,
        base_dir: Some(dir.to_path_buf()),
        out_dir: Some(dir.to_path_buf()),
        timing: false,
        mode: evflow_engine::RunMode::Offline,
        check_only,
    };
    Plan::build(&checked, &opts).map_err(|e| e.to_string())
}

fn run(dir: &Path, doc: &str, block: usize) -> Result<RunReport, String> {
    let mut p = plan(dir, doc, block)?;
    run_offline(&mut p, RunOptions::default()).map_err(|e| e.to_string())
}

/// Names of the files in `dir` other than the graph.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "g.toml")
        .collect();
    v.sort();
    v
}

#[test]
fn feed_to_file_round_trips_bit_exact_with_metadata_and_summary() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = signals(3066);
    let doc = graph(
        1000.0,
        &[("force", &a), ("pos", &b)],
        "path = \"out.wav\"\nunits = [\"N\", \"m\"]\nload_g = 85.0\nvelocity_cm_s = 4.0\nmaterial = \"felt\"\ngain = 1.0",
    );
    let report = run(dir.path(), &doc, 256).unwrap();
    let (_, summary) = report.summaries.iter().find(|(n, _)| n == "rec").unwrap();
    assert_eq!(summary.lines, vec!["wrote out.wav (3066 frames, 2 channels, 1000 Hz)".to_string()]);
    assert_eq!(report.value("rec", "frames"), Some(3066.0));
    assert_eq!(files(dir.path()), ["out.json", "out.wav"]);

    let rec = Recording::open(&dir.path().join("out.wav")).unwrap();
    rec.require_complete().unwrap();
    assert_eq!(rec.frames(), 3066);
    assert_eq!(rec.rate(), 1000.0);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(rec.channel("force").unwrap()), bits(&a));
    assert_eq!(bits(rec.channel("pos").unwrap()), bits(&b));
    let m = rec.meta();
    assert_eq!(m.channels[0].unit, "N");
    assert_eq!(m.channels[1].unit, "m");
    assert_eq!(m.condition.load_g, Some(85.0));
    assert_eq!(m.condition.velocity_cm_s, Some(4.0));
    assert_eq!(m.condition.material.as_deref(), Some("felt"));
    assert_eq!(m.condition.gain, Some(1.0));
    assert_eq!(m.source, "evflow recording.out node `rec`");
}

#[test]
fn unset_condition_is_left_out_and_source_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let doc = graph(500.0, &[("force", &[1.0, 2.0])], "path = \"sub/r\"\nsource = \"bench rig 2\"");
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    run(dir.path(), &doc, 64).unwrap();
    let text = std::fs::read_to_string(dir.path().join("sub/r.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["condition"], serde_json::json!({}));
    assert_eq!(v["source"], "bench rig 2");
    assert_eq!(v["rate"], 500.0);
    assert_eq!(v["channels"], serde_json::json!([{"name": "force", "unit": ""}]));
}

#[test]
fn block_one_and_large_block_write_identical_bytes() {
    let (a, b) = signals(777);
    let doc = graph(1000.0, &[("x", &a), ("y", &b)], "path = \"o.wav\"");
    let d1 = tempfile::tempdir().unwrap();
    let d2 = tempfile::tempdir().unwrap();
    run(d1.path(), &doc, 1).unwrap();
    run(d2.path(), &doc, 4096).unwrap();
    for f in ["o.wav", "o.json"] {
        assert_eq!(std::fs::read(d1.path().join(f)).unwrap(), std::fs::read(d2.path().join(f)).unwrap(), "{f}");
    }
}

/// Writes a good recording at `dir/out` and returns its bytes.
fn existing(dir: &Path) -> (Vec<u8>, Vec<u8>) {
    run(dir, &graph(1000.0, &[("force", &[0.5, 0.25, 0.125])], "path = \"out\""), 16).unwrap();
    (std::fs::read(dir.join("out.wav")).unwrap(), std::fs::read(dir.join("out.json")).unwrap())
}

fn unchanged(dir: &Path, before: &(Vec<u8>, Vec<u8>)) {
    assert_eq!(files(dir), ["out.json", "out.wav"], "temporary files left or recording removed");
    assert_eq!(std::fs::read(dir.join("out.wav")).unwrap(), before.0);
    assert_eq!(std::fs::read(dir.join("out.json")).unwrap(), before.1);
}

#[test]
fn a_failing_run_leaves_no_file_and_keeps_the_old_recording() {
    let dir = tempfile::tempdir().unwrap();
    let before = existing(dir.path());
    // +Inf at frame 700 of channel `b`, after the buffer was written out once.
    let a = vec![0.1; 1000];
    let mut b = vec![0.2; 1000];
    b[700] = f64::INFINITY;
    let doc = graph(1000.0, &[("a", &a), ("b", &b)], "path = \"out.wav\"");
    let err = run(dir.path(), &doc, 100).unwrap_err();
    assert!(err.contains("out.wav: channel `b` frame 700 is +Inf"), "{err}");
    unchanged(dir.path(), &before);

    // Without an earlier recording, nothing at all is left.
    let empty = tempfile::tempdir().unwrap();
    run(empty.path(), &doc, 100).unwrap_err();
    assert!(files(empty.path()).is_empty(), "{:?}", files(empty.path()));
}

#[test]
fn a_dropped_or_interrupted_run_leaves_no_file_and_keeps_the_old_recording() {
    let dir = tempfile::tempdir().unwrap();
    let before = existing(dir.path());
    let (a, _) = signals(20_000);
    let doc = graph(1000.0, &[("force", &a)], "path = \"out.wav\"");

    // Dropped mid-run (e.g. a panic elsewhere or an early return).
    let mut p = plan(dir.path(), &doc, 1000).unwrap();
    for _ in 0..12 {
        p.step(1000).unwrap();
    }
    assert!(files(dir.path()).contains(&"out.wav.tmp".to_string()));
    drop(p);
    unchanged(dir.path(), &before);

    // Interrupted (Ctrl-C through the progress callback).
    let mut p = plan(dir.path(), &doc, 1000).unwrap();
    let mut stop = |done: u64, _: u64| done < 5000;
    let r = run_offline(&mut p, RunOptions { duration: None, progress: Some(&mut stop) });
    assert!(matches!(r, Err(RunError::Interrupted(5000))));
    drop(p);
    unchanged(dir.path(), &before);
}

#[test]
fn reset_empties_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let (a, _) = signals(10_000);
    let doc = graph(1000.0, &[("force", &a)], "path = \"r.wav\"");
    let mut p = plan(dir.path(), &doc, 1000).unwrap();
    for _ in 0..9 {
        p.step(1000).unwrap(); // 9000 frames, more than the writer buffers
    }
    p.reset();
    p.step(1000).unwrap();
    p.step(500).unwrap();
    p.finish().unwrap();
    let rec = Recording::open(&dir.path().join("r.wav")).unwrap();
    rec.require_complete().unwrap();
    assert_eq!(rec.channel("force").unwrap(), &a[..1500]);
}

#[test]
fn harness_single_writes_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.5).collect();
    Single::new(&SPEC, "path = \"h.wav\"\nchannels = [\"force\"]")
        .input("force", x.clone(), 10_000.0)
        .ticks(5)
        .block(2)
        .base_dir(dir.path())
        .run()
        .unwrap();
    let rec = Recording::open(&dir.path().join("h.wav")).unwrap();
    assert_eq!(rec.rate(), 10_000.0);
    assert_eq!(rec.channel("force").unwrap(), &x[..]);
}

#[test]
fn refuses_bad_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let doc = graph(1000.0, &[("a", &[1.0]), ("b", &[1.0])], "path = \"o.wav\"\nunits = [\"N\"]");
    let err = run(dir.path(), &doc, 8).unwrap_err();
    assert!(err.contains("parameter `units`: 1 units for 2 channels"), "{err}");

    // A folder that cannot be made (a file is in the way) is an error
    // naming the path; nothing is written.
    std::fs::write(dir.path().join("blocker"), "").unwrap();
    let doc = graph(1000.0, &[("a", &[1.0])], "path = \"blocker/o.wav\"");
    let err = run(dir.path(), &doc, 8).unwrap_err();
    assert!(err.contains("blocker"), "{err}");
    assert_eq!(files(dir.path()), ["blocker"]);
}

#[test]
fn a_missing_folder_is_created() {
    let dir = tempfile::tempdir().unwrap();
    let doc = graph(1000.0, &[("a", &[1.0, 2.0])], "path = \"no/such/folder/o.wav\"");
    run(dir.path(), &doc, 8).unwrap();
    let rec = Recording::open(&dir.path().join("no/such/folder/o.wav")).unwrap();
    assert_eq!(rec.channel("a").unwrap(), &[1.0, 2.0][..]);
}

#[test]
fn a_check_writes_nothing() {
    // `evflow check` builds every node with check_only: the sink validates
    // its path but creates neither the folder nor a file.
    let dir = tempfile::tempdir().unwrap();
    let doc = graph(1000.0, &[("a", &[1.0, 2.0])], "path = \"no/such/folder/o.wav\"");
    plan_for(dir.path(), &doc, 8, true).unwrap();
    assert!(files(dir.path()).is_empty(), "{:?}", files(dir.path()));
    // A path leaving the output folder is still refused.
    let doc = graph(1000.0, &[("a", &[1.0])], "path = \"../o.wav\"");
    assert!(plan_for(dir.path(), &doc, 8, true).is_err());
}
