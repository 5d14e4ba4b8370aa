//! What proves a recorded session whole, and the check of it.
//!
//! A session records, when it starts, a fingerprint of the graph file it
//! runs (`graph_hash`) and of everything the replay takes from its manifest
//! — the graph's fingerprint, the seed, the overrides, the rate, the files
//! and their ports (`identity`) — and, when it ends, every recording's frame
//! count and a fingerprint of its samples (`end.files[].hash`). `evflow
//! replay --check` holds the folder to them: a file cut short, a sidecar
//! whose `frames` is not what was written, a changed input (whether or not
//! it feeds a recorded output), another seed or graph, a file in `inputs/`
//! or `outputs/` the session did not write, a key in `session.json` its
//! version does not define is a failure, named ([`Verdict::Fails`]); what
//! cannot be checked (a session killed before it ended has no end) is said
//! and leaves the session unproven ([`Verdict::Unproven`]). Fingerprints are
//! FNV-1a, 64 bits — they catch accidents and careless edits, not a forger.

use super::session::{FileSpec, Manifest};
use serde_json::Value;
use std::io::Read;
use std::path::Path;

/// FNV-1a, 64 bits, over `bytes` continuing from `h`.
fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// The fingerprint of a file's bytes, read in pieces.
pub fn file_hash(path: &Path) -> std::io::Result<String> {
    let mut f = std::fs::File::open(path)?;
    let mut buf = vec![0u8; 1 << 16];
    let mut h = FNV_START;
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h = fnv(h, &buf[..n]);
    }
    Ok(format!("fnv1a64:{h:016x}"))
}

/// The fingerprint of what a replay takes from the manifest.
pub fn identity(
    graph_hash: &str,
    seed: u64,
    overrides: &[String],
    base_rate: f64,
    inputs: &[FileSpec],
    outputs: &[FileSpec],
) -> String {
    let mut text = format!("{graph_hash}\nseed {seed}\nrate {:?}\n", base_rate);
    for o in overrides {
        text.push_str(&format!("set {o}\n"));
    }
    for f in inputs.iter().chain(outputs) {
        text.push_str(&format!("file {} {} {:?} {}\n", f.file, f.node, f.rate, f.ports.join(",")));
    }
    format!("fnv1a64:{:016x}", fnv(FNV_START, text.as_bytes()))
}

/// What a finding means for the check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Something is not as the session recorded it: the check fails.
    Fails,
    /// Something could not be checked: the check cannot prove the session.
    Unproven,
}

/// One thing the check found.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// Whether it fails the check or leaves it unproven.
    pub verdict: Verdict,
    /// What, for people.
    pub what: String,
}

fn bad(what: String) -> Finding {
    Finding { verdict: Verdict::Fails, what }
}

fn unproven(what: String) -> Finding {
    Finding { verdict: Verdict::Unproven, what }
}

/// Holds the session folder `dir` (its manifest `m`, read as `raw`) to what
/// it recorded: the manifest's keys, the graph file and the manifest's
/// fingerprints, the files in `inputs/` and `outputs/`, then, for a session
/// that ended, every recording's frames (WAV and sidecar) and fingerprint.
pub fn check(dir: &Path, m: &Manifest, raw: &Value) -> Vec<Finding> {
    let mut out = unknown_keys(m, raw);
    match (&m.graph_hash, &m.identity) {
        (Some(g), Some(id)) => {
            match file_hash(&dir.join("graph.toml")) {
                Ok(now) if now == *g => {}
                Ok(_) => out.push(bad("graph.toml: changed since the session ran it".into())),
                Err(e) => out.push(bad(format!("graph.toml: cannot read: {e}"))),
            }
            let now = identity(g, m.seed, &m.overrides, m.base_rate, &m.inputs, &m.outputs);
            if now != *id {
                out.push(bad(
                    "session.json: its seed, overrides, rate or files are not those the session recorded".into()
                ));
            }
        }
        _ => out.push(unproven(
            "could not check the graph and the seed: the session was recorded without fingerprints".into(),
        )),
    }
    let status = raw["status"].as_str().unwrap_or("");
    let ended = raw["end"]["files"].as_array();
    out.extend(strangers(dir, m, ended.is_some()));
    let Some(files) = ended else {
        out.push(unproven(format!(
            "could not check that the recordings are whole: the session did not end (status `{status}`: \
             killed?), so it recorded neither their lengths nor their fingerprints; what they hold was compared"
        )));
        return out;
    };
    let ticks = raw["end"]["ticks"].as_u64();
    for f in m.inputs.iter().chain(&m.outputs) {
        let Some(rec) = files.iter().find(|x| x["file"].as_str() == Some(f.file.as_str())) else {
            out.push(bad(format!("{}: not among the files the session ended with", f.file)));
            continue;
        };
        let wav = dir.join(format!("{}.wav", f.file));
        let frames = rec["frames"].as_u64().unwrap_or(0);
        match evflow_nodes::recording::format::Recording::open(&dir.join(&f.file)) {
            Ok(r) if r.frames() as u64 != frames => out.push(bad(format!(
                "{}: holds {} frames, the session wrote {frames}{}",
                f.file,
                r.frames(),
                if (r.frames() as u64) < frames { " (cut short)" } else { "" }
            ))),
            Ok(r) if r.sidecar_frames() != frames => out.push(bad(format!(
                "{}.json: says {} frames, the session wrote {frames}",
                f.file,
                r.sidecar_frames()
            ))),
            Ok(_) => {}
            Err(e) => out.push(bad(format!("{}: cannot read: {e}", f.file))),
        }
        match (rec["hash"].as_str(), file_hash(&wav)) {
            (Some(want), Ok(now)) if want != now => {
                out.push(bad(format!("{}: its samples changed since the session wrote them", f.file)))
            }
            (None, _) => out.push(unproven(format!(
                "could not check the samples of {}: the session recorded no fingerprint",
                f.file
            ))),
            _ => {}
        }
        // The session's length: every stream as long as its ticks say, bar the gaps it logged.
        if let Some(t) = ticks {
            let want = f.ratio.count(0, t);
            let gaps = rec["gap_frames"].as_u64().unwrap_or(0);
            if frames + gaps != want {
                out.push(bad(format!(
                    "{}: the session wrote {frames} frames and lost {gaps} over {t} ticks, where {want} were due",
                    f.file
                )));
            }
        }
    }
    out
}

/// Keys of `session.json` (and of its files' entries) that its version
/// does not define. A newer evflow that adds a key raises `version`, which
/// this one refuses by name ([`Manifest::read`]); so an unknown key in a
/// manifest this evflow reads was not written by a session.
fn unknown_keys(m: &Manifest, raw: &Value) -> Vec<Finding> {
    let mut out = Vec::new();
    let mut unknown = |raw: &Value, known: &Value, at: &str| {
        if let (Some(raw), Some(known)) = (raw.as_object(), known.as_object()) {
            for key in raw.keys().filter(|k| !known.contains_key(*k)) {
                out.push(bad(format!("session.json: `{at}{key}` is not a key a session writes")));
            }
        }
    };
    let known = m.json("", None);
    unknown(raw, &known, "");
    // Inputs and outputs are described alike.
    if let Some(known_entry) = known["inputs"].get(0).or_else(|| known["outputs"].get(0)) {
        for list in ["inputs", "outputs"] {
            for (k, entry) in raw[list].as_array().into_iter().flatten().enumerate() {
                unknown(entry, known_entry, &format!("{list}[{k}]."));
            }
        }
    }
    out
}

/// Files in `inputs/` and `outputs/` that are not the session's recordings
/// (`FILE.wav`, `FILE.json` of its manifest). A session that did not end
/// may have left a sidecar's temporary (`FILE.json….tmp`) there.
fn strangers(dir: &Path, m: &Manifest, ended: bool) -> Vec<Finding> {
    let ours: Vec<String> = m
        .inputs
        .iter()
        .chain(&m.outputs)
        .flat_map(|f| [format!("{}.wav", f.file), format!("{}.json", f.file)])
        .collect();
    let temporary = |name: &str| {
        name.ends_with(".tmp")
            && m.inputs.iter().chain(&m.outputs).any(|f| name.starts_with(&format!("{}.json.", f.file)))
    };
    let mut out = Vec::new();
    for sub in ["inputs", "outputs"] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else { continue };
        let mut names: Vec<String> =
            entries.filter_map(Result::ok).map(|e| format!("{sub}/{}", e.file_name().to_string_lossy())).collect();
        names.sort();
        for name in names {
            if ours.contains(&name) || (!ended && temporary(&name)) {
                continue;
            }
            out.push(bad(format!("{name}: not a file the session wrote")));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fingerprints_see_every_byte_and_every_field() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x");
        std::fs::write(&p, vec![7u8; 200_000]).unwrap();
        let a = file_hash(&p).unwrap();
        let mut bytes = vec![7u8; 200_000];
        bytes[150_000] = 8;
        std::fs::write(&p, &bytes).unwrap();
        assert_ne!(file_hash(&p).unwrap(), a);
        let f = |rate: f64| FileSpec {
            file: "inputs/user".into(),
            node: "user".into(),
            ports: vec!["x".into()],
            ratio: evflow_engine::rate::Ratio::of(rate, 1000.0).unwrap(),
            rate,
        };
        let base = identity("g", 7, &["gain=1".into()], 1000.0, &[f(1000.0)], &[]);
        assert_ne!(identity("g", 8, &["gain=1".into()], 1000.0, &[f(1000.0)], &[]), base, "seed");
        assert_ne!(identity("h", 7, &["gain=1".into()], 1000.0, &[f(1000.0)], &[]), base, "graph");
        assert_ne!(identity("g", 7, &[], 1000.0, &[f(1000.0)], &[]), base, "overrides");
        assert_ne!(identity("g", 7, &["gain=1".into()], 1000.0, &[f(40.0)], &[]), base, "files");
        assert_eq!(identity("g", 7, &["gain=1".into()], 1000.0, &[f(1000.0)], &[]), base);
    }
}
