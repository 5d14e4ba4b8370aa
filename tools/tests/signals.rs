//! A caught signal (SIGINT, SIGTERM, SIGHUP) during `evflow import` or
//! `evflow run` leaves no temporary file and no half-written output: the
//! signal is sent the moment the `.tmp` file appears, mid-write.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn spawn(args: &[&str], dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_evflow"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("evflow starts")
}

/// Waits until `file` exists (or `child` ends), then sends `signal`.
/// Whether the file was seen.
fn signal_when(child: &mut Child, file: &Path, signal: &str) -> bool {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(60) {
        if file.exists() {
            let ok = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
            assert!(ok.success());
            return true;
        }
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    panic!("{} never appeared", file.display());
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn an_interrupted_import_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // 3 million frames: a 48 MB recording, written in pieces.
    let mut csv = String::with_capacity(40 << 20);
    csv.push_str("force,x\n");
    for i in 0..3_000_000u32 {
        csv.push_str(&format!("{:.3},{:.1}\n", f64::from(i % 1000) * 1e-3, f64::from(i % 7) * 0.5));
    }
    std::fs::write(dir.path().join("big.csv"), csv).unwrap();
    for signal in ["TERM", "INT", "HUP"] {
        let out = dir.path().join(format!("out-{signal}"));
        std::fs::create_dir(&out).unwrap();
        let out_arg = format!("out-{signal}/");
        let mut child = spawn(&["import", "big.csv", "--rate", "10000", "--out", &out_arg], dir.path());
        let seen = signal_when(&mut child, &out.join("big.wav.tmp"), signal);
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        let left = files(&out);
        if seen && !o.status.success() {
            assert!(left.is_empty(), "SIG{signal}: left {left:?}; {stderr}");
            assert!(stderr.contains("import interrupted; nothing was written"), "SIG{signal}: {stderr}");
        } else {
            // It finished before the signal landed: the whole recording.
            assert_eq!(left, ["big.json", "big.wav"], "SIG{signal}: {stderr}");
        }
    }
}

#[test]
fn a_run_stopped_by_sigterm_leaves_no_temporary_recording() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("g.toml"),
        "[graph]\nformat = 1\nname = \"g\"\nrate = 1000\nconnections = [\"s.out -> r.x\"]\n\
         [nodes.s]\ntype = \"sine\"\n[nodes.r]\ntype = \"recording.out\"\npath = \"long\"\nchannels = [\"x\"]\n",
    )
    .unwrap();
    for signal in ["TERM", "HUP", "INT"] {
        let out = dir.path().join(format!("out-{signal}"));
        let out_arg = format!("out-{signal}");
        // An hour of signal: far longer than the test waits.
        let mut child = spawn(&["run", "g.toml", "--duration", "3600", "--out", &out_arg], dir.path());
        assert!(signal_when(&mut child, &out.join("long.wav.tmp"), signal), "the run ended by itself");
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "SIG{signal}: {stderr}");
        let left = files(&out);
        assert!(left.is_empty(), "SIG{signal}: left {left:?}; {stderr}");
    }
}
