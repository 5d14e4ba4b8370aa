//! `serial.in` and `serial.out` in a plan stepped one tick per millisecond
//! (as the live runner does) against a device on a pseudo-terminal: what
//! the graph sends arrives, what the device sends comes back, a vanished
//! device fades the output and the link comes back; errors name the port.

use super::device::{DeviceConfig, DeviceSession};
use super::message::{self, Message, Touch};
use evflow_engine::{check, graph::parse_graph, Override, Plan, PlanOptions, RunMode};
use serialport::{SerialPort, TTYPort};
use std::io::{ErrorKind, Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What a test device saw.
#[derive(Debug, Default)]
struct Log {
    received: Vec<i16>,
    hellos: u64,
}

/// A device on the master side of a fresh pty: answers HELLO, sends force
/// = its tick count (1 kHz) and a touch frame every 25 ms.
struct TestDevice {
    slave: String,
    stop: Arc<AtomicBool>,
    /// Actuation samples received so far.
    received: Arc<AtomicUsize>,
    thread: std::thread::JoinHandle<Log>,
}

impl TestDevice {
    fn spawn(config: DeviceConfig) -> Self {
        let (mut master, slave) = TTYPort::pair().expect("a pty pair");
        let path = slave.name().expect("the slave's path");
        drop(slave);
        master.set_timeout(Duration::from_millis(1)).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let received = Arc::new(AtomicUsize::new(0));
        let count = received.clone();
        let thread = std::thread::spawn(move || {
            let t0 = Instant::now();
            let mut dev = DeviceSession::new(config, t0);
            let mut log = Log::default();
            let (mut buf, mut out) = ([0u8; 1024], Vec::new());
            let mut tick = 0u64;
            let mut host = false;
            while !s.load(Ordering::Acquire) {
                match master.read(&mut buf) {
                    Ok(n) if n > 0 => {
                        host = true;
                        dev.receive(Instant::now(), &buf[..n], &mut out, &mut |v| log.received.push(v));
                        count.store(log.received.len(), Ordering::Release);
                    }
                    Err(e) if e.kind() == ErrorKind::TimedOut => host = true,
                    _ => {
                        // No host on the slave side (POLLHUP): wait for one.
                        if host {
                            dev.host_gone();
                            host = false;
                        }
                        std::thread::sleep(Duration::from_millis(1));
                    }
                }
                let now = Instant::now();
                while tick < now.duration_since(t0).as_millis() as u64 {
                    tick += 1;
                    dev.play(now, &mut out);
                    if dev.engaged() {
                        dev.send(Message::Force(tick as f32), &mut out);
                        if tick.is_multiple_of(25) {
                            let x = tick as f32 * 1e-4;
                            dev.send(Message::Touch(Touch { x, y: 0.03, load: 0.8, flags: 1 }), &mut out);
                        }
                        if tick.is_multiple_of(100) {
                            dev.heartbeat(now, &mut out);
                        }
                    }
                }
                if host && !out.is_empty() {
                    let _ = master.write_all(&out);
                }
                out.clear();
            }
            log.hellos = dev.counters().hellos;
            log
        });
        Self { slave: path, stop, received, thread }
    }

    /// Waits until the device has received `n` actuation samples, or `within` passed.
    fn wait_for(&self, n: usize, within: Duration) {
        let until = Instant::now() + within;
        while self.received.load(Ordering::Acquire) < n && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    fn stop(self) -> Log {
        self.stop.store(true, Ordering::Release);
        self.thread.join().unwrap()
    }
}

const GRAPH: &str = r#"
[graph]
format = 1
name = "t"
rate = 1000.0
connections = ["drive.out -> limit.in", "dev.fault -> limit.link", "limit.out -> out.u", "dev.force -> st.in"]
[vars]
port = ""
wait = 2.0
[nodes.dev]
type = "serial.in"
port = "$port"
wait = "$wait"
retry = 0.05
timeout = 2.0
[nodes.drive]
type = "sine"
frequency = 50.0
amplitude = 0.7
[nodes.limit]
type = "limit"
faults = ["link"]
[nodes.out]
type = "serial.out"
port = "$port"
wait = "$wait"
retry = 0.05
timeout = 2.0
[nodes.st]
type = "stats"
"#;

/// A live plan (blocks of one tick) on `port`.
fn plan(port: &str, wait: f64) -> Result<Plan, String> {
    plan_as(port, RunMode::Live, 1, wait)
}

fn plan_as(port: &str, mode: RunMode, max_block: usize, wait: f64) -> Result<Plan, String> {
    let g = parse_graph(Path::new("t.toml"), GRAPH).map_err(|e| e.to_string())?;
    let o = [Override::parse(&format!("port={port}")).unwrap(), Override::parse(&format!("wait={wait}")).unwrap()];
    let checked = check(&g, &crate::registry(), &o).map_err(|e| e.to_string())?;
    Plan::build(&checked, &PlanOptions { max_block, mode, ..Default::default() }).map_err(|e| e.to_string())
}

/// Per tick: serial.in's outputs (x, y, load, force, contact, connected,
/// fault) and the limiter's output.
type Row = ([f64; 7], f64);

/// Ticks `plan` `n` times, one per millisecond.
fn run(plan: &mut Plan, n: usize) -> Vec<Row> {
    let dev = plan.index("dev").unwrap();
    let lim = plan.index("limit").unwrap();
    let t0 = Instant::now();
    let mut rows = Vec::new();
    for k in 0..n {
        let due = t0 + Duration::from_millis(k as u64);
        if let Some(d) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(d);
        }
        plan.tick().unwrap();
        let mut r = [0.0; 7];
        for (j, v) in r.iter_mut().enumerate() {
            *v = plan.output_at(dev, j)[0];
        }
        rows.push((r, plan.output_at(lim, 0)[0]));
    }
    rows
}

/// (values of `want` missing from `have`, values of `have` not in `want`),
/// by the longest common subsequence.
fn lcs_diff(want: &[i16], have: &[i16]) -> (usize, usize) {
    let mut prev = vec![0u32; have.len() + 1];
    let mut row = vec![0u32; have.len() + 1];
    for w in want {
        for (j, h) in have.iter().enumerate() {
            row[j + 1] = if w == h { prev[j] + 1 } else { prev[j + 1].max(row[j]) };
        }
        std::mem::swap(&mut prev, &mut row);
    }
    let common = prev[have.len()] as usize;
    (want.len() - common, have.len() - common)
}

#[test]
fn a_live_plan_exchanges_samples_with_the_device() {
    let dev = TestDevice::spawn(DeviceConfig::default());
    let mut p = plan(&dev.slave, 5.0).unwrap();
    let rows = run(&mut p, 400);
    let summaries = p.finish().unwrap();
    drop(p); // the link closes: a zero sample goes out last
             // Everything sent reaches the device (a loaded machine may take a
             // while to run its thread).
    let sent = summaries.iter().find(|(n, _)| n == "out").and_then(|(_, o)| o.get("sent")).unwrap_or(0.0);
    dev.wait_for(sent as usize, Duration::from_secs(5));
    let log = dev.stop();

    assert!(rows.iter().all(|(r, _)| r[5] == 1.0 && r[6] == 0.0), "connected throughout, no fault");
    // Touch frames: x = tick·1e-4 every 25 ms, held between frames.
    let xs: Vec<f64> = rows.iter().map(|(r, _)| r[0]).collect();
    assert!(xs.windows(2).all(|w| w[1] >= w[0]), "x only grows");
    assert!(xs.last().unwrap() > &0.0);
    assert!(rows.iter().skip(50).all(|(r, _)| r[1] == 0.03f32 as f64 && r[2] == 0.8f32 as f64 && r[4] == 1.0));
    // Force = the device's tick count, one fresh sample on most ticks, never going back.
    let f: Vec<f64> = rows.iter().map(|(r, _)| r[3]).collect();
    assert!(f.windows(2).all(|w| w[1] >= w[0]));
    let fresh = f.windows(2).filter(|w| w[1] > w[0]).count();
    assert!(fresh > 200, "{fresh} of 400 ticks had a new force sample");
    // Every limiter output sample reached the device, in order, quantized
    // (the I/O thread's stall fade may add frames when this thread stalls).
    let sent: Vec<i16> = rows.iter().map(|(_, u)| message::actuation_to_i16(*u).0).collect();
    let o = &summaries.iter().find(|(n, _)| n == "out").unwrap().1;
    let (missing, extra) = lcs_diff(&sent, &log.received);
    let dropped = o.get("dropped_stale").unwrap() + o.get("ring_overruns").unwrap();
    assert!(missing as f64 <= dropped, "{missing} samples never arrived ({dropped} dropped after stalls)");
    assert!(extra as f64 <= 10.0 * o.get("stall_fades").unwrap() + 1.0, "{extra} extra frames: {o:?}");
    assert!(sent.iter().any(|v| v.unsigned_abs() > 20000), "the sine got through the limiter");
    // Every sample is accounted for: sent, or dropped and counted (after
    // a stall of the I/O thread, or while the link was down).
    let accounted: f64 =
        ["sent", "dropped_stale", "ring_overruns", "dropped_link_down"].iter().map(|k| o.get(k).unwrap()).sum();
    assert_eq!(accounted, 400.0, "{o:?}");
    let s = &summaries.iter().find(|(n, _)| n == "dev").unwrap().1;
    assert_eq!(s.get("bad_crc"), Some(0.0));
    assert_eq!(s.get("connects"), Some(1.0));
}

#[test]
fn a_vanished_device_fades_the_output_and_the_link_comes_back() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("device");
    let dev = TestDevice::spawn(DeviceConfig::default());
    std::os::unix::fs::symlink(&dev.slave, &link).unwrap();
    let mut p = plan(link.to_str().unwrap(), 5.0).unwrap();
    let before = run(&mut p, 100);
    assert!(before.iter().all(|(r, _)| r[5] == 1.0));
    assert!(before.last().unwrap().1 != 0.0);

    dev.stop(); // the pty closes: the port's reads fail
    let mut gone = Vec::new();
    let t = Instant::now();
    while gone.iter().all(|(r, _): &Row| r[5] == 1.0) {
        assert!(t.elapsed() < Duration::from_secs(5), "the disconnect was never noticed");
        gone.extend(run(&mut p, 10));
    }
    gone.extend(run(&mut p, 20));
    let k = gone.iter().position(|(r, _)| r[5] == 0.0).unwrap();
    assert!(gone[k..].iter().all(|(r, _)| r[6] == 1.0), "fault raised with the disconnect");
    assert!(gone[k + 10..].iter().all(|(_, u)| *u == 0.0), "the limiter reached 0 within 10 ms");

    // A new device behind the same path: the node reopens it.
    let dev2 = TestDevice::spawn(DeviceConfig::default());
    std::fs::remove_file(&link).unwrap();
    std::os::unix::fs::symlink(&dev2.slave, &link).unwrap();
    let mut back = Vec::new();
    let t = Instant::now();
    while back.last().is_none_or(|(r, _): &Row| r[5] == 0.0) {
        assert!(t.elapsed() < Duration::from_secs(10), "the link never came back");
        back.extend(run(&mut p, 10));
    }
    assert_eq!(back.last().unwrap().0[6], 0.0, "fault cleared");
    assert!(back.iter().all(|(_, u)| *u == 0.0), "the limiter stays latched until re-armed");
    let k = p.index("limit").unwrap();
    p.set(k, "enable", 1.0).unwrap();
    let armed = run(&mut p, 100);
    assert!(armed.iter().any(|(_, u)| u.abs() > 0.3), "re-armed, the actuation flows again");
    let s = p.finish().unwrap();
    drop(p);
    let log = dev2.stop();
    assert!(log.received.iter().any(|v| v.unsigned_abs() > 10000), "and reaches the new device");
    let d = &s.iter().find(|(n, _)| n == "dev").unwrap().1;
    assert_eq!((d.get("connects"), d.get("disconnects")), (Some(2.0), Some(1.0)));
    assert!(d.lines.iter().any(|l| l.contains("link lost")), "{:?}", d.lines);
}

#[test]
fn errors_name_the_port_and_the_reason() {
    let e = plan("/nonexistent/evflow-tty", 0.05).err().unwrap();
    assert!(e.contains("/nonexistent/evflow-tty") && e.contains("cannot open"), "{e}");
    assert!(e.contains("dev"), "names the node: {e}");

    let dev = TestDevice::spawn(DeviceConfig { version: 2, ..DeviceConfig::default() });
    let e = plan(&dev.slave, 0.5).err().unwrap();
    assert!(e.contains("protocol version 2"), "{e}");
    dev.stop();
}

#[test]
fn wait_zero_starts_unconnected_and_says_why() {
    // Before: `wait = 0` failed at once with "the device did not answer
    // HELLO", hiding that the port does not exist.
    let mut p = plan("/nonexistent/evflow-tty-wait0", 0.0).expect("starts without its device");
    let rows = run(&mut p, 100);
    assert!(rows.iter().all(|(r, out)| r[5] == 0.0 && r[6] == 1.0 && *out == 0.0), "unconnected, faulted, silent");
    let s = p.finish().unwrap();
    let dev = &s.iter().find(|(n, _)| n == "dev").unwrap().1;
    assert!(
        dev.lines.iter().any(|l| l.contains("cannot open /nonexistent/evflow-tty-wait0") && l.contains("No such file")),
        "{:?}",
        dev.lines
    );
}

#[test]
fn offline_runs_never_open_the_port_whatever_their_block_size() {
    // Blocks of 4096 (`evflow run`, a replay) and of one tick (`evflow run
    // --block 1`, a replay with --block 1): offline is offline.
    for max_block in [4096, 1] {
        let dev = TestDevice::spawn(DeviceConfig::default());
        let mut p = plan_as(&dev.slave, RunMode::Offline, max_block, 2.0).unwrap();
        for _ in 0..(4096 / p.max_block()) {
            p.step(p.max_block()).unwrap();
        }
        let s = p.finish().unwrap();
        let d = &s.iter().find(|(n, _)| n == "dev").unwrap().1;
        assert!(d.lines[0].contains("offline run"), "{:?}", d.lines);
        drop(p);
        std::thread::sleep(Duration::from_millis(50));
        let log = dev.stop();
        assert_eq!((log.hellos, log.received.len()), (0, 0), "blocks of {max_block}: the device heard nothing");
    }
}

#[test]
fn one_node_of_each_direction_per_port() {
    let dev = TestDevice::spawn(DeviceConfig::default());
    let p = plan(&dev.slave, 5.0).unwrap();
    let e = plan(&dev.slave, 5.0).err().unwrap();
    assert!(e.contains("already has a `serial.in`"), "{e}");
    drop(p);
    dev.stop();
}

#[test]
fn nodes_on_one_port_must_agree_on_its_settings() {
    let dev = TestDevice::spawn(DeviceConfig::default());
    let text = GRAPH.replace(
        "[nodes.out]\ntype = \"serial.out\"\nport = \"$port\"\nwait = \"$wait\"\nretry = 0.05\ntimeout = 2.0",
        "[nodes.out]\ntype = \"serial.out\"\nport = \"$port\"\nwait = \"$wait\"\nretry = 0.05\ntimeout = 2.0\nbaud = 115200",
    );
    assert_ne!(text, GRAPH);
    let g = parse_graph(Path::new("t.toml"), &text).unwrap();
    let o = [Override::parse(&format!("port={}", dev.slave)).unwrap()];
    let checked = check(&g, &crate::registry(), &o).unwrap();
    let live = PlanOptions { max_block: 1, mode: RunMode::Live, ..Default::default() };
    let e = Plan::build(&checked, &live).err().unwrap().to_string();
    assert!(e.contains("other settings") && e.contains("baud 921600"), "{e}");
    dev.stop();
}
