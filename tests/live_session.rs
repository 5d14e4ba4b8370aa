//! `evflow live` end to end: a session killed with `kill -9` leaves
//! readable recordings; `evflow replay` reproduces a session's outputs bit
//! for bit (parameter changes included); Ctrl-C fades the actuation to zero
//! before the process ends.

use evflow_nodes::recording::format::Recording;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The `evflow` binary beside this test's (built if it is missing).
fn evflow() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    let dir = exe.parent().and_then(Path::parent).expect("target/<profile>");
    let bin = dir.join("evflow");
    if !bin.exists() {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.args(["build", "-q", "-p", "evflow"]);
        if dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        assert!(cmd.status().expect("cargo build").success(), "building evflow failed");
    }
    bin
}

fn graph() -> PathBuf {
    evflow_tests::root().join("graphs/display-live.toml")
}

fn live(session: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(evflow());
    c.arg("live").arg(graph()).arg("--session").arg(session).args(["--no-realtime", "--miss-streak", "0", "-q"]);
    c.args(args).stdin(Stdio::null());
    c
}

fn replay(session: &Path, args: &[&str]) -> (bool, String) {
    let (code, out, err) = replay_apart(&[session.as_os_str()], args);
    (code == Some(0), out + &err)
}

/// `evflow replay SESSIONS ARGS`: the exit code, stdout and stderr.
fn replay_apart(sessions: &[&std::ffi::OsStr], args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(evflow()).arg("replay").args(sessions).args(args).output().expect("evflow replay");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.code(), text(&out.stdout), text(&out.stderr))
}

/// Frames the sidecar of a live recording claims (0 when not yet readable).
fn sidecar_frames(path: &Path) -> u64 {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v["frames"].as_u64())
        .unwrap_or(0)
}

#[test]
fn a_session_killed_with_sigkill_leaves_readable_recordings_that_replay_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let s = tmp.path().join("killed");
    let mut child = live(&s, &["--endless", "--change", "0.3:gain.gain=0.4"]).spawn().expect("evflow live");
    let started = Instant::now();
    while sidecar_frames(&s.join("outputs/limit.out.json")) < 600 {
        assert!(started.elapsed() < Duration::from_secs(60), "the session never flushed 600 frames");
        assert!(child.try_wait().unwrap().is_none(), "evflow live ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL: no handler, no cleanup
    child.wait().unwrap();

    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("session.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "running", "killed before it could write its end");
    for f in ["inputs/drive", "inputs/tribometer", "outputs/limit.out"] {
        let r = Recording::open(&s.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(r.frames() >= 600, "{f}: {} frames", r.frames());
    }
    let out = Recording::open(&s.join("outputs/limit.out")).unwrap();
    assert!(out.channel("out").unwrap().iter().all(|x| x.is_finite() && x.abs() <= 1.0));
    let (ok, text) = replay(&s, &["-q"]);
    assert!(ok, "{text}");
    assert!(text.contains("limit.out: identical to the live session, bit for bit"), "{text}");
    // What a killed session cannot prove is said.
    assert!(text.contains("could not check that the recordings are whole: the session did not end"), "{text}");

    // Issue 37, point 4: `--check` cannot prove a killed session — nor one
    // of its outputs cut to half, which a killed session cannot tell from
    // a short one: exit status 3 (not 0, not 1), and why on stderr, with -q.
    let halved = tmp.path().join("halved");
    copy_session(&s, &halved);
    let p = halved.join("outputs/limit.out.wav");
    let len = std::fs::metadata(&p).unwrap().len();
    std::fs::OpenOptions::new().write(true).open(&p).unwrap().set_len(44 + (len - 44) / 2).unwrap();
    let why = "the replay could not prove the live session: could not check that the recordings are whole: \
               the session did not end (status `running`: killed?)";
    for session in [&s, &halved] {
        let (code, out, err) = replay_apart(&[session.as_os_str()], &["--check", "-q"]);
        assert_eq!(code, Some(3), "{}: {out}{err}", session.display());
        assert!(err.contains(why), "{err}");
        assert!(out.contains("limit.out: identical to the live session, bit for bit"), "{out}");
    }
    // Several sessions: the same status when none failed otherwise.
    let out_dir = tmp.path().join("replays");
    let (code, out, err) =
        replay_apart(&[s.as_os_str(), halved.as_os_str()], &["--check", "-q", "--out", out_dir.to_str().unwrap()]);
    assert_eq!(code, Some(3), "{out}{err}");
    assert!(err.contains("2 of 2 sessions failed") && err.contains("could not prove it"), "{err}");
}

#[test]
fn replay_reproduces_a_session_with_changes_bit_for_bit_and_the_stop_fades_to_zero() {
    let tmp = tempfile::tempdir().unwrap();
    let s = tmp.path().join("changes");
    let out = live(
        &s,
        &[
            "--duration",
            "1.0",
            "--tap",
            "sensor.force",
            "--change",
            "0.2:gain.gain=0.3",
            "--change",
            "0.5:limit.enable=false",
            "--change",
            "0.7:limit.enable=true",
        ],
    )
    .output()
    .expect("evflow live");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("stopped: duration"), "{text}");

    let events = std::fs::read_to_string(s.join("events.jsonl")).unwrap();
    assert!(events.contains(r#""node":"gain","param":"gain","tick":200,"value":0.3"#), "{events}");
    let y = Recording::open(&s.join("outputs/limit.out")).unwrap().channel("out").unwrap().to_vec();
    assert_eq!(y.len(), 1011, "1 s plus the 11-tick stop sequence");
    assert!(y[999] != 0.0);
    assert_eq!(y[1009], 0.0, "faded to zero within 10 ms of the stop");
    assert_eq!(y[1010], 0.0);
    assert!(y[509..700].iter().all(|&v| v == 0.0), "disabled from tick 500, faded by 509");

    let (ok, text) = replay(&s, &["--check", "-q", "--block", "333"]);
    assert!(ok, "{text}");
    assert!(text.contains("limit.out: identical to the live session, bit for bit (1011 samples)"), "{text}");
    assert!(text.contains("sensor.force: identical to the live session, bit for bit (1011 samples)"), "{text}");

    // Another graph (here: another initial gain; the sine itself is the
    // recorded input) differs, and --check says so.
    let (ok, text) = replay(&s, &[graph().to_str().unwrap(), "--set", "gain=0.5", "--check", "-q"]);
    assert!(!ok, "{text}");
    assert!(text.contains("limit.out: differs from sample"), "{text}");
}

/// A copy of the session folder `from` at `to`, every file copied.
fn copy_session(from: &Path, to: &Path) {
    for sub in ["", "inputs", "outputs"] {
        std::fs::create_dir_all(to.join(sub)).unwrap();
        for e in std::fs::read_dir(from.join(sub)).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), to.join(sub).join(e.file_name())).unwrap();
            }
        }
    }
}

#[test]
fn replay_check_proves_the_whole_session_and_names_every_tampering() {
    // Issue 27, point 4: a file cut short, a changed input that feeds no
    // recorded output, another seed, another graph.toml — each fails the
    // check with its reason; the untouched session passes.
    let tmp = tempfile::tempdir().unwrap();
    let s = tmp.path().join("whole");
    let out = live(&s, &["--duration", "1.0"]).output().expect("evflow live");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (ok, text) = replay(&s, &["--check", "-q"]);
    assert!(ok && !text.contains("could not check"), "{text}");
    type Tamper = Box<dyn Fn(&Path)>;
    let edit_json = |p: &Path, f: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        f(&mut v);
        std::fs::write(p, v.to_string()).unwrap();
    };
    let wav_len = |p: &Path| std::fs::metadata(p).unwrap().len();
    let cases: Vec<(&str, Tamper, &str)> = vec![
        (
            "cut by 1001 bytes",
            Box::new(move |d: &Path| {
                let p = d.join("outputs/limit.out.wav");
                let f = std::fs::OpenOptions::new().write(true).open(&p).unwrap();
                f.set_len(wav_len(&p) - 1001).unwrap();
            }),
            "outputs/limit.out: holds",
        ),
        (
            "cut to half",
            Box::new(move |d: &Path| {
                let p = d.join("outputs/limit.out.wav");
                let f = std::fs::OpenOptions::new().write(true).open(&p).unwrap();
                f.set_len(44 + (wav_len(&p) - 44) / 2).unwrap();
            }),
            "(cut short)",
        ),
        (
            "an input's last byte changed",
            Box::new(|d: &Path| {
                let p = d.join("inputs/tribometer.wav");
                let mut b = std::fs::read(&p).unwrap();
                let n = b.len();
                b[n - 9] ^= 1;
                std::fs::write(&p, b).unwrap();
            }),
            "inputs/tribometer: its samples changed",
        ),
        (
            "another seed",
            Box::new(|d: &Path| {
                let p = d.join("session.json");
                let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
                v["seed"] = serde_json::json!(v["seed"].as_u64().unwrap() + 1);
                std::fs::write(&p, v.to_string()).unwrap();
            }),
            "session.json: its seed",
        ),
        (
            "graph.toml edited",
            Box::new(|d: &Path| {
                let p = d.join("graph.toml");
                let t = std::fs::read_to_string(&p).unwrap() + "\n# edited\n";
                std::fs::write(&p, t).unwrap();
            }),
            "graph.toml: changed since the session ran it",
        ),
        // Issue 37, point 5.
        (
            "an output sidecar's frames minus one",
            Box::new(move |d: &Path| {
                edit_json(&d.join("outputs/limit.out.json"), &|v| {
                    v["frames"] = serde_json::json!(v["frames"].as_u64().unwrap() - 1)
                })
            }),
            "outputs/limit.out.json: says 1010 frames, the session wrote 1011",
        ),
        (
            "an extra file in inputs",
            Box::new(|d: &Path| {
                std::fs::copy(d.join("inputs/tribometer.wav"), d.join("inputs/extra.wav")).unwrap();
            }),
            "inputs/extra.wav: not a file the session wrote",
        ),
        (
            "session.json padded with an unknown key",
            Box::new(move |d: &Path| edit_json(&d.join("session.json"), &|v| v["padding"] = serde_json::json!("x"))),
            "session.json: `padding` is not a key a session writes",
        ),
        (
            "an unknown key in a file's entry",
            Box::new(move |d: &Path| {
                edit_json(&d.join("session.json"), &|v| v["outputs"][0]["note"] = serde_json::json!(1))
            }),
            "session.json: `outputs[0].note` is not a key a session writes",
        ),
    ];
    for (what, tamper, said) in cases {
        let t = tmp.path().join(what.replace(' ', "-"));
        copy_session(&s, &t);
        tamper(&t);
        let (code, out, err) = replay_apart(&[t.as_os_str()], &["--check", "-q"]);
        assert_eq!(code, Some(1), "{what}: the check did not fail:\n{out}{err}");
        let named = out.lines().any(|l| l.starts_with("not the session's: ") && l.contains(said));
        assert!(named, "{what}: {out}");
    }
    // Accepted by design (docs/security.md): `graph_source` says where the
    // graph file was when the session started; the replay never reads it.
    let t = tmp.path().join("graph-source");
    copy_session(&s, &t);
    edit_json(&t.join("session.json"), &|v| v["graph_source"] = serde_json::json!("/elsewhere/other.toml"));
    let (ok, text) = replay(&t, &["--check", "-q"]);
    assert!(ok && !text.contains("not the session's"), "{text}");
}

#[test]
fn ctrl_c_ends_the_session_with_the_actuation_at_zero() {
    let tmp = tempfile::tempdir().unwrap();
    let s = tmp.path().join("interrupted");
    let child = live(&s, &["--endless"]).stdout(Stdio::piped()).spawn().expect("evflow live");
    let started = Instant::now();
    while sidecar_frames(&s.join("outputs/limit.out.json")) < 300 {
        assert!(started.elapsed() < Duration::from_secs(60), "the session never flushed");
        std::thread::sleep(Duration::from_millis(20));
    }
    // SAFETY: sending SIGINT to our own child process.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("stopped: requested"), "{text}");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("session.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "ended");
    let y = Recording::open(&s.join("outputs/limit.out")).unwrap().channel("out").unwrap().to_vec();
    assert_eq!(manifest["end"]["ticks"].as_u64().unwrap() as usize, y.len());
    assert_eq!(*y.last().unwrap(), 0.0);
    let before_stop = &y[y.len() - 40..y.len() - 11];
    assert!(before_stop.iter().any(|&v| v != 0.0), "running until the stop");
}

#[test]
fn the_rendering_chains_replay_bit_for_bit_multi_rate_sources_included() {
    // sim.user has ports at 1 kHz and at 40 Hz: the session records one file
    // per rate and the replay feeds each back at its own rate.
    // Each switches its texture or scene halfway through a graph variable,
    // which sets two nodes of the mesh chain at one tick.
    for (g, files, change, sets) in [
        ("graphs/texture-live.toml", vec!["inputs/user", "inputs/user-40Hz"], "0.3:texture=3", 1),
        ("graphs/mesh-live.toml", vec!["inputs/finger", "inputs/finger-40Hz"], "0.3:scene=4", 2),
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let s = tmp.path().join("s");
        let status = Command::new(evflow())
            .arg("live")
            .arg(evflow_tests::root().join(g))
            .arg("--session")
            .arg(&s)
            .args(["--no-realtime", "--miss-streak", "0", "--duration", "0.6", "-q", "--change", change])
            .stdin(Stdio::null())
            .status()
            .expect("evflow live");
        assert!(status.success(), "{g}");
        let events = std::fs::read_to_string(s.join("events.jsonl")).unwrap();
        let at_300: Vec<&str> =
            events.lines().filter(|l| l.contains("\"event\":\"set\"") && l.contains("\"tick\":300")).collect();
        assert_eq!(at_300.len(), sets, "{g}: {events}");
        for f in &files {
            assert!(Recording::open(&s.join(f)).is_ok(), "{g}: {f} missing");
        }
        let (ok, text) = replay(&s, &["--check", "-q"]);
        assert!(ok, "{g}: {text}");
        assert!(text.contains("limit.out: identical to the live session, bit for bit"), "{g}: {text}");
    }
}
