//! What travels between the real-time thread and the others: commands in
//! (one ordered queue stamped with tick indices), events and per-tick
//! measurements out. All are `Copy`, so the rings never allocate.

use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

/// A parameter change for the real-time thread, applied before the step of
/// tick `at` (or of the first tick after it, if it arrives late). Commands
/// apply in queue order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// The earliest tick it applies at.
    pub at: u64,
    /// The node's index in the plan.
    pub node: u32,
    /// The parameter's declared name.
    pub param: &'static str,
    /// The value, already checked against the declaration.
    pub value: f64,
}

/// Why a session stopped (or is stopping).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum StopReason {
    /// Asked to stop (Ctrl-C, `stop` typed, the caller).
    Requested = 1,
    /// The session's duration elapsed.
    Duration = 2,
    /// A finite source is about to end.
    SourcesEnded = 3,
    /// Too many deadline misses in a row.
    DeadlineMisses = 4,
    /// A device reported a disconnect (I/O threads).
    Disconnect = 5,
}

impl StopReason {
    /// The reason for a code stored in [`Shared::stop`].
    pub fn from_code(c: u8) -> Option<Self> {
        Some(match c {
            1 => Self::Requested,
            2 => Self::Duration,
            3 => Self::SourcesEnded,
            4 => Self::DeadlineMisses,
            5 => Self::Disconnect,
            _ => return None,
        })
    }
    /// A word for logs and files.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Requested => "requested",
            Self::Duration => "duration",
            Self::SourcesEnded => "sources ended",
            Self::DeadlineMisses => "deadline misses",
            Self::Disconnect => "disconnect",
        }
    }
    /// True for stops caused by a fault rather than the session's plan.
    pub fn is_fault(&self) -> bool {
        matches!(self, Self::DeadlineMisses | Self::Disconnect)
    }
}

/// Something the real-time thread did at a tick (for the session log).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EventKind {
    /// A parameter change applied before the step of this tick.
    Set {
        /// Node index in the plan.
        node: u32,
        /// Parameter name.
        param: &'static str,
        /// Value.
        value: f64,
    },
    /// A parameter change the node refused (nothing changed).
    Refused {
        /// Node index in the plan.
        node: u32,
        /// Parameter name.
        param: &'static str,
        /// Value.
        value: f64,
    },
    /// The stop sequence began: every safety guard was disabled at this
    /// tick (their `Set` events follow) and the session ends once they
    /// have faded out.
    Stop(StopReason),
    /// Taps were not written for `ticks` ticks from this one (their rings
    /// were full: a slow consumer); the samples are lost and counted.
    Gap {
        /// Ticks lost.
        ticks: u64,
    },
    /// A replacement plan took over at this tick (its own t = 0).
    Replaced,
}

/// An event stamped with the session tick it happened at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Session tick (ticks since the session started).
    pub tick: u64,
    /// What happened.
    pub kind: EventKind,
}

/// Timing of one tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TickStat {
    /// Session tick.
    pub tick: u64,
    /// Wake-up lateness: from the tick's deadline to the moment the thread
    /// ran (ns).
    pub jitter_ns: u64,
    /// From waking to the end of the tick's work (commands, step, taps), ns.
    pub compute_ns: u64,
    /// The work ended after the next tick's deadline.
    pub missed: bool,
}

/// Counters and flags shared with the real-time thread (atomics only).
#[derive(Debug, Default)]
pub struct Shared {
    /// A stop request: 0 = none, else a [`StopReason`] code.
    pub stop: AtomicU8,
    /// Ticks run so far.
    pub tick: AtomicU64,
    /// Deadline misses so far.
    pub misses: AtomicU64,
    /// Ticks whose tap samples were dropped because a ring was full.
    pub tap_overruns: AtomicU64,
    /// Events dropped because the event ring was full.
    pub event_overruns: AtomicU64,
    /// Tick measurements dropped because the measurement ring was full.
    pub stat_overruns: AtomicU64,
    /// Commands refused because the command ring was full (control side).
    pub command_overruns: AtomicU64,
}

impl Shared {
    /// Asks the real-time thread to begin its stop sequence (the first
    /// request wins).
    pub fn request_stop(&self, why: StopReason) {
        let _ = self.stop.compare_exchange(0, why as u8, Ordering::SeqCst, Ordering::SeqCst);
    }
    /// The pending stop request.
    pub fn stop_requested(&self) -> Option<StopReason> {
        StopReason::from_code(self.stop.load(Ordering::Relaxed))
    }
    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.tick.load(Ordering::Relaxed)
    }
}
