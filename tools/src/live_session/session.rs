//! A live session on disk: what it records and where.
//!
//! ```text
//! SESSION/
//!   session.json          what ran: graph, overrides, seed, rate, files; status and metrics at the end
//!   graph.toml            the graph file as it was
//!   inputs/NODE.wav|json  every output of every source node (one channel per port)
//!   outputs/NODE.PORT.wav|json  every safety guard's output, and each --tap
//!   events.jsonl          tick-stamped parameter changes, stops, gaps
//! ```
//!
//! Recordings are written with the live writer (readable after every flush);
//! the manifest and event log are rewritten/appended so a process killed at
//! any moment leaves a session `evflow replay` can read up to the last flush.

use super::error::SessionError;

type Result<T> = std::result::Result<T, SessionError>;
use evflow_engine::live::{Event, EventKind, TapInfo};
use evflow_engine::rate::Ratio;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The manifest's `format` value.
pub const FORMAT: &str = "evflow-session";
/// The manifest version this evflow writes and reads.
pub const VERSION: u64 = 1;

/// One recording of a session: a node's ports at one rate.
#[derive(Debug, Clone)]
pub struct FileSpec {
    /// Path relative to the session folder, without extension.
    pub file: String,
    /// The node.
    pub node: String,
    /// Its ports recorded (the channels, in order).
    pub ports: Vec<String>,
    /// Rate relative to the base rate.
    pub ratio: Ratio,
    /// Rate in Hz.
    pub rate: f64,
}

impl FileSpec {
    fn json(&self) -> Value {
        json!({ "file": self.file, "node": self.node, "ports": self.ports, "rate": self.rate })
    }
}

/// Groups taps into files: sources by node and rate (`inputs/NODE`, and
/// `inputs/NODE-RATEHz` for each further rate of a multi-rate source such
/// as `sim.user`), the rest one port each (`outputs/NODE.PORT`). `n_inputs`
/// taps at the front are inputs.
pub fn files(taps: &[TapInfo], n_inputs: usize) -> Result<(Vec<FileSpec>, Vec<FileSpec>)> {
    let mut inputs: Vec<FileSpec> = Vec::new();
    for t in &taps[..n_inputs] {
        match inputs.iter_mut().find(|f| f.node == t.node && f.ratio == t.ratio) {
            Some(f) => f.ports.push(t.port.clone()),
            None => {
                let first = !inputs.iter().any(|f| f.node == t.node);
                let file = if first { format!("inputs/{}", t.node) } else { format!("inputs/{}-{}Hz", t.node, t.rate) };
                inputs.push(FileSpec {
                    file,
                    node: t.node.clone(),
                    ports: vec![t.port.clone()],
                    ratio: t.ratio,
                    rate: t.rate,
                })
            }
        }
    }
    let outputs = taps[n_inputs..]
        .iter()
        .map(|t| FileSpec {
            file: format!("outputs/{}.{}", t.node, t.port),
            node: t.node.clone(),
            ports: vec![t.port.clone()],
            ratio: t.ratio,
            rate: t.rate,
        })
        .collect();
    Ok((inputs, outputs))
}

/// What a session manifest says.
#[derive(Debug, Clone)]
pub struct Manifest {
    /// The graph's name.
    pub name: String,
    /// Where the graph file was.
    pub graph_source: PathBuf,
    /// The folder relative input paths of the graph were taken from.
    pub base_dir: PathBuf,
    /// `--set` overrides as typed.
    pub overrides: Vec<String>,
    /// The run's seed.
    pub seed: u64,
    /// Base rate, Hz.
    pub base_rate: f64,
    /// Recorded inputs.
    pub inputs: Vec<FileSpec>,
    /// Recorded outputs.
    pub outputs: Vec<FileSpec>,
    /// Unix time the session started.
    pub started: u64,
    /// The fingerprint of `graph.toml` as the session wrote it (None in a
    /// session recorded before fingerprints).
    pub graph_hash: Option<String>,
    /// The fingerprint of what a replay takes from this manifest
    /// ([`super::integrity::identity`]).
    pub identity: Option<String>,
}

impl Manifest {
    /// The manifest as JSON, with a status and optional end report.
    pub fn json(&self, status: &str, end: Option<Value>) -> Value {
        json!({
            "format": FORMAT,
            "version": VERSION,
            "name": self.name,
            "status": status,
            "graph": "graph.toml",
            "graph_source": self.graph_source,
            "base_dir": self.base_dir,
            "overrides": self.overrides,
            "seed": self.seed,
            "base_rate": self.base_rate,
            "started_unix": self.started,
            "graph_hash": self.graph_hash,
            "identity": self.identity,
            "inputs": self.inputs.iter().map(FileSpec::json).collect::<Vec<_>>(),
            "outputs": self.outputs.iter().map(FileSpec::json).collect::<Vec<_>>(),
            "events": "events.jsonl",
            "end": end.unwrap_or(Value::Null),
        })
    }

    /// Writes `session.json` atomically (temporary file, then rename).
    pub fn write(&self, dir: &Path, status: &str, end: Option<Value>) -> Result<()> {
        let path = dir.join("session.json");
        let text =
            serde_json::to_string_pretty(&self.json(status, end)).map_err(SessionError::json(&path, "cannot write"))?;
        evflow_engine::atomic_file::write_atomically(&path, text + "\n")
            .map_err(SessionError::file(&path, "cannot write"))
    }

    /// Reads `SESSION/session.json`, and the JSON as it is.
    pub fn read_raw(dir: &Path) -> Result<(Manifest, Value)> {
        let m = Self::read(dir)?;
        let path = dir.join("session.json");
        let text = std::fs::read_to_string(&path).map_err(SessionError::file(&path, "cannot read"))?;
        let v: Value = serde_json::from_str(&text).map_err(SessionError::json(&path, "not valid JSON"))?;
        Ok((m, v))
    }

    /// Reads `SESSION/session.json`.
    pub fn read(dir: &Path) -> Result<Manifest> {
        let path = dir.join("session.json");
        let text = std::fs::read_to_string(&path)
            .map_err(SessionError::file(dir, "not a session folder (no session.json; `evflow live` writes one)"))?;
        let v: Value = serde_json::from_str(&text).map_err(SessionError::json(&path, "not valid JSON"))?;
        if v["format"] != FORMAT {
            return Err(SessionError::Recording(format!(
                "{}: `format` is {}, not \"{FORMAT}\"",
                path.display(),
                v["format"]
            )));
        }
        let version = v["version"].as_u64().unwrap_or(0);
        if version > VERSION {
            return Err(SessionError::Recording(format!(
                "{}: session format version {version} is newer than this evflow reads ({VERSION}); update evflow",
                path.display()
            )));
        }
        let base_rate = v["base_rate"]
            .as_f64()
            .ok_or_else(|| SessionError::Recording(format!("{}: `base_rate` missing", path.display())))?;
        let files = |key: &str| -> Result<Vec<FileSpec>> {
            let list = v[key]
                .as_array()
                .ok_or_else(|| SessionError::Recording(format!("{}: `{key}` missing", path.display())))?;
            list.iter()
                .map(|f| {
                    let rate = f["rate"].as_f64().ok_or_else(|| {
                        SessionError::Recording(format!("{}: a file in `{key}` has no rate", path.display()))
                    })?;
                    let ratio = Ratio::of(rate, base_rate).ok_or_else(|| {
                        SessionError::Recording(format!(
                            "{}: rate {rate} Hz is not a multiple or divisor of {base_rate} Hz",
                            path.display()
                        ))
                    })?;
                    Ok(FileSpec {
                        file: f["file"].as_str().unwrap_or_default().to_string(),
                        node: f["node"].as_str().unwrap_or_default().to_string(),
                        ports: f["ports"]
                            .as_array()
                            .map(|a| a.iter().filter_map(|p| p.as_str().map(str::to_string)).collect())
                            .unwrap_or_default(),
                        ratio,
                        rate,
                    })
                })
                .collect()
        };
        let text_list = |key: &str| -> Vec<String> {
            v[key]
                .as_array()
                .map(|a| a.iter().filter_map(|s| s.as_str().map(str::to_string)).collect())
                .unwrap_or_default()
        };
        Ok(Manifest {
            name: v["name"].as_str().unwrap_or_default().to_string(),
            graph_source: PathBuf::from(v["graph_source"].as_str().unwrap_or_default()),
            base_dir: PathBuf::from(v["base_dir"].as_str().unwrap_or_default()),
            overrides: text_list("overrides"),
            seed: v["seed"].as_u64().unwrap_or(0),
            base_rate,
            inputs: files("inputs")?,
            outputs: files("outputs")?,
            started: v["started_unix"].as_u64().unwrap_or(0),
            graph_hash: v["graph_hash"].as_str().map(str::to_string),
            identity: v["identity"].as_str().map(str::to_string),
        })
    }
}

/// One line of `events.jsonl` for an event; node indices named.
pub fn event_json(e: &Event, names: &[String]) -> Value {
    let name = |k: u32| names.get(k as usize).cloned().unwrap_or_else(|| format!("#{k}"));
    match e.kind {
        EventKind::Set { node, param, value } => {
            json!({ "tick": e.tick, "event": "set", "node": name(node), "param": param, "value": value })
        }
        EventKind::Refused { node, param, value } => {
            json!({ "tick": e.tick, "event": "refused", "node": name(node), "param": param, "value": value })
        }
        EventKind::Stop(why) => json!({ "tick": e.tick, "event": "stop", "reason": why.as_str() }),
        EventKind::Gap { ticks } => json!({ "tick": e.tick, "event": "gap", "ticks": ticks }),
        EventKind::Replaced => json!({ "tick": e.tick, "event": "replaced" }),
    }
}

/// A parsed line of `events.jsonl`.
#[derive(Debug, Clone, PartialEq)]
pub enum LoggedEvent {
    /// A parameter change applied before tick `tick`.
    Set {
        /// Tick.
        tick: u64,
        /// Node name.
        node: String,
        /// Parameter name.
        param: String,
        /// Value.
        value: f64,
    },
    /// Samples lost from `tick` for `ticks` ticks.
    Gap {
        /// First tick lost.
        tick: u64,
        /// Ticks lost.
        ticks: u64,
    },
    /// The plan was replaced at `tick`.
    Replaced {
        /// Tick.
        tick: u64,
    },
    /// Anything else (stops, refusals): informational.
    Other,
}

/// Every line of `events.jsonl` as JSON, each with a tick; a last line cut
/// short by a crash is left out. A file that is not there holds no events.
pub fn read_event_values(path: &Path) -> Result<Vec<Value>> {
    let text = match evflow_engine::files::read_regular_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(SessionError::Recording(format!("{}: {e}", path.display()))),
    };
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        match serde_json::from_str::<Value>(line) {
            Ok(v) if v["tick"].is_u64() => out.push(v),
            Ok(_) => {
                return Err(SessionError::Recording(format!("{}:{}: event without a tick", path.display(), i + 1)))
            }
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => break,
            Err(e) => {
                return Err(SessionError::Recording(format!("{}:{}: not a JSON event: {e}", path.display(), i + 1)))
            }
        }
    }
    Ok(out)
}

/// Reads `events.jsonl` ([`read_event_values`]) into the events a replay
/// acts on.
pub fn read_events(path: &Path) -> Result<Vec<LoggedEvent>> {
    let mut out = Vec::new();
    for (i, v) in read_event_values(path)?.into_iter().enumerate() {
        let tick = v["tick"].as_u64().unwrap_or_default();
        out.push(match v["event"].as_str() {
            Some("set") => LoggedEvent::Set {
                tick,
                node: v["node"].as_str().unwrap_or_default().to_string(),
                param: v["param"].as_str().unwrap_or_default().to_string(),
                value: v["value"].as_f64().ok_or_else(|| {
                    SessionError::Recording(format!("{}:{}: `set` without a value", path.display(), i + 1))
                })?,
            },
            Some("gap") => LoggedEvent::Gap { tick, ticks: v["ticks"].as_u64().unwrap_or(0) },
            Some("replaced") => LoggedEvent::Replaced { tick },
            _ => LoggedEvent::Other,
        });
    }
    Ok(out)
}
