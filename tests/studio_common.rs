//! What the studio tests share: the `evflow` binary, a session started
//! with `--studio`, a plain HTTP GET.

#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStderr, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// The `evflow` binary beside this test's, built if it is missing or was
/// built without the studio (a rig build, `--no-default-features`, leaves
/// one there).
pub fn evflow() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    let dir = exe.parent().and_then(Path::parent).expect("target/<profile>");
    let bin = dir.join("evflow");
    let has_studio = || {
        Command::new(&bin)
            .args(["live", "--help"])
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("--studio"))
    };
    if !bin.exists() || !has_studio() {
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

/// A live session with the studio, its stderr lines arriving on `lines`;
/// killed if dropped while it runs (a failed test leaves nothing running).
pub struct Session {
    pub child: Child,
    pub url: String,
    pub lines: mpsc::Receiver<String>,
    pub dir: PathBuf,
}

fn forward(err: ChildStderr, tx: mpsc::Sender<String>) {
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines() {
            let Ok(l) = l else { break };
            if tx.send(l).is_err() {
                break;
            }
        }
    });
}

/// Starts `evflow live GRAPH --studio ADDR …` (not real-time, misses
/// tolerated: CI machines are shared) and waits for the studio's address.
pub fn start(graph: &str, dir: &Path, studio: &[&str], extra: &[&str]) -> Session {
    let session = dir.join("session");
    let mut child = Command::new(evflow())
        .arg("live")
        .arg(evflow_tests::root().join("graphs").join(graph))
        .arg("--session")
        .arg(&session)
        .args(["--no-realtime", "--miss-streak", "0", "-q", "--studio"])
        .args(studio)
        .args(extra)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("evflow live");
    let (tx, lines) = mpsc::channel();
    forward(child.stderr.take().unwrap(), tx);
    let mut seen = Vec::new();
    let url = loop {
        match lines.recv_timeout(Duration::from_secs(60)) {
            Ok(l) => {
                if let Some(u) = l.strip_prefix("studio: http") {
                    break format!("http{u}");
                }
                seen.push(l);
            }
            Err(_) => {
                let _ = child.kill();
                panic!("no studio address printed; stderr: {seen:?}");
            }
        }
    };
    Session { child, url, lines, dir: session }
}

impl Drop for Session {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A child process killed when dropped.
pub struct KillOnDrop(pub Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Session {
    /// Types `stop` on the console and waits for the end; returns stdout.
    pub fn stop(mut self) -> String {
        if let Some(mut i) = self.child.stdin.take() {
            let _ = writeln!(i, "stop");
        }
        let _ = self.child.wait();
        let mut out = String::new();
        if let Some(mut o) = self.child.stdout.take() {
            let _ = o.read_to_string(&mut out);
        }
        out
    }
    /// `host:port` of the studio.
    pub fn host(&self) -> String {
        self.url.trim_start_matches("http://").split('/').next().unwrap().to_string()
    }
}

/// `GET path` on `host` with extra header lines; (status code, body).
pub fn get(host: &str, path: &str, headers: &str) -> (u16, String) {
    let mut s = TcpStream::connect(host).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {host}\r\n{headers}Connection: close\r\n\r\n").unwrap();
    let mut text = String::new();
    let _ = s.read_to_string(&mut text);
    let code = text.split_whitespace().nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = text.split_once("\r\n\r\n").map(|x| x.1.to_string()).unwrap_or_default();
    (code, body)
}
