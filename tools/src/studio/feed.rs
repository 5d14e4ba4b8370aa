//! What the page is sent while a session runs, accumulated between frames
//! off the real-time thread: each tap's samples decimated to min/max pairs
//! (one pair per 5 ms), the events, the tick timings (jitter and compute
//! histograms, misses), the limiters' states.

use super::describe::Description;
use super::limiter::LimiterTrack;
use evflow_engine::live::{Event, EventKind, Metrics, Shared, TickStat};
use serde_json::{json, Value};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

/// Seconds of signal per min/max pair.
pub(crate) const BUCKET_S: f64 = 0.005;

/// Pairs kept per tap between two frames (a frame not taken for this long
/// loses its oldest pairs, counted).
pub(crate) const MAX_PENDING: usize = 4096;

/// Upper edges (µs) of the jitter histogram's bins; the last bin is open.
pub(crate) const JITTER_EDGES_US: [f64; 14] =
    [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0, 20000.0];

/// One tap's decimation.
#[derive(Debug, Clone)]
pub(crate) struct Trace {
    rate: f64,
    per_bucket: u64,
    /// Samples seen.
    seen: u64,
    acc: u64,
    lo: f64,
    hi: f64,
    /// Index (in buckets) of the first pending pair.
    first: u64,
    pending: Vec<(f64, f64)>,
    lost: u64,
    non_finite: u64,
    last: f64,
}

impl Trace {
    fn new(rate: f64) -> Self {
        Self::with_bucket(rate, BUCKET_S)
    }

    /// Min/max pairs of about `bucket_s` seconds each.
    pub(crate) fn with_bucket(rate: f64, bucket_s: f64) -> Self {
        let per_bucket = ((rate * bucket_s).round() as u64).max(1);
        Self {
            rate,
            per_bucket,
            seen: 0,
            acc: 0,
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
            first: 0,
            pending: Vec::new(),
            lost: 0,
            non_finite: 0,
            last: 0.0,
        }
    }

    pub(crate) fn push(&mut self, x: &[f64]) {
        for &v in x {
            if v.is_finite() {
                self.lo = self.lo.min(v);
                self.hi = self.hi.max(v);
                self.last = v;
            } else {
                self.non_finite += 1;
            }
            self.acc += 1;
            self.seen += 1;
            if self.acc == self.per_bucket {
                let pair = if self.lo <= self.hi { (self.lo, self.hi) } else { (f64::NAN, f64::NAN) };
                if self.pending.len() == MAX_PENDING {
                    self.pending.remove(0);
                    self.first += 1;
                    self.lost += 1;
                }
                self.pending.push(pair);
                self.acc = 0;
                self.lo = f64::INFINITY;
                self.hi = f64::NEG_INFINITY;
            }
        }
    }

    /// The pending pairs as JSON (times in seconds), emptied.
    pub(crate) fn take(&mut self, i: usize) -> Option<Value> {
        if self.pending.is_empty() {
            return None;
        }
        let dt = self.per_bucket as f64 / self.rate;
        let lo: Vec<Value> = self.pending.iter().map(|p| num(p.0)).collect();
        let hi: Vec<Value> = self.pending.iter().map(|p| num(p.1)).collect();
        let v = json!({ "i": i, "t0": self.first as f64 * dt, "dt": dt, "lo": lo, "hi": hi, "last": num(self.last) });
        self.first += self.pending.len() as u64;
        self.pending.clear();
        Some(v)
    }
}

/// A finite number rounded to 6 significant digits (smaller frames), or null.
fn num(x: f64) -> Value {
    if x.is_finite() {
        let r: f64 = format!("{x:.5e}").parse().unwrap_or(x);
        json!(r)
    } else {
        Value::Null
    }
}

/// Everything accumulated for the next frame.
pub(crate) struct FeedState {
    traces: Vec<Trace>,
    limiters: Vec<LimiterTrack>,
    names: Vec<String>,
    base_rate: f64,
    metrics: Metrics,
    jitter_bins: [u64; JITTER_EDGES_US.len() + 1],
    window_compute_max: u64,
    window_jitter_max: u64,
    window_misses: u64,
    last_tick: u64,
    events: Vec<Value>,
    /// The value each parameter last took (`node.param`), sent in every
    /// frame: a browser that joins after a change shows it.
    values: std::collections::BTreeMap<String, f64>,
    steal_s: Option<f64>,
    shared: Option<Arc<Shared>>,
}

impl FeedState {
    pub fn new(d: &Description, shared: Option<Arc<Shared>>) -> Self {
        Self {
            traces: d.taps.iter().map(|t| Trace::new(t.rate)).collect(),
            limiters: d.limiters.iter().cloned().map(LimiterTrack::new).collect(),
            names: d.names.clone(),
            base_rate: d.base_rate,
            metrics: Metrics::new(),
            jitter_bins: [0; JITTER_EDGES_US.len() + 1],
            window_compute_max: 0,
            window_jitter_max: 0,
            window_misses: 0,
            last_tick: 0,
            events: Vec::new(),
            values: std::collections::BTreeMap::new(),
            steal_s: None,
            shared,
        }
    }

    fn samples(&mut self, tap: usize, x: &[f64]) {
        if let Some(t) = self.traces.get_mut(tap) {
            t.push(x);
        }
        for l in &mut self.limiters {
            if l.spec.input == Some(tap) {
                l.input(x);
            }
            if l.spec.output == Some(tap) {
                l.output(x);
            }
            if l.spec.state == Some(tap) {
                l.states(x);
            }
        }
    }

    fn event(&mut self, e: &Event) {
        let name = |k: u32| self.names.get(k as usize).cloned().unwrap_or_else(|| format!("#{k}"));
        let t = e.tick as f64 / self.base_rate;
        let v = match e.kind {
            EventKind::Set { node, param, value } => {
                if param == "enable" {
                    for l in self.limiters.iter_mut().filter(|l| l.spec.index == node) {
                        l.set_enable(value != 0.0);
                    }
                }
                self.values.insert(format!("{}.{param}", name(node)), value);
                json!({ "tick": e.tick, "t": t, "event": "set", "node": name(node), "param": param, "value": value })
            }
            EventKind::Refused { node, param, value } => {
                json!({ "tick": e.tick, "t": t, "event": "refused", "node": name(node), "param": param, "value": value })
            }
            EventKind::Stop(why) => json!({ "tick": e.tick, "t": t, "event": "stop", "reason": why.as_str() }),
            EventKind::Gap { ticks } => json!({ "tick": e.tick, "t": t, "event": "gap", "ticks": ticks }),
            EventKind::Replaced => json!({ "tick": e.tick, "t": t, "event": "replaced" }),
        };
        if self.events.len() < 1000 {
            self.events.push(v);
        }
    }

    fn stats(&mut self, s: &[TickStat]) {
        for st in s {
            self.metrics.absorb(st);
            let us = st.jitter_ns as f64 / 1e3;
            let bin = JITTER_EDGES_US.iter().position(|&e| us < e).unwrap_or(JITTER_EDGES_US.len());
            self.jitter_bins[bin] += 1;
            self.window_compute_max = self.window_compute_max.max(st.compute_ns);
            self.window_jitter_max = self.window_jitter_max.max(st.jitter_ns);
            self.window_misses += u64::from(st.missed);
            self.last_tick = st.tick;
        }
    }

    /// The frame of everything since the last one; `drops` are the frames
    /// the browsers lost so far.
    pub fn frame(&mut self, drops: u64, clients: usize) -> Value {
        let taps: Vec<Value> = self.traces.iter_mut().enumerate().filter_map(|(i, t)| t.take(i)).collect();
        let limiters: Vec<Value> = self.limiters.iter_mut().map(LimiterTrack::window).collect();
        let p = |p: evflow_engine::live::Percentiles| json!({ "p50": p.p50, "p99": p.p99, "p99_9": p.p999, "max": p.max, "mean": p.mean, "n": p.n });
        let (ticks, overruns) = match &self.shared {
            Some(s) => (
                s.ticks(),
                json!({
                    "taps": s.tap_overruns.load(Ordering::Relaxed),
                    "events": s.event_overruns.load(Ordering::Relaxed),
                    "measurements": s.stat_overruns.load(Ordering::Relaxed),
                    "commands": s.command_overruns.load(Ordering::Relaxed),
                }),
            ),
            None => (self.last_tick, json!({})),
        };
        let lost: u64 = self.traces.iter().map(|t| t.lost).sum();
        let v = json!({
            "type": "frame",
            "tick": ticks,
            "t": ticks as f64 / self.base_rate,
            "taps": taps,
            "limiters": limiters,
            "events": std::mem::take(&mut self.events),
            "values": self.values,
            "timing": {
                "jitter_us": p(self.metrics.jitter.percentiles()),
                "compute_us": p(self.metrics.compute.percentiles()),
                "misses": self.metrics.misses,
                "longest_miss_streak": self.metrics.longest_streak,
                "window": {
                    "compute_max_us": self.window_compute_max as f64 / 1e3,
                    "jitter_max_us": self.window_jitter_max as f64 / 1e3,
                    "misses": self.window_misses,
                },
                "jitter_hist": { "edges_us": JITTER_EDGES_US, "counts": self.jitter_bins },
                "overruns": overruns,
                "host_steal_ms": self.steal_s.map(|s| s * 1e3),
            },
            "studio": { "frames_dropped": drops, "browsers": clients, "pairs_lost": lost },
        });
        self.window_compute_max = 0;
        self.window_jitter_max = 0;
        self.window_misses = 0;
        v
    }
}

/// The studio's intake: the session's non-real-time threads hand it what
/// they drained (the recorder: tap samples and events; the metrics
/// thread: tick timings and host steal). Cheap and never blocking for
/// long: it decimates under a lock only the studio's feeder shares.
#[derive(Clone)]
pub struct Ingest {
    pub(crate) feed: Arc<Mutex<FeedState>>,
}

impl Ingest {
    fn with(&self, f: impl FnOnce(&mut FeedState)) {
        f(&mut self.feed.lock().unwrap_or_else(|e| e.into_inner()));
    }
    /// Samples of tap `tap` (in the session's tap order), oldest first.
    pub fn samples(&self, tap: usize, x: &[f64]) {
        if !x.is_empty() {
            self.with(|f| f.samples(tap, x));
        }
    }
    /// An event of the real-time thread.
    pub fn event(&self, e: &Event) {
        self.with(|f| f.event(e));
    }
    /// Tick timings.
    pub fn stats(&self, s: &[TickStat]) {
        if !s.is_empty() {
            self.with(|f| f.stats(s));
        }
    }
    /// CPU time the host took from this machine since the session began.
    pub fn steal(&self, seconds: Option<f64>) {
        self.with(|f| f.steal_s = seconds);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_extremes_and_times() {
        let mut t = Trace::new(1000.0);
        assert_eq!(t.per_bucket, 5);
        let x: Vec<f64> = (0..12).map(|i| if i == 3 { 9.0 } else { i as f64 * 0.1 }).collect();
        t.push(&x);
        let v = t.take(2).unwrap();
        assert_eq!(v["i"], 2);
        assert_eq!(v["lo"], json!([0.0, 0.5]));
        assert_eq!(v["hi"], json!([9.0, 0.9]));
        assert_eq!(v["t0"], 0.0);
        // The next pairs continue the time axis where the last ended.
        t.push(&[f64::NAN, 0.0, 0.0]);
        let v = t.take(2).unwrap();
        assert_eq!(v["t0"], 0.01);
        assert_eq!(v["lo"], json!([0.0]), "NaN is not an extreme: {v}");
        assert_eq!(t.non_finite, 1);
        assert!(t.take(2).is_none());
        // A slow rate keeps every sample.
        let mut s = Trace::new(40.0);
        s.push(&[1.0, 2.0]);
        assert_eq!(s.take(0).unwrap()["hi"], json!([1.0, 2.0]));
    }

    #[test]
    fn an_untaken_trace_stays_bounded() {
        let mut t = Trace::new(1000.0);
        t.push(&vec![1.0; 5 * (MAX_PENDING + 10)]);
        assert_eq!(t.pending.len(), MAX_PENDING);
        assert_eq!(t.lost, 10);
        assert_eq!(t.take(0).unwrap()["t0"], 10.0 * 0.005);
    }
}
