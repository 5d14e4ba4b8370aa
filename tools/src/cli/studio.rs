//! `evflow studio SESSION`: the studio page for a recorded session.

use super::graph_args::load_with;
use anyhow::{anyhow, Context, Result};
use evflow_nodes::recording::format::Recording;
use evflow_tools::live_session::session::{read_event_values, Manifest};
use evflow_tools::studio::{publish_replay, serve_recorded, RecordedSession, RecordedTap, StudioConfig};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Arguments of `evflow studio`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The session folder written by `evflow live`.
    session: PathBuf,
    /// Where to serve: `PORT` or `HOST:PORT` (port 0 picks a free one).
    /// Also spelled `--studio ADDR`, as `evflow live` takes it.
    #[arg(long, visible_alias = "studio", value_name = "ADDR", default_value = "127.0.0.1:8737")]
    addr: String,
    /// Allow a non-loopback address; the page then needs the one-time
    /// token printed at start. Also spelled `--studio-public`, as `evflow
    /// live` takes it.
    #[arg(long, visible_alias = "studio-public")]
    public: bool,
    /// Do not run the replay check.
    #[arg(long)]
    no_replay: bool,
}

/// The studio's address from `PORT`, `HOST:PORT` or `IP:PORT`.
pub fn studio_addr(text: &str) -> Result<std::net::SocketAddr> {
    use std::net::ToSocketAddrs;
    let t = text.trim();
    let with_host = if t.parse::<u16>().is_ok() { format!("127.0.0.1:{t}") } else { t.to_string() };
    with_host
        .to_socket_addrs()
        .ok()
        .and_then(|mut a| a.next())
        .ok_or_else(|| anyhow!("studio address `{text}`: expected PORT or HOST:PORT (e.g. 127.0.0.1:8737)"))
}

/// Reads a session folder.
fn read(dir: &Path) -> Result<RecordedSession> {
    let m = Manifest::read(dir)?;
    let json_path = dir.join("session.json");
    let raw: Value = serde_json::from_str(&std::fs::read_to_string(&json_path)?)
        .with_context(|| format!("{}: not valid JSON", json_path.display()))?;
    let end = &raw["end"];
    let mut taps = Vec::new();
    let mut notes = Vec::new();
    for f in m.inputs.iter().chain(&m.outputs) {
        let rec = Recording::open(&dir.join(&f.file)).map_err(|e| anyhow!("{e}"))?;
        if let Some(short) = rec.shortfall() {
            notes.push(format!(
                "{}: cut short — {} of the {} frames claimed are in the file",
                f.file, short.present, short.claimed
            ));
        }
        for port in &f.ports {
            let samples = rec
                .channel(port)
                .ok_or_else(|| anyhow!("{}: no channel `{port}`", dir.join(&f.file).display()))?
                .to_vec();
            taps.push(RecordedTap { node: f.node.clone(), port: port.clone(), rate: rec.rate(), samples });
        }
    }
    let checked = match load_with(&dir.join("graph.toml"), &m.overrides) {
        Ok(c) => Some(c),
        Err(e) => {
            notes.push(format!("the recorded graph does not load ({e}); the recordings are shown without it"));
            None
        }
    };
    let scene = checked.as_ref().map(|c| evflow_tools::studio::scene_json(c, &m.base_dir)).unwrap_or(Value::Null);
    Ok(RecordedSession {
        name: m.name.clone(),
        base_rate: m.base_rate,
        ticks: end["ticks"].as_u64().unwrap_or(0),
        stopped: end["stopped"]
            .as_str()
            .map(str::to_string)
            .unwrap_or_else(|| format!("did not end cleanly (status {})", raw["status"].as_str().unwrap_or("unknown"))),
        taps,
        events: read_event_values(&dir.join("events.jsonl"))?,
        metrics: end["metrics"].clone(),
        steal_s: end["host_steal_seconds"].as_f64(),
        checked,
        scene,
        notes,
    })
}

/// Runs `evflow studio`.
pub fn main(a: Args) -> Result<()> {
    let session = read(&a.session)?;
    for n in &session.notes {
        eprintln!("studio: {n}");
    }
    let cfg = StudioConfig { addr: studio_addr(&a.addr)?, public: a.public };
    let studio = serve_recorded(&cfg, &session)?;
    println!("studio: {}", studio.url());
    println!(
        "session {} ({:.3} s); Ctrl-C to stop serving",
        a.session.display(),
        session.ticks as f64 / session.base_rate
    );
    if a.no_replay {
        publish_replay(&studio, false, "not run (--no-replay)");
    } else {
        // The replay check is `evflow replay --check`, run as it is run by hand.
        let out = std::env::current_exe().and_then(|exe| {
            std::process::Command::new(exe).arg("replay").arg(&a.session).args(["--check", "-q"]).output()
        });
        match out {
            Ok(o) => {
                let text = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
                let summary = text.lines().filter(|l| !l.trim().is_empty()).collect::<Vec<_>>().join("\n");
                println!("replay check: {}", if o.status.success() { "reproduced" } else { "FAILED" });
                publish_replay(&studio, o.status.success(), &summary);
            }
            Err(e) => publish_replay(&studio, false, &format!("cannot run evflow replay: {e}")),
        }
    }
    loop {
        std::thread::park();
    }
}
