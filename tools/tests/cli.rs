//! The `evflow` program end to end: exit codes, what it prints, what it
//! writes — and that it writes nothing when a graph is wrong.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs")
}

fn text(o: &Output) -> (String, String) {
    (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn help_explains_each_command_with_an_example() {
    for cmd in ["run", "check", "nodes", "dot", "import"] {
        let o = evflow(&[cmd, "--help"]);
        let (out, _) = text(&o);
        assert!(o.status.success(), "{cmd} --help");
        assert!(out.contains("Example"), "`evflow {cmd} --help` shows no example:\n{out}");
    }
    let (out, _) = text(&evflow(&["--help"]));
    for cmd in ["run", "check", "nodes", "dot", "import"] {
        assert!(out.contains(cmd), "{out}");
    }
}

#[test]
fn import_writes_a_recording_and_says_what_it_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("prbs-85g-4cms.csv");
    let mut csv = String::from("time [s],u,force [N]\n");
    for i in 0..2000 {
        let u = if (i * 7919) % 13 < 6 { -1.0 } else { 1.0 };
        csv += &format!("{},{u},{}\n", i as f64 / 10_000.0, 0.05 * u);
    }
    std::fs::write(&src, csv).unwrap();
    let out = dir.path().join("recordings/");
    let args = [
        "import",
        src.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--load-g",
        "85",
        "--velocity-cm-s",
        "4",
        "--material",
        "display-a",
        "--condition",
        "trial=2",
    ];
    let o = evflow(&args);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    for want in [
        "prbs-85g-4cms.wav + ",
        "rate       10000 Hz",
        "frames     2000 (0.2 s)",
        "channels   u, force [N]",
        "condition  load_g=85, velocity_cm_s=4, material=display-a, trial=2",
        "note: rate 10000 Hz from time column `time`",
    ] {
        assert!(stdout.contains(want), "`{want}` missing:\n{stdout}");
    }
    assert_eq!(files_in(&out), ["prbs-85g-4cms.json", "prbs-85g-4cms.wav"]);
    let sidecar = std::fs::read_to_string(out.join("prbs-85g-4cms.json")).unwrap();
    assert!(sidecar.contains("\"load_g\": 85.0"), "{sidecar}");

    // Again: refused, the recording kept; a bad row: nothing written.
    let o = evflow(&args);
    assert!(!o.status.success());
    assert!(text(&o).1.contains("already exists; give --force"), "{}", text(&o).1);
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "t,force\n0,1\n0.001,x\n").unwrap();
    let o = evflow(&["import", bad.to_str().unwrap(), "--out", dir.path().join("b/c").to_str().unwrap()]);
    let (_, stderr) = text(&o);
    assert!(!o.status.success());
    assert!(stderr.contains("bad.csv:3: column 2 (`force`): `x` is not a number"), "{stderr}");
    assert!(!dir.path().join("b").exists());
}

#[test]
fn run_writes_its_recording_into_the_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let o = evflow(&["run", "graphs/excitation.toml", "--out", out, "--set", "mass=60"]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(stdout.contains("wrote excitation-60g-5cms.wav (3066 frames"), "{stdout}");
    assert!(stdout.contains("ticks/s"), "{stdout}");
    // The total and the nodes' times say what each counts (issue 37, point 13).
    assert!(stdout.contains("the nodes' set-up and finish, writing files included, took"), "{stdout}");
    assert!(
        stdout.lines().any(|l| l.split_whitespace().eq(["node", "type", "set-up", "run", "finish", "share"])),
        "{stdout}"
    );
    assert_eq!(files_in(dir.path()), ["excitation-60g-5cms.json", "excitation-60g-5cms.wav"]);
}

#[test]
fn a_wrong_graph_names_file_line_and_node_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = evflow(&["run", "graphs/excitation.toml", "--out", out.to_str().unwrap(), "--set", "mass=5000"]);
    let (_, stderr) = text(&o);
    assert!(!o.status.success());
    assert!(stderr.contains("graphs/excitation.toml:"), "{stderr}");
    assert!(stderr.contains("node `tribometer`"), "{stderr}");
    assert!(stderr.contains("outside its limits"), "{stderr}");
    assert!(!out.exists(), "an invalid graph created its output folder");

    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[graph]\nformat = 1\nname = \"bad\"\nrate = 1000\nconnections = [\"s.out -> k.in\"]\n\
         [nodes.s]\ntype = \"sinus\"\n[nodes.k]\ntype = \"stats\"\n",
    )
    .unwrap();
    let o = evflow(&["check", bad.to_str().unwrap()]);
    let (_, stderr) = text(&o);
    assert!(!o.status.success());
    assert!(stderr.contains("bad.toml:7"), "{stderr}");
    assert!(stderr.contains("unknown node type `sinus`"), "{stderr}");
    assert!(stderr.contains("did you mean `sine`?"), "{stderr}");
}

#[test]
fn a_sweep_runs_every_combination_and_tabulates_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let csv = dir.path().join("grid.csv");
    let o = evflow(&[
        "sweep",
        "graphs/excitation.toml",
        "--out",
        out,
        "--sweep",
        "mass=60,110",
        "--sweep",
        "speed=3,5",
        "--csv",
        csv.to_str().unwrap(),
        "--quiet",
    ]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    for name in ["60g-3cms", "60g-5cms", "110g-3cms", "110g-5cms"] {
        assert!(dir.path().join(format!("excitation-{name}.wav")).exists(), "{name}: {stdout}");
    }
    let table = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 5, "{table}");
    assert!(lines[0].starts_with("mass,speed,"), "{table}");
    assert!(lines[1].starts_with("60,3,") && lines[4].starts_with("110,5,"), "{table}");

    // A bad value in the sweep fails that run only (tools/tests/batch_cli.rs
    // has the rest); when no run is valid, nothing is written.
    let dir2 = tempfile::tempdir().unwrap();
    let o =
        evflow(&["run", "graphs/excitation.toml", "--out", dir2.path().to_str().unwrap(), "--sweep", "mass=7000,5000"]);
    let (_, stderr) = text(&o);
    assert!(!o.status.success());
    assert!(stderr.contains("mass=5000") && stderr.contains("mass=7000"), "{stderr}");
    assert!(files_in(dir2.path()).is_empty());
}

#[test]
fn check_prints_the_plan_and_what_was_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let g = dir.path().join("g.toml");
    std::fs::write(
        &g,
        "[graph]\nformat = 1\nname = \"g\"\nrate = 1000\n\
         connections = [\"s.out -> k.in\", \"s.out -> unused.in\"]\n\
         [nodes.s]\ntype = \"sine\"\nfrequency = 10.0\n[nodes.k]\ntype = \"stats\"\n\
         [nodes.unused]\ntype = \"gain\"\n",
    )
    .unwrap();
    let o = evflow(&["check", g.to_str().unwrap()]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(stdout.contains("unused"), "{stdout}");
    assert!(stdout.contains("1000"), "{stdout}");
}

#[test]
fn check_prints_each_mesh_s_bounds_up_axis_and_scale_unless_told_not_to_build() {
    let o = evflow(&["check", "graphs/mesh-scan.toml"]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    let surface = stdout.lines().find(|l| l.trim_start().starts_with("surface:")).unwrap_or_else(|| panic!("{stdout}"));
    for part in ["bounds x", "up +z (auto)", "scale 0.01 m per unit", "on the screen"] {
        assert!(surface.contains(part), "`{part}` missing: {surface}");
    }
    let o = evflow(&["check", "graphs/mesh-scan.toml", "--no-build"]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(!stdout.contains("bounds x") && stdout.contains("--no-build"), "{stdout}");
}

#[test]
fn nodes_lists_and_describes_node_types() {
    let (out, _) = text(&evflow(&["nodes"]));
    for t in ["prbs", "butterworth", "sim.display", "recording.out", "metric"] {
        assert!(out.contains(t), "{out}");
    }
    let o = evflow(&["nodes", "butterworth"]);
    let (out, _) = text(&o);
    assert!(o.status.success());
    assert!(out.contains("cutoff") && out.contains("Hz"), "{out}");
    let o = evflow(&["nodes", "buterworth"]);
    let (_, err) = text(&o);
    assert!(!o.status.success());
    assert!(err.contains("did you mean `butterworth`?"), "{err}");
}

#[test]
fn dot_prints_graphviz() {
    let o = evflow(&["dot", "graphs/excitation.toml"]);
    let (out, _) = text(&o);
    assert!(o.status.success());
    assert!(out.starts_with("digraph"), "{out}");
    assert!(out.contains("tribometer") && out.contains("->"), "{out}");
}

/// A sine into stats with its frequency `$f` swept, optionally recorded.
fn sweep_graph(dir: &Path, default: &str, values: &str, record: &str) -> PathBuf {
    let g = dir.join("sweep.toml");
    let (conn, node) = if record.is_empty() {
        (String::new(), String::new())
    } else {
        (
            ", \"s.out -> r.x\"".to_string(),
            format!("[nodes.r]\ntype = \"recording.out\"\npath = \"{record}\"\nchannels = [\"x\"]\n"),
        )
    };
    std::fs::write(
        &g,
        format!(
            "[graph]\nformat = 1\nname = \"g\"\nrate = 1000\nconnections = [\"s.out -> k.in\"{conn}]\n\
             [vars]\nf = {default}\n[sweep]\nf = {values}\n\
             [nodes.s]\ntype = \"sine\"\nfrequency = \"$f\"\n[nodes.k]\ntype = \"stats\"\n{node}"
        ),
    )
    .unwrap();
    g
}

#[test]
fn check_and_run_agree_on_every_run_of_a_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    // A default no run uses may be out of range: both pass.
    let g = sweep_graph(dir.path(), "-1.0", "[10.0, 20.0]", "");
    let g = g.to_str().unwrap();
    let o = evflow(&["check", g]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stdout.contains("f (2 values) → 2 runs") && stdout.contains("built every run of the sweep (2)"),
        "{stdout}"
    );
    assert!(stdout.contains("execution order, the first run's: f=10"), "{stdout}");
    let o = evflow(&["run", g, "--duration", "0.01", "--out", out]);
    assert!(o.status.success(), "{}", text(&o).1);
    // A swept value out of range: both fail, naming the run.
    let g = sweep_graph(dir.path(), "10.0", "[10.0, -3.0]", "");
    let g = g.to_str().unwrap();
    let o = evflow(&["check", g]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("1 of 2 sweep runs would fail") && stderr.contains("f=-3:"), "{stderr}");
    assert!(stderr.contains("`frequency`"), "{stderr}");
    let o = evflow(&["run", g, "--duration", "0.01", "--out", out]);
    assert!(!o.status.success() && text(&o).1.contains("f=-3"), "{}", text(&o).1);
    // A value above Nyquist validates but fails when built: check builds every run.
    let g = sweep_graph(dir.path(), "10.0", "[10.0, 700.0]", "");
    let o = evflow(&["check", g.to_str().unwrap()]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("f=700:"), "{stderr}");
    // --sweep replaces the graph's axis, as in run.
    let o = evflow(&["check", g.to_str().unwrap(), "--sweep", "f=1,2,3"]);
    assert!(o.status.success(), "{}", text(&o).1);
    let o = evflow(&["check", g.to_str().unwrap(), "--sweep", "nope=1,2"]);
    assert!(!o.status.success() && text(&o).1.contains("no variable `nope`"), "{}", text(&o).1);
    // Runs that would write one file are refused by both, before anything runs.
    let g = sweep_graph(dir.path(), "10.0", "[10.0, 20.0]", "same.wav");
    let o = evflow(&["check", g.to_str().unwrap()]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("same.wav"), "{stderr}");
    let o = evflow(&["run", g.to_str().unwrap(), "--duration", "0.01", "--out", out]);
    assert!(!o.status.success() && text(&o).1.contains("same.wav"), "{}", text(&o).1);
}

#[test]
fn deadline_misses_stop_a_session_by_default_only_when_it_drives_hardware() {
    let dir = tempfile::tempdir().unwrap();
    let live = |graph: &str, name: &str, extra: &[&str]| {
        let s = dir.path().join(name);
        let mut args = vec!["live", graph, "--no-realtime", "--duration", "0.2", "--session", s.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = evflow(&args);
        // The rig's session may stop on a loaded machine's misses: that is
        // the point; the others never stop for them.
        assert!(o.status.success() || name == "rig", "{}", text(&o).1);
        text(&o).1
    };
    // The simulated lab: a loaded machine's misses are counted, never fatal.
    let e = live("graphs/texture-live.toml", "sim", &[]);
    assert!(e.contains("without hardware they never stop the session"), "{e}");
    let e = live("graphs/texture-live.toml", "sim3", &["--miss-streak", "1000"]);
    assert!(e.contains("1000 deadline misses in a row stop the session"), "{e}");
    // A graph with a hardware output (here without its device).
    let e = live("graphs/texture-serial.toml", "rig", &["--set", "wait=0"]);
    assert!(e.contains("10 deadline misses in a row stop the session"), "{e}");
}

#[test]
fn check_refuses_a_recording_folder_whose_recordings_lack_a_channel_the_graph_reads() {
    // Before: check said ok; run then failed (issue 27, point 11).
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("u,force\n");
    for i in 0..2000 {
        csv += &format!("{},{}\n", if i % 7 < 3 { 1 } else { -1 }, 0.01 * f64::from(i % 11));
    }
    std::fs::write(dir.path().join("x.csv"), csv).unwrap();
    let rec = dir.path().join("prbs-85g-5cms");
    let o = evflow(&[
        "import",
        dir.path().join("x.csv").to_str().unwrap(),
        "--rate",
        "1000",
        "--load-g",
        "85",
        "--velocity-cm-s",
        "5",
        "--out",
        rec.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o).1);
    std::fs::remove_file(dir.path().join("x.csv")).unwrap();
    let set = format!("recordings={}", dir.path().display());
    let o = evflow(&["check", "graphs/model-build-recordings.toml", "--set", &set]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("prbs-85g-5cms") && stderr.contains("no channel `velocity`"), "{stderr}");
}

/// `evflow check` writes nothing: checking a graph whose sink writes into
/// a folder, from another working folder, leaves that folder empty.
#[test]
fn check_creates_no_file_and_no_folder() {
    let dir = tempfile::tempdir().unwrap();
    let graph = root().join("graphs/synthesize-recordings.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_evflow"))
        .args(["check", graph.to_str().unwrap()])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "check left {left:?}");
}

/// docs/rig.md's slip (issue 37, point 9): `sample=felt` names a grid folder
/// that is not there; the error names it once and the folders there are.
#[test]
fn a_misnamed_sample_names_its_grid_folder_once_and_suggests_the_nearest() {
    let o = evflow(&["check", "graphs/texture-live-recorded.toml", "--set", "sample=felt"]);
    let (_, stderr) = text(&o);
    assert!(!o.status.success(), "{stderr}");
    assert_eq!(stderr.matches("forces-felt:").count(), 1, "{stderr}");
    assert!(stderr.contains("cannot list the grid folder"), "{stderr}");
    assert!(stderr.contains("did you mean `forces-felt-fabric`?"), "{stderr}");
}

/// `check` shows what a gain, a hold or a filter carries, not `[1]`
/// (issue 37, point 13): the load cell's N made g, the velocity in cm/s.
#[test]
fn check_shows_the_units_a_chain_carries() {
    let o = evflow(&["check", "graphs/texture-live-recorded.toml"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let line = |name: &str| out.lines().find(|l| l.trim_start().starts_with(name)).unwrap_or_default().to_string();
    assert!(line("load_g ").ends_with("out: out [g]"), "{out}");
    assert!(line("load_1khz ").ends_with("out: out [g]"), "{out}");
    assert!(line("velocity_1khz ").ends_with("out: out [cm/s]"), "{out}");
}

/// `live` and `replay` print a sink's values as `run` does, six
/// significant digits, not seventeen, and `stats` gives them the unit of
/// what feeds it (a force in N; its sample count has none) (issue 37,
/// point 13).
#[test]
fn live_prints_values_as_run_does() {
    let dir = tempfile::tempdir().unwrap();
    let with_units = |stdout: &str| {
        for k in ["mean", "rms", "min", "max", "pp"] {
            let line = stdout.lines().find(|l| l.starts_with(&format!("force_stats: {k} = "))).unwrap();
            assert!(line.ends_with(" N"), "{line}");
        }
        let samples = stdout.lines().find(|l| l.starts_with("force_stats: samples = ")).unwrap();
        assert!(samples.trim_end().chars().last().unwrap().is_ascii_digit(), "{samples}");
    };
    let o = evflow(&["run", "graphs/display-live.toml", "-q", "--out", dir.path().to_str().unwrap()]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    with_units(&stdout);
    let out = dir.path().join("s");
    let o = evflow(&["live", "graphs/display-live.toml", "--duration", "0.3", "--out", out.to_str().unwrap()]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    let six_digits = |stdout: &str| {
        let rms = stdout.lines().find(|l| l.starts_with("force_stats: rms = ")).unwrap_or_else(|| panic!("{stdout}"));
        let number = rms.trim_start_matches("force_stats: rms = ").split(' ').next().unwrap();
        let mantissa = number.split('e').next().unwrap();
        let significant = mantissa.chars().filter(char::is_ascii_digit).skip_while(|c| *c == '0').count();
        assert!(significant <= 6, "{rms}");
    };
    six_digits(&stdout);
    with_units(&stdout);
    // And its replay.
    let session = std::fs::read_dir(out.join("sessions")).unwrap().next().unwrap().unwrap().path();
    let o = evflow(&["replay", session.to_str().unwrap()]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    six_digits(&stdout);
    with_units(&stdout);
}

/// A scheduled `--change` is echoed on the console as it lands, with its
/// time; `-q` keeps the console quiet (issue 37, point 13).
#[test]
fn live_echoes_a_scheduled_change_as_it_lands() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let args = ["live", "graphs/display-live.toml", "--duration", "0.3", "--change", "0.1:gain.gain=0.5", "--out", out];
    let o = evflow(&args);
    let (_, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.lines().any(|l| l == "at 0.100 s: gain.gain = 0.5"), "{stderr}");
    // The end says what was recorded and how to record more (point 12).
    assert!(
        text(&o).0.contains("every source's outputs and every safety guard's; `--tap NODE.PORT`"),
        "{}",
        text(&o).0
    );
    assert!(!stderr.contains(".enable = 0"), "the ending's fade-out is not echoed: {stderr}");
    let quiet = dir.path().join("quiet");
    let o = evflow(&[&args[..6], &["--out", quiet.to_str().unwrap(), "-q"]].concat());
    assert!(o.status.success(), "{}", text(&o).1);
    assert!(!text(&o).1.contains("gain.gain = 0.5"), "{}", text(&o).1);
}

#[cfg(unix)]
#[test]
fn links_planted_at_the_temporary_names_are_never_written_through() {
    // Issue 37, point 2: `ln -s /elsewhere/X.wav out/excitation-85g-5cms.wav.tmp`
    // before `evflow run graphs/excitation.toml --out out` wrote the
    // recording through the link (overwriting the file it points to) and
    // renamed the link to the final name; the same for `.json.tmp` and the
    // tables' temporaries.
    let dir = tempfile::tempdir().unwrap();
    let (out, elsewhere) = (dir.path().join("out"), dir.path().join("elsewhere"));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    let planted = [
        "excitation-85g-5cms.wav.tmp",
        "excitation-85g-5cms.json.tmp",
        "grid.csv.tmp",
        ".grid.csv.tmp",
        "results.json.tmp",
        ".results.json.tmp",
    ];
    for (k, name) in planted.iter().enumerate() {
        let target = elsewhere.join(format!("X{k}"));
        std::fs::write(&target, "precious").unwrap();
        std::os::unix::fs::symlink(&target, out.join(name)).unwrap();
    }
    let (csv, json) = (out.join("grid.csv"), out.join("results.json"));
    let o = evflow(&[
        "run",
        "graphs/excitation.toml",
        "--out",
        out.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stdout}{stderr}");
    for (k, name) in planted.iter().enumerate() {
        let t = std::fs::read_to_string(elsewhere.join(format!("X{k}"))).unwrap();
        assert_eq!(t, "precious", "written through the link {name}");
    }
    for name in ["excitation-85g-5cms.wav", "excitation-85g-5cms.json", "grid.csv", "results.json"] {
        let m = std::fs::symlink_metadata(out.join(name)).unwrap();
        assert!(m.file_type().is_file(), "{name} is not a regular file");
    }
    let r = evflow_nodes::recording::format::Recording::open(&out.join("excitation-85g-5cms")).unwrap();
    assert_eq!(r.frames(), 3066);
    // The planted links are left where they were, untouched.
    for name in planted {
        assert!(std::fs::symlink_metadata(out.join(name)).unwrap().file_type().is_symlink(), "{name}");
    }
}
