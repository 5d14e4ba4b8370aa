//! Live metrics, computed off the real-time thread from its per-tick
//! measurements: wake-up jitter and compute time histograms, deadline
//! misses and ring overruns.

use super::histogram::{Histogram, Percentiles};
use super::message::{Shared, TickStat};
use std::fmt;
use std::sync::atomic::Ordering;

/// Accumulates [`TickStat`]s.
#[derive(Debug, Clone, Default)]
pub struct Metrics {
    /// Wake-up lateness per tick.
    pub jitter: Histogram,
    /// Work per tick.
    pub compute: Histogram,
    /// Deadline misses counted from the measurements.
    pub misses: u64,
    /// Longest run of consecutive misses.
    pub longest_streak: u64,
    streak: u64,
}

impl Metrics {
    /// Empty metrics.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counts one tick.
    pub fn absorb(&mut self, s: &TickStat) {
        self.jitter.add(s.jitter_ns);
        self.compute.add(s.compute_ns);
        if s.missed {
            self.misses += 1;
            self.streak += 1;
            self.longest_streak = self.longest_streak.max(self.streak);
        } else {
            self.streak = 0;
        }
    }

    /// Drains a measurement ring in chunks.
    pub fn drain(&mut self, ring: &mut rtrb::Consumer<TickStat>) {
        let n = ring.slots();
        if n == 0 {
            return;
        }
        if let Ok(chunk) = ring.read_chunk(n) {
            let (a, b) = chunk.as_slices();
            for s in a.iter().chain(b) {
                self.absorb(s);
            }
            chunk.commit_all();
        }
    }

    /// A summary with the shared counters.
    pub fn summary(&self, shared: &Shared, base_rate: f64) -> MetricsSummary {
        MetricsSummary {
            ticks: shared.ticks(),
            base_rate,
            jitter: self.jitter.percentiles(),
            compute: self.compute.percentiles(),
            misses: self.misses,
            longest_streak: self.longest_streak,
            tap_overruns: shared.tap_overruns.load(Ordering::Relaxed),
            event_overruns: shared.event_overruns.load(Ordering::Relaxed),
            stat_overruns: shared.stat_overruns.load(Ordering::Relaxed),
            command_overruns: shared.command_overruns.load(Ordering::Relaxed),
        }
    }
}

/// Metrics of a session so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MetricsSummary {
    /// Ticks run.
    pub ticks: u64,
    /// The base rate (ticks per second).
    pub base_rate: f64,
    /// Wake-up jitter, µs.
    pub jitter: Percentiles,
    /// Compute time per tick, µs.
    pub compute: Percentiles,
    /// Deadline misses among the measured ticks.
    pub misses: u64,
    /// Longest streak of consecutive misses.
    pub longest_streak: u64,
    /// Ticks whose tap samples were dropped (ring full).
    pub tap_overruns: u64,
    /// Events dropped (ring full).
    pub event_overruns: u64,
    /// Measurements dropped (ring full); those ticks are missing from the
    /// histograms.
    pub stat_overruns: u64,
    /// Commands refused because their ring was full.
    pub command_overruns: u64,
}

impl MetricsSummary {
    /// One line for a live display.
    pub fn line(&self) -> String {
        format!(
            "{:>8.1} s  jitter p50 {:.0} p99 {:.0} p99.9 {:.0} max {:.0} µs | compute p99.9 {:.0} max {:.0} µs | misses {} | dropped {}",
            self.ticks as f64 / self.base_rate,
            self.jitter.p50,
            self.jitter.p99,
            self.jitter.p999,
            self.jitter.max,
            self.compute.p999,
            self.compute.max,
            self.misses,
            self.tap_overruns + self.event_overruns + self.stat_overruns,
        )
    }
}

impl fmt::Display for MetricsSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} ticks ({:.3} s at {} Hz)", self.ticks, self.ticks as f64 / self.base_rate, self.base_rate)?;
        writeln!(f, "{:<22} {:>9} {:>9} {:>9} {:>9} {:>9}", "µs", "p50", "p99", "p99.9", "max", "mean")?;
        for (name, p) in [("wake-up jitter", self.jitter), ("compute per tick", self.compute)] {
            writeln!(f, "{name:<22} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1}", p.p50, p.p99, p.p999, p.max, p.mean)?;
        }
        writeln!(f, "deadline misses: {} (longest streak {})", self.misses, self.longest_streak)?;
        write!(
            f,
            "ring overruns: taps {} ticks, events {}, measurements {}, commands {}",
            self.tap_overruns, self.event_overruns, self.stat_overruns, self.command_overruns
        )
    }
}
