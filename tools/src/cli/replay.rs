//! `evflow replay SESSION [GRAPH]`: a recorded live session, offline.
//!
//! The session's recorded inputs take the place of the source nodes of the
//! same names (as `recording.in` nodes with the same ports), its logged
//! parameter changes are applied before the same ticks, and the graph —
//! the session's own, or another one — runs offline in large blocks. The
//! outputs are compared with the recorded ones: with the session's own
//! graph they are identical bit for bit, because the live tick and the
//! offline step are the same code. With the session's own graph the folder
//! is also held to what the session recorded of itself (`live_session::integrity`):
//! its graph file, seed and files, each as long and as written as when it
//! ended — or the replay says what it could not check, and `--check`
//! ends with exit status [`UNPROVEN_EXIT`] ([`Unproven`]).
//!
//! Several sessions (`evflow replay S1 S2 … [GRAPH]`) replay on `--jobs`
//! threads, each into its own folder under `--out`, printed in the order
//! given; one that fails does not stop the others.

use anyhow::{anyhow, bail, Context, Result};
use evflow_engine::batch::{for_each_ordered, Failures};
use evflow_engine::graph::{parse_graph, ParamDecl};
use evflow_engine::{check, Override, Plan, PlanOptions, Value};
use evflow_nodes::recording::format::Recording;
use evflow_tools::batch::{progress_bar, JobsArg};
use evflow_tools::live_session::integrity::Verdict;
use evflow_tools::live_session::session::{read_events, FileSpec, LoggedEvent, Manifest};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Arguments of `evflow replay`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The session folders written by `evflow live`, then optionally a
    /// graph file to run over them instead of their own (its sources of
    /// the same names take the recorded inputs).
    #[arg(required = true, value_name = "SESSION... [GRAPH]")]
    paths: Vec<PathBuf>,
    /// Set a graph variable or node parameter (`name=value`,
    /// `node.param=value`); the session's own overrides apply when GRAPH is
    /// not given.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Block size in base ticks (results do not depend on it).
    #[arg(long, default_value_t = 4096)]
    block: usize,
    /// Folder for files the graph writes (with several sessions, a folder
    /// per session in it, named as the session's folder).
    #[arg(long, value_name = "DIR", default_value = ".")]
    out: PathBuf,
    /// Fail unless the replay proves the session: every recorded output
    /// reproduced bit for bit and, with the session's own graph, the folder
    /// as the session recorded it (graph, seed, files and their lengths and
    /// fingerprints; docs/live.md). Exit status 1 when something differs or
    /// is not the session's; 3 when nothing differs but something could not
    /// be checked — a session killed before it ended, one recorded without
    /// fingerprints, outputs compared only up to samples the session lost.
    /// Why is printed on stderr, also with -q.
    #[arg(long)]
    check: bool,
    /// Print only the comparison.
    #[arg(long, short)]
    quiet: bool,
    #[command(flatten)]
    jobs: JobsArg,
}

/// The exit status of `replay --check` when nothing differs but something
/// could not be checked (1: something differs, or the replay failed).
pub const UNPROVEN_EXIT: u8 = 3;

/// The error `replay --check` ends with when it could not prove a session
/// it found no fault in; the program then exits with [`UNPROVEN_EXIT`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Unproven(String);

/// What a replay proved of its session.
#[derive(Debug, Clone, PartialEq)]
enum Proof {
    /// Every recorded output reproduced bit for bit and, with the
    /// session's own graph, the folder as the session recorded it.
    Proven,
    /// Something differs or is not the session's (said in the text).
    Differs,
    /// Nothing differs, but these could not be checked.
    Unproven(Vec<String>),
}

impl Proof {
    /// The error `--check` ends with, if any.
    fn check(self) -> Result<()> {
        match self {
            Proof::Proven => Ok(()),
            Proof::Differs => Err(anyhow!("the replay does not prove the live session (above: what differs)")),
            Proof::Unproven(why) => {
                Err(Unproven(format!("the replay could not prove the live session: {}", why.join("; "))).into())
            }
        }
    }
}

/// How one recorded output compares with its replay.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// `node.port`.
    pub name: String,
    /// Samples compared.
    pub samples: usize,
    /// Index of the first differing sample, with the two values.
    pub first_difference: Option<(usize, f64, f64)>,
    /// Largest absolute difference.
    pub max_abs: f64,
}

/// Runs `evflow replay`.
pub fn main(a: Args) -> Result<()> {
    let mut sessions = a.paths.clone();
    let graph = match sessions.last() {
        Some(p) if sessions.len() > 1 && p.is_file() => sessions.pop(),
        _ => None,
    };
    if let [session] = sessions.as_slice() {
        let (text, proof) = replay_one(session, graph.as_deref(), &a.out, &a)?;
        print!("{text}");
        return if a.check { proof.check() } else { Ok(()) };
    }
    let mut outs: Vec<PathBuf> = Vec::with_capacity(sessions.len());
    for s in &sessions {
        let name = std::fs::canonicalize(s).unwrap_or_else(|_| s.clone());
        let name = name.file_name().ok_or_else(|| anyhow!("{}: not a session folder", s.display()))?;
        let out = a.out.join(name);
        if outs.contains(&out) {
            bail!("{}: two sessions of one folder name; their outputs would share {}", s.display(), out.display());
        }
        outs.push(out);
    }
    let n = sessions.len();
    let bar = progress_bar(n, "sessions", a.quiet);
    let work = |k: usize, s: &PathBuf| {
        let r = replay_one(s, graph.as_deref(), &outs[k], &a);
        bar.inc(1);
        r
    };
    let mut failures = Failures::new();
    // Failures that are not merely unproven sessions.
    let mut faults = 0;
    let items: Vec<&PathBuf> = sessions.iter().collect();
    for_each_ordered(items, a.jobs.jobs(), &AtomicBool::new(false), work, |k, outcome| {
        println!("── session {}/{n}: {} ──", k + 1, sessions[k].display());
        let name = sessions[k].display().to_string();
        match outcome.map_err(|p| anyhow!(p)).and_then(|r| r) {
            Ok((text, proof)) => {
                print!("{text}");
                match proof {
                    _ if !a.check => {}
                    Proof::Proven => {}
                    Proof::Differs => {
                        failures.push(name, "the replay does not prove the live session");
                        faults += 1;
                    }
                    Proof::Unproven(why) => failures.push(name, format!("could not prove it: {}", why.join("; "))),
                }
            }
            Err(e) => {
                println!("replay failed: {e:#}");
                failures.push(name, format!("{e:#}"));
                faults += 1;
            }
        }
        println!();
    });
    evflow_tools::batch::finish(&bar);
    if failures.is_empty() {
        return Ok(());
    }
    let summary = failures.summary(n, "sessions").trim_end().to_string();
    if faults == 0 {
        return Err(Unproven(summary).into());
    }
    bail!("{summary}")
}

/// Replays one session with `graph` (else its own), the graph's files
/// written under `out`; returns what to print and what it proved.
fn replay_one(session: &Path, graph: Option<&Path>, out: &Path, a: &Args) -> Result<(String, Proof)> {
    let mut shown = String::new();
    let (m, raw) = Manifest::read_raw(session)?;
    let own = graph.is_none();
    let (graph_file, base_dir) = match graph {
        Some(g) => (g.to_path_buf(), g.parent().map(Path::to_path_buf).unwrap_or_default()),
        None => (session.join("graph.toml"), m.base_dir.clone()),
    };
    let text = evflow_engine::files::read_regular_to_string(&graph_file)
        .with_context(|| format!("{}: cannot read", graph_file.display()))?;
    let mut graph = parse_graph(&graph_file, &text).map_err(|e| anyhow!("{e}"))?;

    let session_dir = std::fs::canonicalize(session).unwrap_or_else(|_| session.to_path_buf());
    let (mut ticks, replaced) = replace_sources(&mut graph, &m, &session_dir)?;
    let recorded = recorded_outputs(&m, &session_dir)?;
    for (f, s) in &recorded {
        ticks = ticks.min(f.ratio.ticks_for(s.len() as u64));
    }
    if ticks == u64::MAX {
        return Err(anyhow!("{}: the session recorded nothing to replay", session.display()));
    }

    let overrides = overrides(own, &m, a, &replaced)?;
    let checked = check(&graph, &evflow_nodes::registry(), &overrides).map_err(|e| anyhow!("{e}"))?;
    std::fs::create_dir_all(out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", out.display()))?;
    let opts = PlanOptions {
        max_block: a.block.max(1),
        seed: Some(m.seed),
        base_dir: Some(base_dir),
        out_dir: Some(out.to_path_buf()),
        timing: true,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
    };
    // The session's parameter changes apply: no constant may rest on a live parameter.
    let mut plan =
        Plan::build_with(&checked, &opts, evflow_engine::plan::Folding::Changes).map_err(|e| anyhow!("{e}"))?;
    if (plan.base_rate() - m.base_rate).abs() > 1e-9 * m.base_rate {
        return Err(anyhow!("the graph runs at {} Hz but the session at {} Hz", plan.base_rate(), m.base_rate));
    }

    let (sets, exact_until) = session_changes(session, &plan, &replaced, ticks)?;
    let (replayed, report_ticks) = run(&mut plan, &recorded, &sets, ticks)?;
    let summaries = plan.finish().map_err(|e| anyhow!("{e}"))?;

    if !a.quiet {
        let _ = writeln!(
            shown,
            "replayed {} ticks ({:.3} s) of session `{}`{}",
            report_ticks,
            report_ticks as f64 / m.base_rate,
            m.name,
            if replaced.is_empty() { String::new() } else { format!("; recorded inputs: {}", replaced.join(", ")) }
        );
        for (node, s) in &summaries {
            for l in &s.lines {
                let _ = writeln!(shown, "{node}: {l}");
            }
            for (k, v, unit) in &s.values {
                let _ = writeln!(
                    shown,
                    "{node}: {k} = {}{}",
                    evflow_tools::batch::tables::number(*v),
                    evflow_tools::batch::tables::unit_suffix(unit)
                );
            }
        }
    }
    let mut all_same = compare_outputs(&mut shown, &recorded, &replayed, exact_until);
    let mut unproven = Vec::new();
    if exact_until < ticks {
        let why = format!(
            "compared up to tick {exact_until} of {ticks} (the session lost samples or replaced its plan there)"
        );
        let _ = writeln!(shown, "{why}");
        unproven.push(why);
    }
    // The folder held to what the session recorded of itself: its graph,
    // seed and files, every file as long and as written as it ended.
    if own {
        for f in evflow_tools::live_session::integrity::check(&session_dir, &m, &raw) {
            match f.verdict {
                Verdict::Fails => {
                    let _ = writeln!(shown, "not the session's: {}", f.what);
                    all_same = false;
                }
                Verdict::Unproven => {
                    let _ = writeln!(shown, "{}", f.what);
                    unproven.push(f.what);
                }
            }
        }
    }
    let proof = match (all_same, unproven.is_empty()) {
        (false, _) => Proof::Differs,
        (true, false) => Proof::Unproven(unproven),
        (true, true) => Proof::Proven,
    };
    Ok((shown, proof))
}

/// Recorded inputs replace the sources of the same names in `graph`;
/// returns the ticks the shortest input lasts (`u64::MAX` without inputs)
/// and the sources replaced.
fn replace_sources(graph: &mut evflow_engine::Graph, m: &Manifest, session_dir: &Path) -> Result<(u64, Vec<String>)> {
    let mut ticks = u64::MAX;
    let mut replaced = Vec::new();
    for f in &m.inputs {
        let rec = open(session_dir, f)?;
        ticks = ticks.min(f.ratio.ticks_for(rec.frames() as u64));
        let path = session_dir.join(&f.file).to_string_lossy().into_owned();
        let params = vec![
            param("path", Value::Text(path)),
            param("channels", Value::TextList(f.ports.clone())),
            param("rate", Value::Float(f.rate)),
        ];
        if replaced.contains(&f.node) {
            // A further rate of a multi-rate source: its own recording node,
            // and the connections from those ports move to it.
            // Named after its rate (a dot would read as a port separator).
            let name = format!("{}__{}Hz", f.node, f.rate.to_string().replace('.', "_"));
            let Some(decl) = graph.nodes.iter().find(|n| n.name == f.node).cloned() else { continue };
            graph.nodes.push(evflow_engine::graph::NodeDecl {
                name: name.clone(),
                kind: "recording.in".into(),
                params,
                ..decl
            });
            for c in graph.connections.iter_mut().filter(|c| c.from.node == f.node && f.ports.contains(&c.from.port)) {
                c.from.node = name.clone();
            }
        } else if let Some(decl) = graph.nodes.iter_mut().find(|n| n.name == f.node) {
            decl.kind = "recording.in".into();
            decl.params = params;
            replaced.push(f.node.clone());
        }
    }
    Ok((ticks, replaced))
}

/// The session's recorded outputs, each file's first channel.
fn recorded_outputs(m: &Manifest, session_dir: &Path) -> Result<Vec<(FileSpec, Vec<f64>)>> {
    m.outputs
        .iter()
        .map(|f| {
            let rec = open(session_dir, f)?;
            let samples = rec.channel(&f.ports[0]).map(<[f64]>::to_vec).unwrap_or_default();
            Ok((f.clone(), samples))
        })
        .collect()
}

/// Overrides: the session's (for its own graph) and the command line's;
/// none may address a replaced source.
fn overrides(own: bool, m: &Manifest, a: &Args, replaced: &[String]) -> Result<Vec<Override>> {
    let mut overrides = Vec::new();
    for s in if own { m.overrides.iter().chain(&a.set).collect::<Vec<_>>() } else { a.set.iter().collect() } {
        let o = Override::parse(s).map_err(|e| anyhow!("--set {e}"))?;
        if o.key.split_once('.').is_some_and(|(n, _)| replaced.iter().any(|r| r == n)) {
            continue;
        }
        overrides.push(o);
    }
    Ok(overrides)
}

/// A parameter change the session made: at which tick, to which node (its
/// index in the plan), which parameter, what value.
type Change = (u64, usize, &'static str, f64);

/// Events: changes to apply (before `ticks`, to nodes not replaced); gaps
/// and plan replacements end the exact part. Returns the changes and the
/// tick the exact part ends at.
fn session_changes(session: &Path, plan: &Plan, replaced: &[String], ticks: u64) -> Result<(Vec<Change>, u64)> {
    let mut exact_until = ticks;
    let mut sets = Vec::new();
    for e in read_events(&session.join("events.jsonl"))? {
        match e {
            LoggedEvent::Set { tick, node, param, value } if tick < ticks => {
                if replaced.contains(&node) {
                    continue;
                }
                let Some(k) = plan.index(&node) else {
                    eprintln!("replay: the graph has no node `{node}`; its change at tick {tick} is skipped");
                    continue;
                };
                let Some(p) = plan.spec(k).param(&param) else {
                    eprintln!("replay: `{node}` has no parameter `{param}`; its change at tick {tick} is skipped");
                    continue;
                };
                sets.push((tick, k, p.name, value));
            }
            LoggedEvent::Gap { tick, .. } | LoggedEvent::Replaced { tick } => exact_until = exact_until.min(tick),
            _ => {}
        }
    }
    Ok((sets, exact_until))
}

/// Compares each recorded output with its replay up to `exact_until`,
/// writing a line for each to `shown`; true when all are identical.
fn compare_outputs(
    shown: &mut String,
    recorded: &[(FileSpec, Vec<f64>)],
    replayed: &[Option<Vec<f64>>],
    exact_until: u64,
) -> bool {
    let mut all_same = true;
    for ((f, rec), replay) in recorded.iter().zip(replayed) {
        let name = format!("{}.{}", f.node, f.ports[0]);
        let Some(out) = replay else {
            let _ = writeln!(shown, "{name}: not in the replayed graph");
            all_same = false;
            continue;
        };
        let n = (f.ratio.count(0, exact_until) as usize).min(rec.len()).min(out.len());
        let c = compare(&name, &rec[..n], &out[..n]);
        match c.first_difference {
            None => {
                let _ = writeln!(shown, "{name}: identical to the live session, bit for bit ({} samples)", c.samples);
            }
            Some((i, r, o)) => {
                all_same = false;
                let _ = writeln!(
                    shown,
                    "{name}: differs from sample {i} (live {r:e}, replay {o:e}); largest difference {:e} over {} samples",
                    c.max_abs, c.samples
                );
            }
        }
    }
    all_same
}

fn param(name: &str, value: Value) -> ParamDecl {
    ParamDecl { name: name.into(), value, loc: Default::default() }
}

fn open(dir: &Path, f: &FileSpec) -> Result<Recording> {
    Recording::open(&dir.join(&f.file)).map_err(|e| anyhow!("{e}"))
}

/// Runs `ticks` ticks in blocks, applying each change before its tick and
/// collecting the outputs the session recorded.
fn run(
    plan: &mut Plan,
    recorded: &[(FileSpec, Vec<f64>)],
    sets: &[Change],
    ticks: u64,
) -> Result<(Vec<Option<Vec<f64>>>, u64)> {
    let taps: Vec<Option<(usize, usize)>> = recorded
        .iter()
        .map(|(f, _)| {
            let k = plan.index(&f.node)?;
            let j = plan.output_names(k).iter().position(|p| *p == f.ports[0])?;
            Some((k, j))
        })
        .collect();
    let mut out: Vec<Option<Vec<f64>>> = taps.iter().map(|t| t.map(|_| Vec::new())).collect();
    let ticks = plan.remaining_ticks().map_or(ticks, |r| r.min(ticks));
    let block = plan.max_block() as u64;
    let mut t = 0;
    let mut next = 0;
    while t < ticks {
        while next < sets.len() && sets[next].0 <= t {
            let (tick, k, p, v) = sets[next];
            plan.set(k, p, v).map_err(|e| anyhow!("tick {tick}: `{}`: {e}", plan.node_name(k)))?;
            next += 1;
        }
        let until = sets.get(next).map_or(ticks, |s| s.0.min(ticks));
        let n = block.min(until - t).max(1);
        plan.step(n as usize).map_err(|e| anyhow!("{e}"))?;
        for (tap, o) in taps.iter().zip(&mut out) {
            if let (Some((k, j)), Some(o)) = (tap, o) {
                o.extend_from_slice(plan.output_at(*k, *j));
            }
        }
        t += n;
    }
    Ok((out, ticks))
}

/// Compares two equally long signals bit for bit.
pub fn compare(name: &str, recorded: &[f64], replayed: &[f64]) -> Comparison {
    let mut first = None;
    let mut max_abs: f64 = 0.0;
    for (i, (r, o)) in recorded.iter().zip(replayed).enumerate() {
        if r.to_bits() != o.to_bits() {
            first.get_or_insert((i, *r, *o));
            max_abs = max_abs.max((r - o).abs());
        }
    }
    Comparison { name: name.to_string(), samples: recorded.len().min(replayed.len()), first_difference: first, max_abs }
}
