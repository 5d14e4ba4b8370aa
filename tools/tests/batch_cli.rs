//! Batches from the command line (issue 17): a sweep on several jobs
//! prints and writes exactly what it does on one; one bad run does not
//! lose the others; shards merged equal one run byte for byte.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::files;
use files::tree;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs")
}

/// The 3×3 grid of graphs/excitation.toml, outputs into `dir`.
fn sweep_args(dir: &Path) -> Vec<String> {
    let d = dir.to_str().unwrap();
    [
        "run",
        "graphs/excitation.toml",
        "--sweep",
        "mass=60,85,110",
        "--sweep",
        "speed=3,4,5",
        "--no-times",
        "--out",
        d,
        "--csv",
        &format!("{d}/grid.csv"),
        "--json",
        &format!("{d}/grid.json"),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn run(args: &[String], extra: &[&str]) -> Output {
    let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
    all.extend_from_slice(extra);
    evflow(&all)
}

#[test]
fn a_sweep_on_two_jobs_prints_and_writes_what_one_job_does() {
    let (one, two) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let a = run(&sweep_args(one.path()), &["--jobs", "1"]);
    let b = run(&sweep_args(two.path()), &["--jobs", "2"]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let out = String::from_utf8_lossy(&a.stdout);
    // Nine runs, in sweep order, each with its own recording.
    let heads: Vec<&str> = out.lines().filter(|l| l.starts_with("── run")).collect();
    assert_eq!(heads.len(), 9, "{out}");
    assert!(heads[0].contains("1/9: mass=60 speed=3") && heads[8].contains("9/9: mass=110 speed=5"), "{out}");
    assert_eq!(a.stdout, b.stdout, "stdout differs between --jobs 1 and 2");
    // stderr is a pipe here, not a terminal: the progress comes as plain
    // lines (issue 37, point 8): one at the start, one at the end.
    let err = String::from_utf8_lossy(&a.stderr);
    let progress: Vec<&str> = err.lines().filter(|l| l.contains(" runs, ") && l.contains("elapsed")).collect();
    assert!(progress.len() >= 2, "no progress lines in a log:\n{err}");
    assert!(progress.first().is_some_and(|l| l.starts_with("0/9 runs")), "{err}");
    assert!(progress.last().is_some_and(|l| l.starts_with("9/9 runs")), "{err}");
    let (ta, tb) = (tree(one.path()), tree(two.path()));
    assert_eq!(ta.len(), 9 * 2 + 2, "{:?}", ta.iter().map(|t| &t.0).collect::<Vec<_>>());
    assert_eq!(ta, tb, "files differ between --jobs 1 and 2");
}

#[test]
fn a_shared_sweep_prints_and_writes_what_separate_runs_do() {
    // The 3×3 grid changes the lab's first node: nothing is shared, every node copied.
    let (one, shared) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let a = run(&sweep_args(one.path()), &["--jobs", "1"]);
    let b = run(&sweep_args(shared.path()), &["--shared"]);
    assert!(a.status.success() && b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    assert_eq!(a.stdout, b.stdout, "stdout differs with --shared");
    assert_eq!(tree(one.path()), tree(shared.path()), "files differ with --shared");
    // A gain sweep of the live chains: everything before the gains runs once.
    let (one, shared) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let gains = |dir: &Path, extra: &str| {
        let d = dir.to_str().unwrap();
        let mut args = vec!["run", "graphs/texture-live-quality.toml", "--sweep", "gain=0.5,1.0", "--duration", "2"];
        args.extend(["--set", "record=actuations-g${gain}", "--no-times", "--out", d, extra]);
        evflow(&args)
    };
    let (a, b) = (gains(one.path(), "--jobs=1"), gains(shared.path(), "--shared"));
    assert!(a.status.success() && b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    assert_eq!(a.stdout, b.stdout, "stdout differs with --shared");
    assert_eq!(tree(one.path()).len(), 4, "a recording (wav + json) per gain");
    assert_eq!(tree(one.path()), tree(shared.path()), "files differ with --shared");
    let err = String::from_utf8_lossy(&b.stderr);
    assert!(err.contains("nodes run once for the 2 runs") && err.contains("live_gain"), "{err}");
    assert!(!err.split("once per run:").nth(1).unwrap_or("").contains("live_synth"), "{err}");
}

#[test]
fn one_bad_run_does_not_lose_the_others_and_fails_the_batch() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let csv = format!("{d}/t.csv");
    let o = evflow(&[
        "run",
        "graphs/excitation.toml",
        "--sweep",
        "mass=60,5000,110,-3",
        "--jobs",
        "2",
        "--quiet",
        "--out",
        d,
        "--csv",
        &csv,
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "a failed run must fail the batch");
    // The summary names every failure with its reason.
    assert!(stderr.contains("2 of 4 sweep runs failed"), "{stderr}");
    assert!(stderr.contains("mass=5000: ") && stderr.contains("mass=-3: "), "{stderr}");
    assert!(stderr.contains("outside its limits"), "{stderr}");
    // The good runs ran and were written.
    let table = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{table}");
    assert!(rows[0].starts_with("60,") && rows[1].starts_with("110,"), "{table}");
    let wavs: Vec<PathBuf> =
        tree(dir.path()).into_iter().map(|(p, _)| p).filter(|p| p.extension().is_some_and(|e| e == "wav")).collect();
    assert_eq!(wavs.len(), 2, "{wavs:?}");
    assert!(wavs.iter().any(|p| p.to_string_lossy().starts_with("excitation-60g")), "{wavs:?}");
    assert!(wavs.iter().any(|p| p.to_string_lossy().starts_with("excitation-110g")), "{wavs:?}");
}

/// A shard beyond the batch's runs is empty, not a failure (a job array
/// of N tasks over a graph without a sweep, or over a sweep of fewer runs
/// than tasks): it runs nothing, exits 0, writes a record saying so, and
/// `merge` of it with the shards that ran is the one run's output, byte
/// for byte.
fn an_empty_shard_merges(extra: &[&str], shards: usize) {
    let base = tempfile::tempdir().unwrap();
    let dir = |n: &str| base.path().join(n).to_str().unwrap().to_string();
    let with = |args: &[&str]| evflow(&[args, extra].concat());
    let one = with(&["run", "graphs/excitation.toml", "-q", "--no-times", "--out", &dir("one")]);
    assert!(one.status.success(), "{}", String::from_utf8_lossy(&one.stderr));
    let mut parts = Vec::new();
    for k in 1..=shards {
        let shard = format!("{k}/{shards}");
        let part = dir(&format!("s{k}"));
        let o = with(&["run", "graphs/excitation.toml", "-q", "--no-times", "--shard", &shard, "--out", &part]);
        assert!(o.status.success(), "shard {shard}: {}", String::from_utf8_lossy(&o.stderr));
        parts.push(part);
    }
    let empty = std::fs::read_to_string(base.path().join(format!("s{shards}/shard.json"))).unwrap();
    assert!(empty.contains("\"runs\": []") || empty.contains("\"runs\":[]"), "{empty}");
    parts.reverse();
    let o = evflow(&[&["merge", &dir("merged")][..], &parts.iter().map(String::as_str).collect::<Vec<_>>()].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (a, b) = (tree(&base.path().join("one")), tree(&base.path().join("merged")));
    assert_eq!(a.iter().map(|t| &t.0).collect::<Vec<_>>(), b.iter().map(|t| &t.0).collect::<Vec<_>>());
    assert!(a == b, "the merged empty shards differ from one run");
}

#[test]
fn an_empty_shard_writes_its_record_and_merges() {
    an_empty_shard_merges(&[], 3);
}

#[test]
fn an_empty_shard_of_a_sweep_writes_its_record_and_merges() {
    an_empty_shard_merges(&["--sweep", "mass=60,85"], 3);
}

#[test]
fn shards_merged_equal_one_run_byte_for_byte() {
    let base = tempfile::tempdir().unwrap();
    let one = base.path().join("one");
    let o = run(&sweep_args(&one), &["--jobs", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Four shards of nine runs (3, 2, 2, 2), given to merge out of order.
    let mut dirs = Vec::new();
    for k in 1..=4 {
        let d = base.path().join(format!("part{k}"));
        let o = run(&sweep_args(&d), &["--jobs", "1", "--shard", &format!("{k}/4")]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        dirs.push(d.to_str().unwrap().to_string());
    }
    let merged = base.path().join("merged");
    let missing = evflow(&["merge", merged.to_str().unwrap(), &dirs[0], &dirs[2], &dirs[3]]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("shards missing: 2/4"));
    let o = evflow(&["merge", merged.to_str().unwrap(), &dirs[3], &dirs[1], &dirs[0], &dirs[2]]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (a, b) = (tree(&one), tree(&merged));
    assert_eq!(a.iter().map(|t| &t.0).collect::<Vec<_>>(), b.iter().map(|t| &t.0).collect::<Vec<_>>());
    assert_eq!(a, b, "merged shards differ from one run");
    // The same shard twice is refused.
    let o = evflow(&["merge", merged.to_str().unwrap(), &dirs[0], &dirs[1], &dirs[1], &dirs[2], &dirs[3]]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("both are shard 2/4"));
}

#[test]
fn many_sessions_replay_in_order_on_two_jobs_and_a_broken_one_fails_alone() {
    let base = tempfile::tempdir().unwrap();
    let mut sessions = Vec::new();
    for (k, change) in ["0.1:gain.gain=0.3", "0.2:limit.enable=false", "0.05:gain.gain=0.8"].iter().enumerate() {
        let s = base.path().join(format!("s{k}"));
        let o = evflow(&[
            "live",
            "graphs/display-live.toml",
            "--session",
            s.to_str().unwrap(),
            "--no-realtime",
            "--miss-streak",
            "0",
            "-q",
            "--duration",
            "0.3",
            "--change",
            change,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        sessions.push(s.to_str().unwrap().to_string());
    }
    let replay = |jobs: &str, out: &Path, extra: &[&str]| {
        let mut args = vec!["replay", "--check", "-q", "--jobs", jobs, "--out", out.to_str().unwrap()];
        args.extend(sessions.iter().map(String::as_str));
        args.extend_from_slice(extra);
        evflow(&args)
    };
    let a = replay("1", &base.path().join("o1"), &[]);
    let b = replay("2", &base.path().join("o2"), &[]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    assert_eq!(a.stdout, b.stdout);
    let out = String::from_utf8_lossy(&b.stdout);
    let heads: Vec<&str> = out.lines().filter(|l| l.starts_with("── session")).collect();
    assert_eq!(heads.len(), 3, "{out}");
    for (k, s) in sessions.iter().enumerate() {
        assert!(heads[k].contains(&format!("{}/3: {s}", k + 1)), "{out}");
    }
    assert_eq!(out.matches("limit.out: identical to the live session, bit for bit").count(), 3, "{out}");

    // A session without its manifest fails alone; the summary names it.
    let broken = base.path().join("broken");
    std::fs::create_dir(&broken).unwrap();
    let c = replay("2", &base.path().join("o3"), &[broken.to_str().unwrap()]);
    let (out, err) = (String::from_utf8_lossy(&c.stdout), String::from_utf8_lossy(&c.stderr));
    assert!(!c.status.success());
    assert_eq!(out.matches("limit.out: identical to the live session, bit for bit").count(), 3, "{out}");
    assert!(err.contains("1 of 4 sessions failed") && err.contains("broken"), "{err}");
}

/// The model library: built, usable by the texture-live grid, resumed
/// (nothing redone), and a half-written item redone.
#[cfg(feature = "synth")]
#[test]
fn a_model_library_resumes_and_redoes_a_half_written_item() {
    let base = tempfile::tempdir().unwrap();
    let lib = base.path().join("lib");
    let l = lib.to_str().unwrap();
    let build = |jobs: &str| {
        evflow(&[
            "library",
            "build",
            "--out",
            l,
            "--samples",
            "felt-fabric",
            "--masses",
            "60,110",
            "--speeds",
            "3,5",
            "--epochs",
            "3",
            "--iterations",
            "3",
            "--gains",
            "1.0",
            "--jobs",
            jobs,
        ])
    };
    let o = build("2");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("8 items built, 0 already there, 0 failed, of 8"), "{out}");
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lib.join("index.json")).unwrap()).unwrap();
    let entries = index["entries"].as_array().unwrap();
    assert_eq!(entries.len(), 4);
    let tags: Vec<&str> = entries.iter().map(|e| e["tag"].as_str().unwrap()).collect();
    assert_eq!(tags, ["60g-3cms", "60g-5cms", "110g-3cms", "110g-5cms"]);
    for e in entries {
        assert_eq!(e["texture"], "felt-fabric");
        assert!(lib.join(e["model"].as_str().unwrap()).is_file());
        assert!(e["training"]["validation_mse"].as_f64().unwrap().is_finite());
        for m in ["narx", "optimized", "playback"] {
            let es = e["E_s"][m]["welch"].as_f64().unwrap();
            assert!(es.is_finite() && es > 0.0, "{m}: {es}");
            assert!(lib.join(e["cells"][m].as_str().unwrap()).is_file());
        }
    }
    // The live synthesis (texture-live.toml) plays the library's recorded forces.
    let grid = format!("textures=[\"{}\"]", lib.join("forces-felt-fabric").display());
    let o = evflow(&["run", "graphs/texture-live.toml", "--set", &grid, "--duration", "0.5", "-q", "--out", l]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // Rerun: everything is there.
    let o = build("2");
    assert!(String::from_utf8_lossy(&o.stdout).contains("0 items built, 8 already there"));

    // An interruption while one cell was being moved in: its sample file
    // is gone and a partial folder is left. That item alone is redone.
    let cell = lib.join("optimized-felt-fabric/u-felt-fabric-110g-3cms.wav");
    let before = std::fs::read(&cell).unwrap();
    std::fs::remove_file(&cell).unwrap();
    std::fs::create_dir_all(lib.join(".partial/felt-fabric-110g-3cms/cells")).unwrap();
    std::fs::write(lib.join(".partial/felt-fabric-110g-3cms/cells/junk"), "half").unwrap();
    let o = build("1");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("1 items built, 7 already there"), "{out}");
    assert_eq!(std::fs::read(&cell).unwrap(), before, "the redone cell is the one first built");
    assert!(!lib.join(".partial").exists());
}

/// A library built in two shards (conditions split) and merged is the
/// library one build makes: every file byte for byte but the training
/// times the model files and the index record.
#[cfg(feature = "synth")]
#[test]
fn library_shards_merged_equal_one_build() {
    let base = tempfile::tempdir().unwrap();
    let build = |dir: &Path, shard: Option<&str>| {
        let d = dir.to_str().unwrap();
        let mut args = vec![
            "library",
            "build",
            "--out",
            d,
            "--samples",
            "felt-fabric,dotted-sheet",
            "--masses",
            "60,110",
            "--speeds",
            "3,5",
            "--epochs",
            "3",
            "--iterations",
            "3",
            "--gains",
            "1.0",
            "--jobs",
            "2",
        ];
        if let Some(s) = shard {
            args.extend(["--shard", s]);
        }
        let o = evflow(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (one, p1, p2, merged) =
        (base.path().join("one"), base.path().join("p1"), base.path().join("p2"), base.path().join("merged"));
    build(&one, None);
    build(&p2, Some("2/2"));
    build(&p1, Some("1/2"));
    let o = evflow(&["merge", merged.to_str().unwrap(), p2.to_str().unwrap(), p1.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("8 entries"));
    // Training times differ from build to build: drop those lines.
    let timeless = |b: &[u8]| -> String {
        String::from_utf8_lossy(b).lines().filter(|l| !l.contains("\"seconds\"")).collect::<Vec<_>>().join("\n")
    };
    let (a, b) = (tree(&one), tree(&merged));
    assert_eq!(a.iter().map(|t| &t.0).collect::<Vec<_>>(), b.iter().map(|t| &t.0).collect::<Vec<_>>());
    for ((p, x), (_, y)) in a.iter().zip(&b) {
        if p.extension().is_some_and(|e| e == "json") {
            assert_eq!(timeless(x), timeless(y), "{}", p.display());
        } else {
            assert_eq!(x, y, "{}", p.display());
        }
    }
    // One shard alone is refused, naming the missing one.
    let o = evflow(&["merge", base.path().join("m2").to_str().unwrap(), p1.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("shards missing: 2/2"));
}

/// Generated texture samples in the library: `--generated 2` adds
/// generated-1 and generated-2 after `--samples`, the texture-live grid
/// plays a generated texture's cells, and malformed names are refused
/// before anything is built.
#[cfg(feature = "synth")]
#[test]
fn a_library_takes_generated_samples_and_refuses_malformed_names() {
    let base = tempfile::tempdir().unwrap();
    let lib = base.path().join("lib");
    let l = lib.to_str().unwrap();
    let build = |samples: &str, generated: &str| {
        evflow(&[
            "library",
            "build",
            "--out",
            l,
            "--samples",
            samples,
            "--generated",
            generated,
            "--masses",
            "85",
            "--speeds",
            "5",
            "--epochs",
            "3",
            "--iterations",
            "3",
            "--gains",
            "1.0",
            "--jobs",
            "2",
        ])
    };
    let o = build("felt-fabric", "2");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("4 items built, 0 already there, 0 failed, of 4"), "{out}");
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lib.join("index.json")).unwrap()).unwrap();
    assert_eq!(index["samples"], serde_json::json!(["felt-fabric", "generated-1", "generated-2"]));
    let textures: Vec<&str> =
        index["entries"].as_array().unwrap().iter().map(|e| e["texture"].as_str().unwrap()).collect();
    assert_eq!(textures, ["felt-fabric", "generated-1", "generated-2"]);
    // Two generated textures are two different textures: their cells differ.
    let cell = |s: &str| std::fs::read(lib.join(format!("narx-{s}/u-{s}-85g-5cms.wav"))).unwrap();
    assert_ne!(cell("generated-1"), cell("generated-2"));
    let grid = format!("textures=[\"{}\"]", lib.join("forces-generated-2").display());
    let o = evflow(&["run", "graphs/texture-live.toml", "--set", &grid, "--duration", "0.5", "-q", "--out", l]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    for bad in ["generated-x", "generated-07"] {
        let o = build(bad, "0");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains(&format!("--samples: sample `{bad}`")) && err.contains("generated-<seed>"), "{err}");
    }
    let o = build("generated-1", "1");
    assert!(String::from_utf8_lossy(&o.stderr).contains("sample `generated-1` given twice"));
    // A graph naming a malformed generated sample is refused, naming the node's parameter.
    let o = evflow(&[
        "run",
        "graphs/record-textures.toml",
        "--set",
        "sample=generated-x",
        "--out",
        base.path().join("rec").to_str().unwrap(),
        "-q",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("sample") && err.contains("`generated-x`") && err.contains("generated-<seed>"), "{err}");
}

/// A sweep whose runs would write the same file (its output name does not
/// vary with a swept variable) is refused before anything runs, naming
/// the file and the runs that share it.
#[test]
fn a_sweep_whose_runs_share_an_output_file_is_refused_before_running() {
    let base = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("graphs/excitation.toml")).unwrap();
    assert!(text.contains("path = \"excitation-${mass}g-${speed}cms\""));
    let graph = base.path().join("clash.toml");
    std::fs::write(&graph, text.replace("excitation-${mass}g-${speed}cms", "excitation-${mass}g")).unwrap();
    let out = base.path().join("out");
    let args = |extra: &[&str]| {
        let mut v = vec!["run", graph.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q", "--jobs", "2"];
        v.extend_from_slice(extra);
        evflow(&v)
    };
    let o = args(&["--sweep", "mass=60,110", "--sweep", "speed=3,5"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("2 output files would be written by more than one run"), "{err}");
    let f60 = out.join("excitation-60g");
    let f110 = out.join("excitation-110g");
    assert!(
        err.contains(&format!("{}: mass=60 speed=3 (node `record`), mass=60 speed=5 (node `record`)", f60.display())),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "{}: mass=110 speed=3 (node `record`), mass=110 speed=5 (node `record`)",
            f110.display()
        )),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    // Sweeping only the variable the name holds is fine.
    let o = args(&["--sweep", "mass=60,110", "--set", "speed=3"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("excitation-60g.wav").is_file() && out.join("excitation-110g.wav").is_file());
}

/// `report textures` in three shards (four (profile, condition) cells
/// split 2, 1, 1, across two profiles), merged out of order, is the report
/// one run writes, every file byte for byte (textures.md, rows.csv, the
/// spectra, the models without training times, the recordings and runs).
/// Missing shards, shards of another report and `--grid` with `--shard`
/// are refused by name.
#[cfg(feature = "synth")]
#[test]
fn report_textures_shards_merged_equal_one_report() {
    let base = tempfile::tempdir().unwrap();
    let report = |dir: &Path, shard: Option<&str>, gains: &str| {
        let mut args = vec![
            "report",
            "textures",
            "--out",
            dir.to_str().unwrap(),
            "--samples",
            "plastic-sheet",
            "--conditions",
            "60:3,110:5",
            "--profiles",
            "nominal,stiff",
            "--epochs",
            "3",
            "--iterations",
            "3",
            "--gains",
            gains,
            "--no-times",
            "--jobs",
            "2",
        ];
        if let Some(s) = shard {
            args.extend(["--shard", s]);
        }
        evflow(&args)
    };
    let one = base.path().join("one");
    let o = report(&one, None, "1.0");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut dirs = Vec::new();
    for k in 1..=3 {
        let d = base.path().join(format!("part{k}"));
        let o = report(&d, Some(&format!("{k}/3")), "1.0");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(!d.join("textures.md").exists(), "a shard writes its record, not the tables");
        dirs.push(d.to_str().unwrap().to_string());
    }
    let merged = base.path().join("merged");
    let m = merged.to_str().unwrap();
    let o = evflow(&["merge", m, &dirs[0], &dirs[2]]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("shards missing: 2/3"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!merged.exists(), "a refused merge wrote {m}");
    let o = evflow(&["merge", m, &dirs[2], &dirs[0], &dirs[1]]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("merged 3 shards of a texture report: 4 rows"), "{stdout}");
    assert_eq!(
        stdout.lines().take_while(|l| !l.starts_with("wrote ")).collect::<Vec<_>>().join("\n") + "\n",
        std::fs::read_to_string(one.join("textures.md")).unwrap(),
        "merge prints the report one run prints"
    );
    let (a, b) = (tree(&one), tree(&merged));
    assert_eq!(a.iter().map(|t| &t.0).collect::<Vec<_>>(), b.iter().map(|t| &t.0).collect::<Vec<_>>());
    assert!(a.iter().any(|(p, _)| p.ends_with("rows.csv")) && a.iter().any(|(p, _)| p.ends_with("textures.md")));
    assert!(a.iter().any(|(p, _)| p.ends_with("work/stiff/models/forward-110g-5cms.json")));
    for ((p, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{} differs between the merged shards and one run", p.display());
    }
    // A shard of a report with other gains is not one of these.
    let other = base.path().join("other");
    assert!(report(&other, Some("2/3"), "0.8").status.success());
    let o = evflow(&["merge", base.path().join("m2").to_str().unwrap(), &dirs[0], other.to_str().unwrap(), &dirs[2]]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("not shards of one batch") && err.contains("gains"), "{err}");
    // --grid needs every condition of a texture.
    let o = evflow(&["report", "textures", "--shard", "1/2", "--grid", "g", "--out", base.path().to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--grid with --shard"));
    // A folder that is no shard of the report among them is named.
    let o = evflow(&["merge", base.path().join("m3").to_str().unwrap(), &dirs[0], one.to_str().unwrap(), &dirs[2]]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{}", one.join("textures-shard.json").display())) && err.contains("--shard"),
        "{err}"
    );
    // A step that failed in a shard is listed again by the merge, which
    // still writes the tables of every row that ran, and exits 1.
    let record = Path::new(&dirs[1]).join("textures-shard.json");
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    doc["failures"] = serde_json::json!([{ "step": "stiff: felt-fabric at 60 g, 3 cm/s", "reason": "it broke" }]);
    std::fs::write(&record, doc.to_string()).unwrap();
    let m4 = base.path().join("m4");
    let o = evflow(&["merge", m4.to_str().unwrap(), &dirs[0], &dirs[1], &dirs[2]]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("stiff: felt-fabric at 60 g, 3 cm/s (shard 2/3): it broke"), "{err}");
    assert_eq!(std::fs::read(m4.join("rows.csv")).unwrap(), std::fs::read(one.join("rows.csv")).unwrap());
}

/// `report textures --displays tuning` runs on the display family's tuning
/// displays, sharded like any report: of the ten (display, condition)
/// cells at one condition, shard 1/10 runs the first display's alone and
/// its record names it (docs/simulated-lab.md §6.2).
#[cfg(feature = "synth")]
#[test]
fn report_textures_runs_on_the_display_family_in_shards() {
    let base = tempfile::tempdir().unwrap();
    let out = base.path().join("s1");
    let o = evflow(&[
        "report",
        "textures",
        "--displays",
        "tuning",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "plastic-sheet",
        "--conditions",
        "60:3",
        "--epochs",
        "3",
        "--iterations",
        "3",
        "--gains",
        "1.0",
        "--no-floor",
        "--no-multilevel",
        "--no-times",
        "--shard",
        "1/10",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("textures-shard.json")).unwrap()).unwrap();
    assert_eq!(record["cells"], 10, "{record}");
    assert_eq!(record["scope"]["profiles"][9], "family/tuning-10", "{record}");
    let rows: Vec<&str> = record["rows"].as_array().unwrap().iter().map(|r| r["profile"].as_str().unwrap()).collect();
    assert_eq!(rows, ["tuning-01"]);
    assert!(out.join("work/tuning-01/models/forward-60g-3cms.json").is_file());
    // The family's names are the choices; a wrong one lists them.
    let o = evflow(&["report", "textures", "--displays", "held", "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("held-out") && err.contains("tuning"), "{err}");
}

/// The README's main job in shards (issue 27, point 8): a shard draws no
/// plot of the sweep (it holds part of it), and `evflow merge` draws them
/// from every run, so the merge is one run's output, PNGs included, byte
/// for byte.
#[test]
fn the_main_job_in_shards_merges_into_one_run_plots_included() {
    let base = tempfile::tempdir().unwrap();
    let dir = |n: &str| base.path().join(n).to_str().unwrap().to_string();
    let o = evflow(&["run", "graphs/characterize.toml", "-q", "--out", &dir("one")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for k in 1..=2 {
        let o = evflow(&[
            "run",
            "graphs/characterize.toml",
            "-q",
            "--shard",
            &format!("{k}/2"),
            "--out",
            &dir(&format!("s{k}")),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stdout).contains("plots: drawn by `evflow merge`"));
        assert!(!base.path().join(format!("s{k}/characterize-static.png")).exists());
    }
    let o = evflow(&["merge", &dir("m"), &dir("s2"), &dir("s1")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for png in ["characterize-static.png", "characterize-vibratory.png"] {
        let one = std::fs::read(base.path().join("one").join(png)).unwrap();
        assert_eq!(one, std::fs::read(base.path().join("m").join(png)).unwrap(), "{png}");
    }
}
