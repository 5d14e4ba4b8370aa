//! Serial hardware I/O end to end, over real pseudo-terminals: `evflow live
//! graphs/display-serial.toml` against the device emulator `evflow devsim`.
//!
//! - the actuation the graph computes reaches the device sample for sample,
//!   and the force the emulated display renders from it (reproduced here
//!   bit for bit with the display model) comes back to the graph;
//! - killing the emulator mid-session fades the output to exactly zero and
//!   reports the loss; the session's recordings stay intact and replay bit
//!   for bit; a restarted emulator is found again and, once re-armed, the
//!   actuation flows to it;
//! - corrupted frames (bad CRC, truncated, garbage) are counted and skipped.
#![cfg(all(feature = "serial", unix))]

use evflow_nodes::lab::display_model::DisplayModel;
use evflow_nodes::lab::integrator::Method;
use evflow_nodes::lab::LabProfile;
use evflow_nodes::serial::message::actuation_to_i16;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStderr, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

#[path = "common/serial.rs"]
mod common;
use common::{channel, in_order, value};

/// The tests run one at a time: each runs a live session and an emulator,
/// and two cores shared by several would starve them.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow() -> Command {
    Command::new(env!("CARGO_BIN_EXE_evflow"))
}

fn graph() -> PathBuf {
    root().join("graphs/display-serial.toml")
}

/// An emulator on a pty behind the symbolic link `link`, logging to `log`.
fn devsim(link: &Path, log: &Path, extra: &[&str]) -> Child {
    let mut c = evflow()
        .arg("devsim")
        .arg("--link")
        .arg(link)
        .arg("--log")
        .arg(log)
        .args(["--duration", "120"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("evflow devsim");
    let mut lines = BufReader::new(c.stdout.take().unwrap()).lines();
    let first = lines.next().expect("devsim prints its device").unwrap();
    assert!(first.contains("emulated device on /dev/"), "{first}");
    // Keep draining its output so it never blocks on a full pipe.
    std::thread::spawn(move || for _ in lines {});
    c
}

/// Lines of a child's stderr, as they come.
fn lines_of(e: ChildStderr) -> Receiver<String> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for l in BufReader::new(e).lines().map_while(Result::ok) {
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    rx
}

/// Waits for a line containing `what`; returns every line seen meanwhile.
fn wait_line(rx: &Receiver<String>, what: &str, seen: &mut Vec<String>) {
    let until = Instant::now() + Duration::from_secs(30);
    loop {
        match rx.recv_timeout(until.saturating_duration_since(Instant::now())) {
            Ok(l) => {
                let hit = l.contains(what);
                seen.push(l);
                if hit {
                    return;
                }
            }
            Err(RecvTimeoutError::Timeout) => panic!("no line with `{what}` within 30 s: {seen:#?}"),
            Err(RecvTimeoutError::Disconnected) => panic!("the process ended before `{what}`: {seen:#?}"),
        }
    }
}

/// Runs the serial texture graph live for 2 s against the device at `link`,
/// recording the session into `session`; returns its output, and fails the
/// test if the run failed.
fn live_two_seconds(link: &Path, session: &Path) -> String {
    let out = evflow()
        .arg("live")
        .arg(graph())
        .arg("--set")
        .arg(format!("port={}", link.display()))
        // A starved test machine must not take the link down here.
        .args(["--set", "timeout=2"])
        .args(["--duration", "2", "--no-realtime", "--miss-streak", "0", "-q", "--session"])
        .arg(session)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    // -q: the I/O thread's link notices go to the summary (stdout), not stderr.
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("connected at sample"), "-q printed a link notice: {err}");
    assert!(text.contains("connected at sample"), "the summary lists the link events: {text}");
    text
}

#[test]
fn the_force_the_device_renders_from_the_actuation_comes_back() {
    let _one = one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let (link, log, s) = (tmp.path().join("dev"), tmp.path().join("log"), tmp.path().join("session"));
    let mut dev = devsim(&link, &log, &[]);
    let text = live_two_seconds(&link, &s);
    std::thread::sleep(Duration::from_millis(800));
    dev.kill().unwrap();
    dev.wait().unwrap();

    // The link was up throughout, with no bad frames.
    let connected = channel(&s, "inputs/device", "connected");
    assert!(connected.len() >= 1900 && connected.iter().all(|&c| c == 1.0), "{text}");
    assert_eq!(value(&text, "device: bad_crc"), 0.0);
    assert_eq!(value(&text, "device: lost_frames"), 0.0);

    // Every actuation sample the limiter put out reached the device, in
    // order (the I/O thread may have added stall-fade frames in between).
    // Quantized as the host does: through the f32 of its ring to the I/O thread.
    let sent: Vec<i16> =
        channel(&s, "outputs/limit.out", "out").iter().map(|u| actuation_to_i16(*u as f32 as f64).0).collect();
    let got: Vec<i16> = channel(&log, "actuation", "u").iter().map(|u| actuation_to_i16(*u).0).collect();
    let (missing, extra) = in_order(&sent, &got);
    let stale = value(&text, "display: dropped_stale") + value(&text, "display: ring_overruns");
    assert!(
        missing as f64 <= stale,
        "{missing} samples never reached the device ({stale} dropped after stalls)\n{text}"
    );
    assert!(extra <= 10 * value(&text, "display: stall_fades") as usize + 2, "{extra} extra frames\n{text}");
    assert!(sent.iter().filter(|v| v.unsigned_abs() > 20_000).count() > 100, "0.8 amplitude got through");

    // The force the session recorded is the force the device computed (as
    // f32), in order.
    let rendered: Vec<f32> = channel(&log, "device", "force").iter().map(|f| *f as f32).collect();
    let force = channel(&s, "inputs/device", "force");
    let mut distinct: Vec<f32> = force.iter().map(|f| *f as f32).collect();
    distinct.dedup();
    let mut it = rendered.iter();
    assert!(
        distinct.iter().skip(1).all(|f| it.any(|r| r == f)),
        "recorded force values come from the device, in order"
    );
    // One fresh sample per tick, less those skipped when the real-time
    // thread fell behind and caught up (a loaded machine).
    assert!(distinct.len() > 400, "{} distinct force samples", distinct.len());

    // Physics: the force the device sent is the virtual display's response
    // (the model of `sim.display`, nominal lab, devsim's seed 1) to the
    // actuation it played, on its own clock: replayed here bit for bit. The
    // same display left undriven gives another force: the difference is
    // the electrovibration the graph's actuation rendered.
    let played = channel(&log, "device", "u");
    let dforce = channel(&log, "device", "force");
    let (dload, dvel) = (channel(&log, "device", "load"), channel(&log, "device", "velocity"));
    let profile = LabProfile::default();
    let model = || DisplayModel::new(&profile, 1000.0, Method::Exact, 4, 1.0, 1).unwrap();
    let (mut driven, mut undriven) = (model(), model());
    let (mut diff2, mut n_on) = (0.0, 0usize);
    for k in 0..dforce.len() {
        let f = driven.step(played[k], dload[k], dvel[k]);
        assert_eq!(f.to_bits(), dforce[k].to_bits(), "device force at its tick {k}");
        let f0 = undriven.step(0.0, dload[k], dvel[k]);
        if played[k].abs() > 0.1 {
            diff2 += (f - f0).powi(2);
            n_on += 1;
        }
    }
    assert!(n_on > 1000, "the device played the actuation for {n_on} ms");
    let rms = (diff2 / n_on as f64).sqrt();
    eprintln!("the actuation changed the rendered force by {rms:.4} N rms");
    assert!(rms > 0.005, "the actuation changed the rendered force by {rms} N rms");
    // Touch frames: the finger scans at 5 cm/s with about 0.8 N.
    let x = channel(&s, "inputs/device", "x");
    assert!(x[1999] - x[100] > 0.05 && x[1999] - x[100] < 0.1, "moved {} m in 1.9 s", x[1999] - x[100]);
    let load = channel(&s, "inputs/device", "load");
    assert!(load[100..].iter().all(|l| (0.7..0.9).contains(l)));
}

#[test]
fn unplugging_fades_to_zero_and_a_restarted_device_is_found_again() {
    let _one = one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let (link, s) = (tmp.path().join("dev"), tmp.path().join("session"));
    let mut first = devsim(&link, &tmp.path().join("log1"), &[]);
    let mut live = evflow()
        .arg("live")
        .arg(graph())
        .arg("--set")
        .arg(format!("port={}", link.display()))
        .args([
            "--set",
            "retry=0.1",
            "--set",
            "timeout=2",
            "--endless",
            "--no-realtime",
            "--miss-streak",
            "0",
            // Not -q: the link notices on stderr are what this test follows.
            "--session",
        ])
        .arg(&s)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let err = lines_of(live.stderr.take().unwrap());
    let mut seen = Vec::new();
    wait_line(&err, "connected at sample", &mut seen);
    std::thread::sleep(Duration::from_millis(800));
    first.kill().unwrap(); // the pty closes under the host
    first.wait().unwrap();
    wait_line(&err, "link lost at sample", &mut seen);
    std::thread::sleep(Duration::from_millis(300));
    let log2 = tmp.path().join("log2");
    let mut second = devsim(&link, &log2, &[]);
    wait_line(&err, "connected at sample", &mut seen);
    std::thread::sleep(Duration::from_millis(200));
    let mut stdin = live.stdin.take().unwrap();
    writeln!(stdin, "limit.enable=true").unwrap();
    std::thread::sleep(Duration::from_millis(800));
    writeln!(stdin, "stop").unwrap();
    let out = live.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{text}\n{seen:#?}");
    std::thread::sleep(Duration::from_millis(300));
    second.kill().unwrap();
    second.wait().unwrap();

    // The loss is reported, with the limiter's fault.
    assert!(text.contains("device: link lost at sample"), "{text}");
    assert!(text.contains("limit: fault: input `link` raised at sample"), "{text}");
    assert_eq!(value(&text, "device: connects"), 2.0);
    assert_eq!(value(&text, "device: disconnects"), 1.0);

    // The recordings: connected 1 → 0 → 1; the actuation fades to exactly 0
    // within 10 ms of the fault and stays there until re-armed.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("session.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "ended");
    let connected = channel(&s, "inputs/device", "connected");
    let fault = channel(&s, "inputs/device", "fault");
    let u = channel(&s, "outputs/limit.out", "out");
    let lost = connected.iter().position(|&c| c == 0.0).expect("the loss is recorded");
    let back = lost + connected[lost..].iter().position(|&c| c == 1.0).expect("the link came back");
    assert!(connected[..lost].iter().all(|&c| c == 1.0));
    assert_eq!(fault[lost], 1.0);
    assert!(u[..lost].iter().any(|x| x.abs() > 0.5), "actuation flowed before the loss");
    let events = std::fs::read_to_string(s.join("events.jsonl")).unwrap();
    let rearm = events
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .find(|e| e["event"] == "set" && e["param"] == "enable" && e["value"] == 1.0)
        .and_then(|e| e["tick"].as_u64())
        .expect("the re-arm is logged") as usize;
    assert!(rearm > back);
    assert!(u[lost + 10..rearm].iter().all(|&x| x == 0.0), "zero from 10 ms after the loss until the re-arm");
    assert!(u[rearm..].iter().any(|x| x.abs() > 0.5), "the actuation flows again after the re-arm");
    // ... and reaches the new device.
    let got = channel(&log2, "actuation", "u");
    assert!(got.iter().any(|x| x.abs() > 0.5), "the restarted device received the actuation");

    // The session replays bit for bit (serial.in's recording stands in for
    // the device; serial.out stays off the port offline).
    let r = evflow().arg("replay").arg(&s).args(["--check", "-q"]).output().unwrap();
    let rt = String::from_utf8_lossy(&r.stdout).into_owned() + &String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{rt}");
    assert!(rt.contains("limit.out: identical to the live session, bit for bit"), "{rt}");
}

#[test]
fn corrupt_frames_are_counted_and_skipped() {
    let _one = one_at_a_time();
    let tmp = tempfile::tempdir().unwrap();
    let (link, log, s) = (tmp.path().join("dev"), tmp.path().join("log"), tmp.path().join("session"));
    let mut dev = devsim(&link, &log, &["--corrupt", "0.05", "--seed", "3"]);
    let text = live_two_seconds(&link, &s);
    // Stop the emulator only once the host has closed, so its counts cover the session.
    std::thread::sleep(Duration::from_millis(300));
    dev.kill().unwrap();
    dev.wait().unwrap();
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(log.join("stats.json")).unwrap()).unwrap();
    let inj = |k: &str| stats["injected"][k].as_f64().unwrap();

    let (bad, cut, garbage, lost) = (
        value(&text, "device: bad_crc"),
        value(&text, "device: truncated"),
        value(&text, "device: garbage_bytes"),
        value(&text, "device: lost_frames"),
    );
    assert!(bad >= 20.0 && cut >= 20.0, "{text}");
    // What the host rejected is what the emulator damaged (it may have
    // damaged a few more after the host closed, or before it opened).
    assert!(bad + cut <= inj("bad_crc") + inj("truncated") + 3.0, "{text}\n{stats}");
    assert!(garbage >= 0.9 * inj("garbage_bytes"), "{text}\n{stats}");
    // Each rejected frame is one missing sequence number.
    assert!((lost - (bad + cut)).abs() <= 0.03 * lost + 3.0, "lost {lost}, rejected {}", bad + cut);
    // The link held and the rest came through.
    let connected = channel(&s, "inputs/device", "connected");
    let down = connected.iter().filter(|&&c| c == 0.0).count();
    assert!(down == 0, "link down for {down} ticks (first at {:?})\n{text}", connected.iter().position(|&c| c == 0.0));
    assert!(value(&text, "device: frames") > 1800.0, "{text}");
    assert!(channel(&s, "inputs/device", "force").iter().all(|f| f.is_finite() && f.abs() < 5.0));
}

#[test]
fn devsim_help_explains_it() {
    let o = evflow().args(["devsim", "--help"]).output().unwrap();
    let t = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    for w in ["pseudo-terminal", "--link", "--corrupt", "--log", "Example"] {
        assert!(t.contains(w), "`{w}` missing from devsim --help:\n{t}");
    }
}
