//! `evflow live FILE`: run a graph in real time, recording the session.

mod ending;
mod setup;
mod threads;

use super::graph_args::GraphArgs;
use anyhow::{anyhow, Context, Result};
use evflow_engine::live;
use evflow_tools::live_session::recorder::Recorder;
use evflow_tools::live_session::{disk, integrity, recorder, session, steal};
#[cfg(feature = "studio")]
use std::path::Path;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
#[cfg(feature = "studio")]
use std::time::Duration;

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

/// Runs `evflow live`.
pub fn main(a: Args) -> Result<()> {
    // -q: the serial I/O threads' link notices go to the summary only.
    #[cfg(feature = "serial")]
    evflow_nodes::serial::set_notices(!a.quiet);
    let checked = a.graph.load()?;
    // Bound before the session (and its folder) starts: a taken port stops
    // nothing that runs.
    #[cfg(feature = "studio")]
    let bound = bind_studio(&a)?;
    let graph_text =
        std::fs::read_to_string(&a.graph.file).with_context(|| format!("{}: cannot read", a.graph.file.display()))?;
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;
    let seed = a.seed.unwrap_or(checked.graph.seed);
    let (lp, n_inputs) = setup::live_plan(&a, &checked, seed)?;
    let (inputs, outputs) = session::files(lp.taps(), n_inputs)?;
    let folder = setup::Folder { graph_text: &graph_text, seed, inputs: &inputs, outputs: &outputs };
    let (dir, manifest) = folder.open(&a, &checked, &lp)?;
    let pacing = setup::Pacing::of(&a, &checked);
    let vars = live::live_vars(&checked);
    #[cfg(feature = "studio")]
    let description = a.studio.is_some().then(|| {
        let graph_dir = a.graph.file.parent().unwrap_or(Path::new("."));
        evflow_tools::studio::Description::live(&checked, &lp, &vars)
            .with_scene(evflow_tools::studio::scene_json(&checked, graph_dir))
    });
    // The files first: creating them syncs each to disk, which must not
    // happen while the real-time thread fills its rings.
    let files = disk::Files::create(&dir, &[inputs, outputs].concat(), "evflow live")?;
    let mut session = live::start(lp, &pacing.config).map_err(|e| anyhow!("{e}"))?;
    let vars_line = setup::vars_line(&vars);
    session.control.bind_vars(vars);
    setup::schedule_changes(&mut session.control, &a.changes)?;
    let base_rate = session.base_rate;
    let names = session.node_names.clone();
    let parts = session.into_parts();
    let shared = parts.shared.clone();
    // The console and the studio queue changes through the same control.
    let control = Arc::new(std::sync::Mutex::new(parts.control));
    #[cfg(feature = "studio")]
    let studio = start_studio(bound, description, &control, &shared)?;
    threads::on_ctrl_c(&shared);

    // Recorder, metrics display and console: ordinary threads.
    let done = Arc::new(AtomicBool::new(false));
    let recorder = Recorder::create(files, parts.taps, parts.events, names, threads::FLUSH_EVERY)?;
    let recorder = if a.quiet { recorder } else { recorder.echo(base_rate) };
    #[cfg(feature = "studio")]
    let recorder = match &studio {
        Some((_, ingest)) => recorder.tee(Box::new(ingest.clone())),
        None => recorder,
    };
    let rec_thread = threads::spawn_recorder(recorder, &done)?;
    let show = !a.quiet;
    #[cfg(feature = "studio")]
    let ingest = studio.as_ref().map(|(_, i)| i.clone());
    #[cfg(not(feature = "studio"))]
    let ingest: Option<()> = None;
    let display = threads::Display { done: done.clone(), shared: shared.clone(), base_rate, show };
    let metrics_thread = display.spawn(parts.stats, ingest)?;
    if show {
        pacing.print_intro(&checked.graph.name, base_rate, &dir, &vars_line);
    }
    threads::spawn_console(control)?;

    let ran = ending::Ran::wait(parts.thread, &done, rec_thread, metrics_thread)?;
    #[cfg(feature = "studio")]
    if let Some((studio, _)) = studio {
        close_studio(studio);
    }
    ran.finish(&a, &dir, &manifest, &shared, base_rate)
}

/// Binds the studio's address when `--studio` asks for it.
#[cfg(feature = "studio")]
fn bind_studio(a: &Args) -> Result<Option<evflow_tools::studio::Bound>> {
    Ok(match &a.studio {
        Some(addr) => {
            let cfg =
                evflow_tools::studio::StudioConfig { addr: super::studio::studio_addr(addr)?, public: a.studio_public };
            Some(evflow_tools::studio::Bound::bind(&cfg)?)
        }
        None => None,
    })
}

/// Starts serving the studio on the bound address, sharing the session's
/// control; prints its address.
#[cfg(feature = "studio")]
fn start_studio(
    bound: Option<evflow_tools::studio::Bound>,
    description: Option<evflow_tools::studio::Description>,
    control: &Arc<std::sync::Mutex<live::Control>>,
    shared: &Arc<live::Shared>,
) -> Result<Option<(evflow_tools::studio::Studio, evflow_tools::studio::Ingest)>> {
    Ok(match (bound, description) {
        (Some(bound), Some(d)) => {
            let (studio, ingest) = bound.start_live(&d, control.clone(), shared.clone())?;
            eprintln!("studio: {}", studio.url());
            if studio.token().is_some() {
                eprintln!("studio: serving beyond this machine; the address above holds its one-time token");
            }
            Some((studio, ingest))
        }
        _ => None,
    })
}

/// Lets the last frames reach the page, reports frames browsers lost, and
/// closes the studio.
#[cfg(feature = "studio")]
fn close_studio(studio: evflow_tools::studio::Studio) {
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
