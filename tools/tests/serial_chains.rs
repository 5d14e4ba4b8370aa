//! The rendering chains on a serial device, over real pseudo-terminals:
//! `graphs/texture-serial.toml` and `graphs/mesh-serial.toml` run live
//! against `evflow devsim`; the actuation they compute reaches the device
//! (what the emulator logged equals what the limiter put out), and the
//! force the emulated display renders from it comes back into the session.
#![cfg(all(feature = "serial", unix))]

use evflow_nodes::recording::format::Recording;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow() -> Command {
    Command::new(env!("CARGO_BIN_EXE_evflow"))
}

fn devsim(link: &Path, log: &Path) -> Child {
    let mut c = evflow()
        .arg("devsim")
        .arg("--link")
        .arg(link)
        .arg("--log")
        .arg(log)
        .args(["--duration", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("evflow devsim");
    let mut lines = BufReader::new(c.stdout.take().unwrap()).lines();
    let first = lines.next().expect("devsim prints its device").unwrap();
    assert!(first.contains("emulated device on /dev/"), "{first}");
    std::thread::spawn(move || for _ in lines {});
    c
}

fn channel(dir: &Path, name: &str, ch: &str) -> Vec<f64> {
    let r = Recording::open(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    r.channel(ch).unwrap_or_else(|| panic!("{name} has no channel {ch}")).to_vec()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

#[test]
fn the_texture_and_mesh_chains_drive_an_emulated_device_and_get_its_force_back() {
    for graph in ["graphs/texture-serial.toml", "graphs/mesh-serial.toml"] {
        let tmp = tempfile::tempdir().unwrap();
        let (link, log, s) = (tmp.path().join("dev"), tmp.path().join("log"), tmp.path().join("session"));
        let mut dev = devsim(&link, &log);
        let out = evflow()
            .arg("live")
            .arg(root().join(graph))
            .arg("--set")
            .arg(format!("port={}", link.display()))
            // A starved 2-core machine can stall a pty for longer than the default 0.25 s.
            .args(["--set", "timeout=2", "--duration", "2", "--no-realtime", "--miss-streak", "0", "-q", "--session"])
            .arg(&s)
            .stdin(Stdio::null())
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        std::thread::sleep(std::time::Duration::from_millis(500));
        dev.kill().unwrap();
        dev.wait().unwrap();
        assert!(out.status.success(), "{graph}: {text}");

        // The link was up and the device's touch frames arrived.
        let connected = channel(&s, "inputs/device", "connected");
        assert!(connected.iter().filter(|&&c| c == 1.0).count() > 1800, "{graph}: {text}");
        // The chain drove the device: the actuation it logged carries the
        // limiter's output (same level; stall fades may add a few frames).
        let sent = channel(&s, "outputs/limit.out", "out");
        let got = channel(&log, "actuation", "u");
        assert!(rms(&sent) > 0.01, "{graph}: the chain put out nothing: {text}");
        assert!((rms(&got) - rms(&sent)).abs() < 0.1 * rms(&sent), "{graph}: sent {} got {}", rms(&sent), rms(&got));
        // The rendered force came back: it varies with the actuation.
        let force = channel(&s, "inputs/device", "force");
        let mean = force.iter().sum::<f64>() / force.len() as f64;
        let ac: Vec<f64> = force.iter().map(|f| f - mean).collect();
        assert!(force.iter().all(|f| f.is_finite()) && rms(&ac) > 1e-3, "{graph}: force {}", rms(&ac));
    }
}
