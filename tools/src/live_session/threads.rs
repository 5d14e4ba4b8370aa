//! The ordinary threads around the real-time one: Ctrl-C, the recorder,
//! the metrics display and the console.

use super::error::SessionError;
use super::recorder::{Recorder, RecorderReport};
use super::steal;
use evflow_engine::live::{rtrb, Control, Metrics, Shared, StopReason, TickStat};
use std::io::{BufRead, IsTerminal};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the metrics thread hands tick timings and steal to: the studio's
/// ingest, or nothing in a build without the studio.
#[cfg(feature = "studio")]
pub(super) type StudioFeed = crate::studio::Ingest;
/// What the metrics thread hands tick timings and steal to: the studio's
/// ingest, or nothing in a build without the studio.
#[cfg(not(feature = "studio"))]
pub(super) type StudioFeed = ();

/// Ctrl-C: the first stops (the limiters fade out), a second quits at once.
pub(super) fn on_ctrl_c(shared: &Arc<Shared>) {
    let presses = Arc::new(AtomicU32::new(0));
    let shared = shared.clone();
    let _ = ctrlc::set_handler(move || {
        if presses.fetch_add(1, Ordering::SeqCst) == 0 {
            shared.request_stop(StopReason::Requested);
        } else {
            eprintln!("\nsecond Ctrl-C: quitting without waiting");
            std::process::exit(130);
        }
    });
}

/// How often the recorder drains the rings.
const DRAIN_EVERY: Duration = Duration::from_millis(20);

/// How often the disk thread flushes the session's files.
pub(super) const FLUSH_EVERY: Duration = Duration::from_millis(200);

/// Starts the recorder's thread, which drains the taps and events until
/// `done` and hands them to its disk thread.
pub(super) fn spawn_recorder(
    recorder: Recorder,
    done: &Arc<AtomicBool>,
) -> Result<JoinHandle<RecorderReport>, SessionError> {
    let done = done.clone();
    std::thread::Builder::new()
        .name("evflow-recorder".into())
        .spawn(move || recorder.run(done, DRAIN_EVERY))
        .map_err(SessionError::spawn)
}

/// The metrics display: drains the tick timings until `done` and, unless
/// quiet, shows a line of them each second.
pub(super) struct Display {
    /// Set when the real-time thread has ended.
    pub done: Arc<AtomicBool>,
    /// The session's shared state.
    pub shared: Arc<Shared>,
    /// The session's base rate (Hz).
    pub base_rate: f64,
    /// Whether to show the line (not `--quiet`).
    pub show: bool,
}

impl Display {
    /// Starts the metrics thread; it returns the metrics of the whole
    /// session.
    pub(super) fn spawn(
        self,
        stats: rtrb::Consumer<TickStat>,
        ingest: Option<StudioFeed>,
    ) -> Result<JoinHandle<Metrics>, SessionError> {
        std::thread::Builder::new()
            .name("evflow-metrics".into())
            .spawn(move || self.run(stats, ingest))
            .map_err(SessionError::spawn)
    }

    /// The metrics thread's loop.
    fn run(self, mut stats: rtrb::Consumer<TickStat>, ingest: Option<StudioFeed>) -> Metrics {
        let Display { done, shared, base_rate, show } = self;
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
    }
}

/// Hands the tick timings to the studio as well, then counts them.
#[cfg(feature = "studio")]
fn drain_to_studio(m: &mut Metrics, ring: &mut rtrb::Consumer<TickStat>, studio: &crate::studio::Ingest) {
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

/// Starts the console thread: each line of stdin is a change queued on the
/// control, or `stop`.
pub(super) fn spawn_console(control: Arc<Mutex<Control>>) -> Result<(), SessionError> {
    std::thread::Builder::new()
        .name("evflow-console".into())
        .spawn(move || {
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
        })
        .map_err(SessionError::spawn)?;
    Ok(())
}
