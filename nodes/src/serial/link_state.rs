//! What a serial link's I/O thread and its nodes share: the port's
//! settings, the rings' capacities, the link state (atomics) and the
//! report of counters and events. `link.rs` owns the link and its thread,
//! `io.rs` runs the thread; both read these.

use super::host::HostCounters;
use std::sync::atomic::{AtomicBool, AtomicU16, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// Capacity of the touch ring (frames).
pub const TOUCH_RING: usize = 64;
/// Capacity of the force ring (samples: 4 s at 1 kHz).
pub const FORCE_RING: usize = 4096;
/// Capacity of the actuation ring (samples: 1 s at 1 kHz).
pub const ACTUATION_RING: usize = 1024;

/// Port settings; the nodes sharing a port must agree on them.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkConfig {
    /// Device path (e.g. `/dev/ttyACM0`, a pty, `COM3`).
    pub port: String,
    /// Baud rate (ignored by USB CDC devices and ptys).
    pub baud: u32,
    /// How long building the node waits for the device's HELLO.
    pub wait: Duration,
    /// No valid frame for this long: the link is down.
    pub timeout: Duration,
    /// Reopen interval after the link was lost.
    pub retry: Duration,
}

/// Counters and events of a link, kept by its I/O thread for the nodes'
/// summaries (locked only by that thread and by `finish`, never on the
/// real-time thread).
#[derive(Debug, Clone, Default)]
pub struct LinkReport {
    /// Protocol counters.
    pub counters: HostCounters,
    /// Touch frames dropped because the touch ring was full.
    pub touch_overruns: u64,
    /// Force samples dropped because the force ring was full.
    pub force_overruns: u64,
    /// Actuation samples dropped in the I/O thread because too many had
    /// queued up (after a stall of the thread): only the newest are sent.
    pub stale_dropped: u64,
    /// Write backlog dropped because the port did not take it.
    pub write_overflows: u64,
    /// Times the link came up.
    pub connects: u64,
    /// Times the link went down after being up.
    pub disconnects: u64,
    /// What happened, in order (the first [`EVENTS_KEPT`]).
    pub events: Vec<String>,
    /// Events beyond those kept.
    pub events_dropped: u64,
    /// The last failure to open the port or to hear the device.
    pub last_error: Option<String>,
}

/// Events kept in a [`LinkReport`].
pub const EVENTS_KEPT: usize = 32;

impl LinkReport {
    /// Records an event.
    pub fn event(&mut self, e: String) {
        if self.events.len() < EVENTS_KEPT {
            self.events.push(e);
        } else {
            self.events_dropped += 1;
        }
    }
}

/// What the I/O thread and the nodes share.
#[derive(Debug, Default)]
pub struct LinkState {
    /// The link is up (handshake done, frames arriving).
    pub connected: AtomicBool,
    /// The device's fault bits.
    pub faults: AtomicU16,
    /// Samples `serial.in` has produced (stamps events).
    pub in_samples: AtomicU64,
    /// Samples `serial.out` has taken.
    pub out_samples: AtomicU64,
    /// A `serial.in` reads the inbound rings.
    pub has_reader: AtomicBool,
    /// The actuation rate of the `serial.out` on this link, Hz (0: none).
    pub actuation_hz: AtomicU16,
    /// Asks the I/O thread to end.
    pub stop: AtomicBool,
    /// Counters and events.
    pub report: Mutex<LinkReport>,
}

impl LinkState {
    /// A copy of the report.
    pub fn report(&self) -> LinkReport {
        self.report.lock().map(|r| r.clone()).unwrap_or_default()
    }
    /// The sample index events are stamped with: `serial.in`'s, else `serial.out`'s.
    pub fn sample(&self) -> u64 {
        if self.has_reader.load(Ordering::Relaxed) {
            self.in_samples.load(Ordering::Relaxed)
        } else {
            self.out_samples.load(Ordering::Relaxed)
        }
    }
}
