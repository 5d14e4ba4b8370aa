//! What a live session is asked to do: the plain settings `evflow live`
//! builds from its command line (the library knows no command-line parser).

use std::path::PathBuf;

/// Deadline misses in a row that stop a session driving hardware.
pub const DEFAULT_MISS_STREAK: u64 = 10;

/// The settings of one live session; each field is the `evflow live`
/// option of its name (`evflow live --help` explains them to users).
#[derive(Debug, Clone)]
pub struct SessionConfig {
    /// The graph file: copied into the session folder, fingerprinted, and
    /// named in the manifest (`graph_source`) and in errors.
    pub graph_file: PathBuf,
    /// The `--set` overrides as typed (`name=value`, `node.param=value`),
    /// recorded in the manifest; the graph given to [`run`](fn@super::run)
    /// must have been loaded with them.
    pub overrides: Vec<String>,
    /// The session length in seconds (`None`: the graph's `duration`).
    pub duration: Option<f64>,
    /// Run until stopped, ignoring the graph's `duration`.
    pub endless: bool,
    /// The seed of every random stream (`None`: the graph's `seed`).
    pub seed: Option<u64>,
    /// The session folder (`None`: `OUT/sessions/NAME-YYYYMMDD-HHMMSS`).
    pub session: Option<PathBuf>,
    /// The folder for sessions and for files the graph writes.
    pub out: PathBuf,
    /// Further output ports to record (`node.port`), besides every
    /// source's outputs and every safety limiter's.
    pub taps: Vec<String>,
    /// Scripted changes, `SECONDS:node.param=value` or
    /// `SECONDS:variable=value`, applied at exactly that tick.
    pub changes: Vec<String>,
    /// Ask for SCHED_FIFO, memory locking and CPU pinning (`false`:
    /// `--no-realtime`).
    pub realtime: bool,
    /// The real-time thread's SCHED_FIFO priority (1–99).
    pub priority: i32,
    /// The CPU to pin the real-time thread to (`None`: the last one).
    pub cpu: Option<usize>,
    /// Microseconds spun before each deadline after sleeping.
    pub spin_us: u64,
    /// Deadline misses in a row that stop the session, 0 never (`None`:
    /// [`DEFAULT_MISS_STREAK`] when the graph drives hardware, else 0).
    pub miss_streak: Option<u64>,
    /// Show only the final report: no intro, no once-a-second metrics line,
    /// no echo of the changes as they land.
    pub quiet: bool,
    /// Also write the record of the session's end as JSON to this file.
    pub json: Option<PathBuf>,
    /// Serve the studio there while the session runs (`None`: no studio).
    #[cfg(feature = "studio")]
    pub studio: Option<crate::studio::StudioConfig>,
}
