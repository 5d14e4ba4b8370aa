//! The live runner: one real-time thread ticks a plan on absolute
//! deadlines (1 ms at 1 kHz); other threads talk to it only through
//! lock-free single-producer single-consumer rings (rtrb).
//!
//! ```text
//!  control thread ──commands (tick-stamped, ordered)──▶ ┌──────────────┐ ──taps (samples)──▶ recorder
//!                 ──replacement plans───────────────▶ │ real-time    │ ──events─────────▶ recorder
//!                 ◀──retired plans (dropped here)──── │ thread       │ ──tick timings───▶ metrics
//!  any thread ──stop / fault (atomic)───────────────▶ └──────────────┘
//! ```
//!
//! * The plan is built off the real-time thread ([`LivePlan::new`]) and
//!   moved to it; a replacement goes through a ring, and the replaced plan
//!   comes back through another to be dropped by the control side.
//! * Each tick: wait for the deadline (sleep until shortly before it, then
//!   spin for at most a quarter period), apply the commands due, run
//!   [`crate::plan::Plan::tick`] — the same code the offline runner calls —
//!   copy the tapped ports into their rings, and push the tick's timing.
//! * A full ring never blocks the real-time thread: the samples of that
//!   tick are dropped for every tap (so the rings stay aligned), counted,
//!   and reported as a gap event.
//! * Stopping (Ctrl-C, the duration, a finite source about to end, a streak
//!   of deadline misses, a device fault) disables every safety guard and
//!   keeps ticking for the fade (`stop_ramp`), so the actuation reaches zero
//!   before the thread ends.
//!
//! See `docs/live.md`.

mod clock;
mod control;
mod histogram;
mod liveplan;
mod message;
mod metrics;
mod rt;
mod system;
mod vars;

/// The ring buffer crate the runner's rings come from.
pub use rtrb;

pub use clock::{now_ns, thread_cpu_ns, wait_until, Wait};
pub use control::{parse_value, Control};
pub use histogram::{Histogram, Percentiles};
pub use liveplan::{LiveError, LivePlan, Tap, TapInfo};
pub use message::{Command, Event, EventKind, Shared, StopReason, TickStat};
pub use metrics::{Metrics, MetricsSummary};
pub use rt::{RtExit, RtHook};
pub use system::{RealtimeReport, RealtimeRequest};
pub use vars::{live_vars, LiveVar};

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// How to run a session.
#[derive(Debug, Clone)]
pub struct LiveConfig {
    /// Session length in seconds (the stop sequence runs after it); `None`
    /// runs until stopped or a finite source ends.
    pub duration: Option<f64>,
    /// What to ask of the system for the real-time thread.
    pub realtime: RealtimeRequest,
    /// How long before each deadline the sleep ends and the spin begins (at
    /// most a quarter period; zero sleeps to the deadline).
    pub spin: Duration,
    /// Consecutive deadline misses that stop the session (0: never).
    pub miss_streak: u64,
    /// The longest fade a safety guard takes (`limit` ramps in ≤ 10 ms):
    /// how long the runner keeps ticking after disabling the guards.
    pub stop_ramp: Duration,
    /// Capacity of each tap ring, in seconds of samples.
    pub tap_seconds: f64,
    /// Capacity of the tick-timing ring, in ticks.
    pub stat_capacity: usize,
    /// Called on the real-time thread around its loop (tests).
    pub hook: Option<RtHook>,
}

impl Default for LiveConfig {
    fn default() -> Self {
        Self {
            duration: None,
            realtime: RealtimeRequest::default(),
            spin: Duration::from_micros(100),
            miss_streak: 10,
            stop_ramp: Duration::from_millis(10),
            tap_seconds: 4.0,
            stat_capacity: 1 << 16,
            hook: None,
        }
    }
}

/// A running session: the handles of every ring's other end.
pub struct Live {
    /// Commands, stop, plan replacement.
    pub control: Control,
    /// One ring per tap, in the order requested, with what it carries.
    pub taps: Vec<(TapInfo, rtrb::Consumer<f64>)>,
    /// What the real-time thread did, tick-stamped.
    pub events: rtrb::Consumer<Event>,
    /// Per-tick timing.
    pub stats: rtrb::Consumer<TickStat>,
    /// Counters and the stop flag.
    pub shared: Arc<Shared>,
    /// Node names by plan index (to name events).
    pub node_names: Vec<String>,
    /// The base rate in Hz.
    pub base_rate: f64,
    /// Base ticks the stop sequence runs.
    pub stop_ticks: u64,
    thread: JoinHandle<RtExit>,
}

impl Live {
    /// True once the real-time thread has ended.
    pub fn is_finished(&self) -> bool {
        self.thread.is_finished()
    }
}

/// The real-time thread's handle, separated from the rings so they can be
/// moved to other threads.
pub struct RtThread(JoinHandle<RtExit>);

impl RtThread {
    /// Waits for the real-time thread to end.
    pub fn join(self) -> RtExit {
        match self.0.join() {
            Ok(x) => x,
            Err(p) => std::panic::resume_unwind(p),
        }
    }
    /// True once it has ended.
    pub fn is_finished(&self) -> bool {
        self.0.is_finished()
    }
}

/// The parts of a [`Live`] session, to hand to different threads.
pub struct LiveParts {
    /// See [`Live::control`].
    pub control: Control,
    /// See [`Live::taps`].
    pub taps: Vec<(TapInfo, rtrb::Consumer<f64>)>,
    /// See [`Live::events`].
    pub events: rtrb::Consumer<Event>,
    /// See [`Live::stats`].
    pub stats: rtrb::Consumer<TickStat>,
    /// See [`Live::shared`].
    pub shared: Arc<Shared>,
    /// The real-time thread.
    pub thread: RtThread,
}

impl Live {
    /// Splits the session into its parts.
    pub fn into_parts(self) -> LiveParts {
        LiveParts {
            control: self.control,
            taps: self.taps,
            events: self.events,
            stats: self.stats,
            shared: self.shared,
            thread: RtThread(self.thread),
        }
    }

    /// Waits for the real-time thread to end (after a stop, the duration or
    /// the end of a finite source).
    pub fn join(self) -> RtExit {
        self.into_parts().thread.join()
    }
}

/// Starts a session: builds every ring, moves the plan to a new real-time
/// thread and returns the other ends. The first tick runs one period after
/// the thread starts.
pub fn start(plan: LivePlan, config: &LiveConfig) -> Result<Live, LiveError> {
    let base_rate = plan.plan.base_rate();
    let period_ns = (1e9 / base_rate).round() as u64;
    let stop_ticks = (config.stop_ramp.as_secs_f64() * base_rate).ceil() as u64 + 1;
    let shared = Arc::new(Shared::default());
    let (cmd_tx, cmd_rx) = rtrb::RingBuffer::new(1024);
    let (plan_tx, plan_rx) = rtrb::RingBuffer::new(1);
    let (ret_tx, ret_rx) = rtrb::RingBuffer::new(2);
    let (ev_tx, ev_rx) = rtrb::RingBuffer::new(4096);
    let (st_tx, st_rx) = rtrb::RingBuffer::new(config.stat_capacity.max(16));
    let mut tap_tx = Vec::new();
    let mut taps = Vec::new();
    for info in &plan.info {
        let per_tick = if info.ratio.div == 1 { info.ratio.mul as f64 } else { 1.0 / info.ratio.div as f64 };
        let cap = ((config.tap_seconds * base_rate * per_tick).ceil() as usize).max(2 * info.ratio.mul as usize);
        let (tx, rx) = rtrb::RingBuffer::new(cap);
        tap_tx.push(tx);
        taps.push((info.clone(), rx));
    }
    let node_names: Vec<String> = (0..plan.plan.len()).map(|k| plan.plan.node_name(k).to_string()).collect();
    let control = Control {
        commands: cmd_tx,
        plans: plan_tx,
        retired: ret_rx,
        shared: shared.clone(),
        nodes: (0..plan.plan.len()).map(|k| (plan.plan.node_name(k).to_string(), plan.plan.spec(k))).collect(),
        taps: plan.info.clone(),
        base_rate,
        vars: Vec::new(),
    };
    let state = rt::RtState {
        plan: Box::new(plan),
        commands: cmd_rx,
        plans: plan_rx,
        retired: ret_tx,
        taps: tap_tx,
        events: ev_tx,
        stats: st_tx,
        shared: shared.clone(),
        request: config.realtime.clone(),
        period_ns,
        spin_ns: config.spin.as_nanos() as u64,
        stop_ticks,
        duration_ticks: config.duration.map(|d| (d * base_rate).round().max(0.0) as u64),
        miss_streak: config.miss_streak,
        hook: config.hook,
    };
    let thread = std::thread::Builder::new()
        .name("evflow-rt".into())
        .stack_size(1 << 20)
        .spawn(move || state.run())
        .map_err(LiveError::Spawn)?;
    Ok(Live { control, taps, events: ev_rx, stats: st_rx, shared, node_names, base_rate, stop_ticks, thread })
}

#[cfg(test)]
mod tests;
