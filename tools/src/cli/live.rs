//! `evflow live FILE`: run a graph in real time, recording the session.

pub mod integrity;
mod recorder;
pub mod session;
mod steal;

use super::graph_args::GraphArgs;
use anyhow::{anyhow, Context, Result};
use evflow_engine::live::{self, LiveConfig, LivePlan, Metrics, RealtimeRequest, StopReason, Tap};
use evflow_engine::{Plan, PlanOptions};
use recorder::Recorder;
use serde_json::json;
use session::Manifest;
use std::io::{BufRead, IsTerminal};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Deadline misses in a row that stop a session driving hardware.
const DEFAULT_MISS_STREAK: u64 = 10;

/// Arguments of `evflow live`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Session length in seconds (default: the graph's `duration`, else
    /// until Ctrl-C or a finite source ends). The safety limiters then fade
    /// out (10 ms) before the session ends.
    #[arg(long, value_parser = super::graph_args::parse_duration)]
    duration: Option<f64>,
    /// Ignore the graph's `duration` and run until stopped.
    #[arg(long, conflicts_with = "duration")]
    endless: bool,
    /// Seed for every random stream (overrides the graph's `seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// The session folder (default: OUT/sessions/NAME-YYYYMMDD-HHMMSS).
    #[arg(long, value_name = "DIR")]
    session: Option<PathBuf>,
    /// Folder for sessions and for files the graph writes.
    #[arg(long, value_name = "DIR", default_value = ".")]
    out: PathBuf,
    /// Also record this output port (`node.port`); may be repeated. The
    /// outputs of every source and every safety limiter are always recorded.
    #[arg(long = "tap", value_name = "NODE.PORT")]
    taps: Vec<String>,
    /// A scripted parameter change `SECONDS:node.param=value`, applied at
    /// exactly that tick; may be repeated. `SECONDS:variable=value` changes a
    /// graph variable: every live parameter written `"$variable"` (e.g.
    /// `texture` in texture-live.toml, `scene` in mesh-live.toml) at that
    /// same tick. (While running, type the same without `SECONDS:` and
    /// Enter, or `stop`.)
    #[arg(long = "change", value_name = "S:NODE.PARAM=VALUE")]
    changes: Vec<String>,
    /// SCHED_FIFO priority of the real-time thread (1–99).
    #[arg(long, default_value_t = 80, value_parser = clap::value_parser!(i32).range(1..=99))]
    priority: i32,
    /// Do not ask for SCHED_FIFO, memory locking or CPU pinning.
    #[arg(long)]
    no_realtime: bool,
    /// CPU to pin the real-time thread to (default: the last one).
    #[arg(long)]
    cpu: Option<usize>,
    /// Microseconds spun before each deadline after sleeping (at most a
    /// quarter period; 0 sleeps to the deadline).
    #[arg(long, default_value_t = 100)]
    spin_us: u64,
    /// Consecutive deadline misses that stop the session (0: never).
    /// Default: 10 when the graph drives hardware (a late actuation reaches
    /// a person), 0 on the simulated lab, where a loaded machine's misses
    /// are only counted.
    #[arg(long, value_name = "N")]
    miss_streak: Option<u64>,
    /// Print only the final report.
    #[arg(long, short)]
    quiet: bool,
    /// Also write the final report as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Serve the studio: a web page showing the session as it runs and
    /// steering its live parameters (docs/studio.md). ADDR is `PORT` or
    /// `HOST:PORT` (default 127.0.0.1:8737; port 0 picks a free one);
    /// `evflow studio SESSION` takes the same `--studio ADDR` (or `--addr`).
    #[cfg(feature = "studio")]
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8737")]
    studio: Option<String>,
    /// Let the studio listen on a non-loopback address; the page then needs
    /// the one-time token printed at start.
    #[cfg(feature = "studio")]
    #[arg(long, requires = "studio")]
    studio_public: bool,
}

#[cfg(feature = "studio")]
impl recorder::Tee for evflow_tools::studio::Ingest {
    fn samples(&mut self, tap: usize, samples: &[f64]) {
        evflow_tools::studio::Ingest::samples(self, tap, samples);
    }
    fn event(&mut self, e: &evflow_engine::live::Event) {
        evflow_tools::studio::Ingest::event(self, e);
    }
}

/// Runs `evflow live`.
pub fn main(a: Args) -> Result<()> {
    // -q: the serial I/O threads' link notices go to the summary only.
    #[cfg(feature = "serial")]
    evflow_nodes::serial::set_notices(!a.quiet);
    let checked = a.graph.load()?;
    // Bound before the session (and its folder) starts: a taken port stops
    // nothing that runs.
    #[cfg(feature = "studio")]
    let bound = match &a.studio {
        Some(addr) => {
            let cfg =
                evflow_tools::studio::StudioConfig { addr: super::studio::studio_addr(addr)?, public: a.studio_public };
            Some(evflow_tools::studio::Bound::bind(&cfg)?)
        }
        None => None,
    };
    let graph_text =
        std::fs::read_to_string(&a.graph.file).with_context(|| format!("{}: cannot read", a.graph.file.display()))?;
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;
    let seed = a.seed.unwrap_or(checked.graph.seed);
    let opts = PlanOptions {
        max_block: 1,
        seed: Some(seed),
        base_dir: None,
        out_dir: Some(a.out.clone()),
        timing: false,
        mode: evflow_engine::RunMode::Live,
        check_only: false,
    };
    let plan = Plan::build(&checked, &opts).map_err(|e| anyhow!("{e}"))?;
    #[allow(unused_mut)]
    let mut extra = a.taps.clone();
    #[cfg(feature = "studio")]
    if a.studio.is_some() {
        // What the page shows by default is recorded too.
        extra.extend(
            evflow_tools::studio::default_taps(&checked, &plan).into_iter().map(|t| format!("{}.{}", t.node, t.port)),
        );
    }
    let (taps, n_inputs) = taps_of(&plan, &extra)?;
    let lp = LivePlan::new(plan, &taps).map_err(|e| anyhow!("{}: {e}", a.graph.file.display()))?;
    let (inputs, outputs) = session::files(lp.taps(), n_inputs)?;

    // The session folder and its manifest, before anything runs.
    let dir = a.session.clone().unwrap_or_else(|| a.out.join("sessions").join(session_name(&checked.graph.name)));
    if dir.join("session.json").exists() {
        return Err(anyhow!("{}: a session is already recorded there; choose another --session", dir.display()));
    }
    std::fs::create_dir_all(&dir).map_err(|e| anyhow!("{}: cannot create the session folder: {e}", dir.display()))?;
    std::fs::write(dir.join("graph.toml"), &graph_text)?;
    let graph_hash = integrity::file_hash(&dir.join("graph.toml"))
        .map_err(|e| anyhow!("{}: cannot read back: {e}", dir.join("graph.toml").display()))?;
    let graph_path = std::fs::canonicalize(&a.graph.file).unwrap_or_else(|_| a.graph.file.clone());
    let manifest = Manifest {
        identity: Some(integrity::identity(&graph_hash, seed, &a.graph.set, lp.plan().base_rate(), &inputs, &outputs)),
        graph_hash: Some(graph_hash),
        name: checked.graph.name.clone(),
        base_dir: graph_path.parent().map(Path::to_path_buf).unwrap_or_default(),
        graph_source: graph_path,
        overrides: a.graph.set.clone(),
        seed,
        base_rate: lp.plan().base_rate(),
        inputs: inputs.clone(),
        outputs: outputs.clone(),
        started: std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0),
    };
    manifest.write(&dir, "running", None)?;

    let duration = if a.endless { None } else { a.duration.or(checked.graph.duration) };
    let last_cpu = std::thread::available_parallelism().map(|n| n.get() - 1).unwrap_or(0);
    let realtime = if a.no_realtime {
        RealtimeRequest::default()
    } else {
        RealtimeRequest { priority: Some(a.priority), lock_memory: true, cpu: Some(a.cpu.unwrap_or(last_cpu)) }
    };
    let hardware = checked.nodes.iter().any(|n| n.spec.hardware);
    let miss_streak = a.miss_streak.unwrap_or(if hardware { DEFAULT_MISS_STREAK } else { 0 });
    let cfg =
        LiveConfig { duration, realtime, spin: Duration::from_micros(a.spin_us), miss_streak, ..LiveConfig::default() };
    let vars = live::live_vars(&checked);
    #[cfg(feature = "studio")]
    let description = a.studio.is_some().then(|| {
        let graph_dir = a.graph.file.parent().unwrap_or(Path::new("."));
        evflow_tools::studio::Description::live(&checked, &lp, &vars)
            .with_scene(evflow_tools::studio::scene_json(&checked, graph_dir))
    });
    let mut session = live::start(lp, &cfg).map_err(|e| anyhow!("{e}"))?;
    let vars_line = vars
        .iter()
        .map(|v| {
            let uses: Vec<String> = v.uses.iter().map(|(n, p)| format!("{n}.{p}")).collect();
            format!("{} ({})", v.name, uses.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ");
    session.control.bind_vars(vars);
    for c in &a.changes {
        let (t, change) = c
            .split_once(':')
            .ok_or_else(|| anyhow!("--change {c}: expected SECONDS:node.param=value or SECONDS:variable=value"))?;
        let t: f64 = t.trim().parse().map_err(|_| anyhow!("--change {c}: `{t}` is not a number of seconds"))?;
        let at = session.control.tick_at(t);
        session.control.set_text(change, Some(at)).map_err(|e| anyhow!("--change {c}: {e}"))?;
    }
    let base_rate = session.base_rate;
    let names = session.node_names.clone();
    let parts = session.into_parts();
    let shared = parts.shared.clone();
    // The console and the studio queue changes through the same control.
    let control = Arc::new(std::sync::Mutex::new(parts.control));
    #[cfg(feature = "studio")]
    let studio = match (bound, description) {
        (Some(bound), Some(d)) => {
            let (studio, ingest) = bound.start_live(&d, control.clone(), shared.clone())?;
            eprintln!("studio: {}", studio.url());
            if studio.token().is_some() {
                eprintln!("studio: serving beyond this machine; the address above holds its one-time token");
            }
            Some((studio, ingest))
        }
        _ => None,
    };

    // Ctrl-C: the first stops (the limiters fade out), a second quits at once.
    let presses = Arc::new(AtomicU32::new(0));
    {
        let shared = shared.clone();
        let presses = presses.clone();
        let _ = ctrlc::set_handler(move || {
            if presses.fetch_add(1, Ordering::SeqCst) == 0 {
                shared.request_stop(StopReason::Requested);
            } else {
                eprintln!("\nsecond Ctrl-C: quitting without waiting");
                std::process::exit(130);
            }
        });
    }

    // Recorder, metrics display and console: ordinary threads.
    let done = Arc::new(AtomicBool::new(false));
    let recorder = Recorder::create(&dir, &[inputs, outputs].concat(), parts.taps, parts.events, names, "evflow live")?;
    #[cfg(feature = "studio")]
    let recorder = match &studio {
        Some((_, ingest)) => recorder.tee(Box::new(ingest.clone())),
        None => recorder,
    };
    let rec_thread = {
        let done = done.clone();
        std::thread::Builder::new()
            .name("evflow-recorder".into())
            .spawn(move || recorder.run(done, Duration::from_millis(20), Duration::from_millis(200)))?
    };
    let show = !a.quiet;
    let metrics_thread = {
        let done = done.clone();
        let shared = shared.clone();
        let mut stats = parts.stats;
        #[cfg(feature = "studio")]
        let ingest = studio.as_ref().map(|(_, i)| i.clone());
        #[cfg(not(feature = "studio"))]
        let ingest: Option<()> = None;
        std::thread::Builder::new().name("evflow-metrics".into()).spawn(move || {
            let mut m = Metrics::new();
            let mut shown = Instant::now();
            let tty = std::io::stderr().is_terminal();
            let steal0 = steal::steal_seconds();
            while !done.load(Ordering::Acquire) {
                std::thread::sleep(Duration::from_millis(50));
                #[cfg(feature = "studio")]
                if let Some(i) = &ingest {
                    drain_to_studio(&mut m, &mut stats, i);
                    i.steal(steal::steal_seconds().zip(steal0).map(|(b, a)| (b - a).max(0.0)));
                }
                #[cfg(not(feature = "studio"))]
                let _ = &ingest;
                m.drain(&mut stats);
                if show && shown.elapsed() >= Duration::from_secs(1) {
                    let mut line = m.summary(&shared, base_rate).line();
                    // The host's steal so far: misses that coincide with it are the VM's, not the graph's.
                    if let Some(st) = steal::steal_seconds().zip(steal0).map(|(b, a)| b - a).filter(|&st| st > 0.0) {
                        line += &format!(" | host steal {:.0} ms", st * 1e3);
                    }
                    if tty {
                        eprint!("\r{line}\x1b[K");
                    } else {
                        eprintln!("{line}");
                    }
                    shown = Instant::now();
                }
            }
            m.drain(&mut stats);
            if show && tty {
                eprintln!();
            }
            m
        })?
    };
    if show {
        eprintln!(
            "live: `{}` at {base_rate} Hz{}; recording to {}",
            checked.graph.name,
            duration.map(|d| format!(" for {d} s")).unwrap_or_default(),
            dir.display()
        );
        eprintln!(
            "{}",
            match (miss_streak, hardware) {
                (0, false) => "deadline misses are counted; without hardware they never stop the session \
                               (--miss-streak N stops it after N in a row)"
                    .to_string(),
                (0, true) => "deadline misses are counted and never stop the session (--miss-streak 0)".to_string(),
                (n, _) => format!("{n} deadline misses in a row stop the session (--miss-streak)"),
            }
        );
        eprintln!("type node.param=value and Enter to change a live parameter, `stop` or Ctrl-C to stop");
        if !vars_line.is_empty() {
            eprintln!("or variable=value for a graph variable, which changes its parameters at one tick: {vars_line}");
        }
    }
    std::thread::Builder::new().name("evflow-console".into()).spawn(move || {
        let stdin = std::io::stdin();
        for line in stdin.lock().lines() {
            let Ok(line) = line else { break };
            let line = line.trim();
            match line {
                "" => {}
                "stop" | "q" | "quit" => control.lock().unwrap_or_else(|e| e.into_inner()).stop(),
                _ => match control.lock().unwrap_or_else(|e| e.into_inner()).set_text(line, None) {
                    Ok(()) => eprintln!("queued {line}"),
                    Err(e) => eprintln!("{e}"),
                },
            }
            control.lock().unwrap_or_else(|e| e.into_inner()).collect_retired();
        }
    })?;

    let started = Instant::now();
    let steal_before = steal::steal_seconds();
    let exit = parts.thread.join();
    let wall = started.elapsed();
    let stolen = steal::steal_seconds().zip(steal_before).map(|(b, a)| (b - a).max(0.0));
    done.store(true, Ordering::Release);
    let rec = rec_thread.join().map_err(|_| anyhow!("the recorder thread panicked"))?;
    let metrics = metrics_thread.join().map_err(|_| anyhow!("the metrics thread panicked"))?;
    #[cfg(feature = "studio")]
    if let Some((studio, _)) = studio {
        // The last frames reach the page before it is told the session ended.
        std::thread::sleep(Duration::from_millis(150));
        if studio.frames_dropped() > 0 {
            eprintln!(
                "studio: browsers lost {} frames (slow to read; the session was not delayed)",
                studio.frames_dropped()
            );
        }
        studio.close();
    }
    let summary = metrics.summary(&shared, base_rate);
    let mut exit = exit;
    let sums = exit.plan.plan_mut().finish().map_err(|e| anyhow!("{e}"))?;

    let reason = match (&exit.failure, exit.reason) {
        (Some(f), _) => format!("node failure: {f}"),
        (None, Some(r)) => r.as_str().to_string(),
        (None, None) => "unknown".into(),
    };
    let files: Vec<_> = rec
        .files
        .iter()
        .map(|(f, n, gap, err)| {
            // The fingerprint of the samples as written: `evflow replay --check` holds the file to it.
            let hash = integrity::file_hash(&dir.join(format!("{f}.wav"))).ok();
            json!({ "file": f, "frames": n, "gap_frames": gap, "error": err, "hash": hash })
        })
        .collect();
    let end = json!({
        "ticks": exit.ticks,
        "seconds": exit.ticks as f64 / base_rate,
        "wall_seconds": wall.as_secs_f64(),
        "stopped": reason,
        "realtime": exit.realtime.to_string(),
        "metrics": metrics_json(&summary),
        "host_steal_seconds": stolen,
        "files": files,
        "events": rec.events,
    });
    manifest.write(&dir, if exit.failure.is_some() { "failed" } else { "ended" }, Some(end.clone()))?;
    if let Some(path) = &a.json {
        std::fs::write(path, serde_json::to_string_pretty(&end)?)
            .map_err(|e| anyhow!("{}: cannot write results: {e}", path.display()))?;
    }

    println!(
        "session {}: {} ticks ({:.3} s), stopped: {reason}",
        dir.display(),
        exit.ticks,
        exit.ticks as f64 / base_rate
    );
    println!("real-time thread: {}", exit.realtime);
    if let Some(st) = stolen.filter(|&st| st > 0.0) {
        println!(
            "host steal: {:.0} ms of CPU time taken from this virtual machine by its host during the session \
             (stalls no setting inside the machine prevents; see docs/live.md)",
            st * 1e3
        );
    }
    println!("{summary}");
    for (f, n, gap, err) in &rec.files {
        let gap = if *gap > 0 {
            format!(", {gap} lost to a slow disk (zero-filled, see events.jsonl)")
        } else {
            String::new()
        };
        match err {
            None => println!("recorded {f} ({n} frames{gap})"),
            Some(e) => println!("recorded {f}: FAILED: {e}"),
        }
    }
    if let Some(e) = &rec.event_error {
        println!("event log: FAILED: {e}");
    }
    for (node, s) in &sums {
        for l in &s.lines {
            println!("{node}: {l}");
        }
        for (k, v, unit) in &s.values {
            println!("{node}: {k} = {v}{}", unit_suffix(unit));
        }
    }
    match exit.failure {
        Some(f) => Err(anyhow!("{f}")),
        None if exit.reason.is_some_and(|r| r.is_fault()) => Err(anyhow!("session stopped by a fault: {reason}")),
        None => Ok(()),
    }
}

/// Hands the tick timings to the studio as well, then counts them.
#[cfg(feature = "studio")]
fn drain_to_studio(
    m: &mut Metrics,
    ring: &mut evflow_engine::live::rtrb::Consumer<evflow_engine::live::TickStat>,
    studio: &evflow_tools::studio::Ingest,
) {
    let n = ring.slots();
    if let Ok(chunk) = ring.read_chunk(n) {
        let (a, b) = chunk.as_slices();
        studio.stats(a);
        studio.stats(b);
        for s in a.iter().chain(b) {
            m.absorb(s);
        }
        chunk.commit_all();
    }
}

/// ` unit`, or nothing for dimensionless values.
pub(crate) fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() || unit == "1" {
        String::new()
    } else {
        format!(" {unit}")
    }
}

fn metrics_json(s: &evflow_engine::live::MetricsSummary) -> serde_json::Value {
    let p = |p: &evflow_engine::live::Percentiles| json!({ "p50": p.p50, "p99": p.p99, "p99_9": p.p999, "max": p.max, "mean": p.mean });
    json!({
        "jitter_us": p(&s.jitter),
        "compute_us": p(&s.compute),
        "deadline_misses": s.misses,
        "longest_miss_streak": s.longest_streak,
        "tap_overruns": s.tap_overruns,
        "event_overruns": s.event_overruns,
        "stat_overruns": s.stat_overruns,
        "command_overruns": s.command_overruns,
    })
}

/// Sources first (the session's inputs), then guards and `--tap`s.
fn taps_of(plan: &Plan, extra: &[String]) -> Result<(Vec<Tap>, usize)> {
    let mut taps = LivePlan::source_taps(plan);
    let n_inputs = taps.len();
    for t in LivePlan::guard_taps(plan) {
        if !taps.contains(&t) {
            taps.push(t);
        }
    }
    for e in extra {
        let (node, port) = e.split_once('.').ok_or_else(|| anyhow!("--tap {e}: expected node.port"))?;
        let t = Tap::new(node, port);
        if !taps[n_inputs..].contains(&t) {
            taps.push(t);
        }
    }
    Ok((taps, n_inputs))
}

/// `NAME-YYYYMMDD-HHMMSS` in UTC.
fn session_name(graph: &str) -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{graph}-{y:04}{m:02}{d:02}-{:02}{:02}{:02}", rem / 3600, rem % 3600 / 60, rem % 60)
}

#[cfg(test)]
mod tests {
    #[test]
    fn session_names_sort_by_time() {
        let n = super::session_name("g");
        assert!(n.starts_with("g-20"), "{n}");
        assert_eq!(n.len(), "g-20250101-120000".len());
    }
}
