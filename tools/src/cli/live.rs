//! `evflow live FILE`: run a graph in real time, recording the session
//! (the session itself is [`evflow_tools::live_session`]).

use super::graph_args::GraphArgs;
use anyhow::Result;
use evflow_tools::live_session::{self, SessionConfig};
use std::path::PathBuf;

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
    let ended = live_session::run(&config(a)?, &checked)?;
    print!("{ended}");
    Ok(ended.outcome()?)
}

/// The session's settings from the command line.
fn config(a: Args) -> Result<SessionConfig> {
    Ok(SessionConfig {
        #[cfg(feature = "studio")]
        studio: match &a.studio {
            Some(addr) => Some(evflow_tools::studio::StudioConfig {
                addr: super::studio::studio_addr(addr)?,
                public: a.studio_public,
            }),
            None => None,
        },
        graph_file: a.graph.file,
        overrides: a.graph.set,
        duration: a.duration,
        endless: a.endless,
        seed: a.seed,
        session: a.session,
        out: a.out,
        taps: a.taps,
        changes: a.changes,
        realtime: !a.no_realtime,
        priority: a.priority,
        cpu: a.cpu,
        spin_us: a.spin_us,
        miss_streak: a.miss_streak,
        quiet: a.quiet,
        json: a.json,
    })
}
