//! A recorded session for the page (`evflow studio SESSION`): every
//! recording decimated over the whole session (at most ~4000 min/max pairs
//! per stream, so hours stay light), the events on the time axis, the
//! limiters' states over time, the session's timing figures, and —
//! published when it is known — the replay check.

use super::describe::{graph_json, limiter_specs, taps_json};
use super::feed::{Trace, BUCKET_S, MAX_PENDING};
use super::limiter::LimiterTrack;
use super::server::{Studio, StudioConfig, StudioError};
use evflow_engine::Checked;
use serde_json::{json, Value};

/// One recorded stream.
#[derive(Debug, Clone)]
pub struct RecordedTap {
    /// Node name.
    pub node: String,
    /// Output port.
    pub port: String,
    /// Sample rate, Hz.
    pub rate: f64,
    /// Every sample.
    pub samples: Vec<f64>,
}

/// What a session folder holds, read by the CLI.
#[derive(Debug, Clone)]
pub struct RecordedSession {
    /// The graph's name.
    pub name: String,
    /// Base rate, Hz.
    pub base_rate: f64,
    /// Ticks run (0 if the session did not end cleanly).
    pub ticks: u64,
    /// Why it stopped (or its status, if it did not end).
    pub stopped: String,
    /// Its recordings: inputs then outputs.
    pub taps: Vec<RecordedTap>,
    /// `events.jsonl`, one object per event (with `tick`).
    pub events: Vec<Value>,
    /// The session's `end.metrics` (null if it did not end).
    pub metrics: Value,
    /// Host steal over the session, seconds.
    pub steal_s: Option<f64>,
    /// The graph as recorded, if it still loads.
    pub checked: Option<Checked>,
    /// The finger view's background ([`super::scene_json`]), or null.
    pub scene: Value,
    /// What the page must warn about (recordings cut short, a graph that
    /// no longer loads).
    pub notes: Vec<String>,
}

/// Window of the limiter's state timeline, seconds.
const STATE_WINDOW_S: f64 = 0.05;

impl RecordedSession {
    fn seconds(&self) -> f64 {
        let longest = self.taps.iter().map(|t| t.samples.len() as f64 / t.rate).fold(0.0, f64::max);
        if self.ticks > 0 {
            self.ticks as f64 / self.base_rate
        } else {
            longest
        }
    }

    fn tap_of(&self, node: &str, port: &str) -> Option<usize> {
        self.taps.iter().position(|t| t.node == node && t.port == port)
    }

    /// The limiters' states over the session: segments `{t0, t1, state}`
    /// and the last window's details, per limiter.
    fn limiter_timelines(&self) -> (Vec<Value>, Vec<Value>) {
        let Some(checked) = &self.checked else { return (Vec::new(), Vec::new()) };
        let specs = limiter_specs(checked, &|n, p| self.tap_of(n, p), &|n| checked.index(n));
        let mut hello = Vec::new();
        let mut lines = Vec::new();
        for spec in specs {
            hello.push(json!({ "node": spec.node, "amplitude": spec.amplitude }));
            let mut enables: Vec<(f64, bool)> = self
                .events
                .iter()
                .filter(|e| e["event"] == "set" && e["node"] == spec.node.as_str() && e["param"] == "enable")
                .filter_map(|e| Some((e["tick"].as_f64()? / self.base_rate, e["value"].as_f64()? != 0.0)))
                .collect();
            enables.reverse();
            let mut track = LimiterTrack::new(spec.clone());
            let mut segs: Vec<Value> = Vec::new();
            let mut last = Value::Null;
            let total = self.seconds();
            let mut t = 0.0;
            while t < total {
                let t1 = (t + STATE_WINDOW_S).min(total);
                while enables.last().is_some_and(|(te, _)| *te < t1) {
                    let (_, on) = enables.pop().unwrap_or((0.0, true));
                    track.set_enable(on);
                }
                let slice = |i: Option<usize>| {
                    i.map(|i| {
                        let tap = &self.taps[i];
                        let a = ((t * tap.rate).round() as usize).min(tap.samples.len());
                        let b = ((t1 * tap.rate).round() as usize).min(tap.samples.len());
                        &tap.samples[a..b]
                    })
                    .unwrap_or(&[])
                };
                track.input(slice(spec.input));
                track.output(slice(spec.output));
                track.states(slice(spec.state));
                last = track.window();
                let state = last["state"].clone();
                match segs.last_mut() {
                    Some(s) if s["state"] == state => s["t1"] = json!(t1),
                    _ => segs.push(json!({ "t0": t, "t1": t1, "state": state })),
                }
                t = t1;
            }
            // The panel shows the peaks over the whole session: its last
            // window alone is the fade-out at the end.
            let peak = |i: Option<usize>| {
                i.map(|i| self.taps[i].samples.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs())))
            };
            if last.is_object() {
                last["session"] = json!({ "in_peak": peak(spec.input), "out_peak": peak(spec.output) });
            }
            lines.push(json!({ "node": spec.node, "segments": segs, "last": last }));
        }
        (hello, lines)
    }

    /// The `hello` and the one `frame` that carries the whole session.
    pub(crate) fn messages(&self) -> (String, String) {
        let seconds = self.seconds();
        let bucket = BUCKET_S.max(seconds / (MAX_PENDING as f64 * 0.95));
        let list: Vec<(String, String, f64)> =
            self.taps.iter().map(|t| (t.node.clone(), t.port.clone(), t.rate)).collect();
        let specs = self
            .checked
            .as_ref()
            .map(|c| limiter_specs(c, &|n, p| self.tap_of(n, p), &|n| c.index(n)))
            .unwrap_or_default();
        let graph = match &self.checked {
            Some(c) => graph_json(c, self.base_rate, &|n| c.order.iter().any(|&k| c.nodes[k].name == n)),
            None => {
                json!({ "name": self.name, "description": "(the recorded graph no longer loads)", "base_rate": self.base_rate, "nodes": [], "edges": [], "pruned": [] })
            }
        };
        let (limiters, timelines) = self.limiter_timelines();
        let hello = json!({
            "type": "hello",
            "mode": "recorded",
            "graph": graph,
            "taps": taps_json(self.checked.as_ref(), &list, &specs),
            "params": [],
            "vars": [],
            "limiters": limiters,
            "scene": self.scene,
            "recording": {
                "seconds": seconds, "ticks": self.ticks, "stopped": self.stopped, "bucket_s": bucket,
                "replay": { "ok": null, "summary": "running `evflow replay --check`…" },
                "notes": self.notes,
            },
        });
        let taps: Vec<Value> = self
            .taps
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let mut tr = Trace::with_bucket(t.rate, bucket);
                tr.push(&t.samples);
                tr.take(i)
            })
            .collect();
        let events: Vec<Value> = self
            .events
            .iter()
            .map(|e| {
                let mut e = e.clone();
                e["t"] = json!(e["tick"].as_f64().unwrap_or(0.0) / self.base_rate);
                e
            })
            .collect();
        let m = &self.metrics;
        let timing = if m.is_null() {
            Value::Null
        } else {
            json!({
                "jitter_us": m["jitter_us"], "compute_us": m["compute_us"],
                "misses": m["deadline_misses"], "longest_miss_streak": m["longest_miss_streak"],
                "overruns": { "taps": m["tap_overruns"], "events": m["event_overruns"], "measurements": m["stat_overruns"], "commands": m["command_overruns"] },
                "host_steal_ms": self.steal_s.map(|s| s * 1e3),
            })
        };
        let frame = json!({
            "type": "frame", "t": seconds, "tick": self.ticks, "taps": taps, "events": events,
            "limiters": timelines.iter().map(|l| l["last"].clone()).filter(|l| !l.is_null()).collect::<Vec<_>>(),
            "limiter_timelines": timelines, "timing": timing,
        });
        (hello.to_string(), frame.to_string())
    }
}

/// Serves `session`'s page.
pub fn serve_recorded(cfg: &StudioConfig, session: &RecordedSession) -> Result<Studio, StudioError> {
    let (hello, frame) = session.messages();
    Studio::serve(cfg, hello, vec![frame], None)
}

/// Tells the page the replay check's result.
pub fn publish_replay(studio: &Studio, ok: bool, summary: &str) {
    studio.publish(json!({ "type": "replay", "ok": ok, "summary": summary }).to_string());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_session_stays_within_the_pairs_per_stream() {
        let s = RecordedSession {
            name: "g".into(),
            base_rate: 1000.0,
            ticks: 3_600_000,
            stopped: "duration".into(),
            taps: vec![RecordedTap {
                node: "a".into(),
                port: "out".into(),
                rate: 1000.0,
                samples: vec![0.5; 3_600_000],
            }],
            events: vec![json!({ "tick": 1000, "event": "set", "node": "a", "param": "x", "value": 1.0 })],
            metrics: Value::Null,
            steal_s: None,
            checked: None,
            scene: Value::Null,
            notes: vec!["outputs/a.out: cut short".into()],
        };
        let (hello, frame) = s.messages();
        let h: Value = serde_json::from_str(&hello).unwrap();
        assert_eq!(h["mode"], "recorded");
        assert_eq!(h["recording"]["seconds"], 3600.0);
        assert_eq!(h["recording"]["notes"][0], "outputs/a.out: cut short");
        let f: Value = serde_json::from_str(&frame).unwrap();
        let n = f["taps"][0]["lo"].as_array().unwrap().len();
        assert!(n <= MAX_PENDING && n > 3000, "{n} pairs for an hour");
        assert_eq!(f["events"][0]["t"], 1.0);
    }

    /// A recorded `sine → limit` session of 0.3 s whose limiter faded out
    /// at 0.1 s; `state` recorded or not.
    fn faded_session(with_state: bool) -> RecordedSession {
        let doc = "[graph]\nformat = 1\nname = \"r\"\nrate = 1000.0\nconnections = [\"s.out -> limit.in\", \"limit.out -> st.in\"]\n\
                   [nodes.s]\ntype = \"sine\"\n[nodes.limit]\ntype = \"limit\"\n[nodes.st]\ntype = \"stats\"\n";
        let g = evflow_engine::graph::parse_graph(std::path::Path::new("r.toml"), doc).unwrap();
        let checked = evflow_engine::check(&g, &evflow_nodes::registry(), &[]).unwrap();
        use evflow_nodes::safety::limit::State;
        // The output is made up so that it contradicts the state: the
        // strip must follow the node's report, not the signal.
        let state: Vec<f64> = (0..300)
            .map(|i| {
                if i < 100 {
                    State::Armed
                } else if i < 109 {
                    State::Fading
                } else {
                    State::Faded
                }
                .code()
            })
            .collect();
        let mut taps =
            vec![RecordedTap { node: "limit".into(), port: "out".into(), rate: 1000.0, samples: vec![0.5; 300] }];
        if with_state {
            taps.push(RecordedTap { node: "limit".into(), port: "state".into(), rate: 1000.0, samples: state });
        }
        RecordedSession {
            name: "r".into(),
            base_rate: 1000.0,
            ticks: 300,
            stopped: "duration".into(),
            taps,
            events: vec![json!({ "tick": 100, "event": "set", "node": "limit", "param": "enable", "value": 0.0 })],
            metrics: Value::Null,
            steal_s: None,
            checked: Some(checked),
            scene: Value::Null,
            notes: Vec::new(),
        }
    }

    fn strip(s: &RecordedSession) -> (Vec<String>, Value) {
        let (_, frame) = s.messages();
        let f: Value = serde_json::from_str(&frame).unwrap();
        let l = &f["limiter_timelines"][0];
        let states =
            l["segments"].as_array().unwrap().iter().map(|x| x["state"].as_str().unwrap().to_string()).collect();
        (states, l["last"].clone())
    }

    #[test]
    fn the_limiter_panel_gets_the_peaks_of_the_whole_session() {
        let mut s = faded_session(true);
        s.taps[0].samples[40] = -0.66;
        let (_, last) = strip(&s);
        assert_eq!(last["out_peak"], 0.5, "the last window");
        assert_eq!(last["session"]["out_peak"], 0.66);
        assert_eq!(last["session"]["in_peak"], Value::Null, "the input is not recorded");
    }

    #[test]
    fn a_recorded_state_drives_the_strip() {
        let (states, last) = strip(&faded_session(true));
        assert_eq!(states, ["armed", "faded"], "the 100..150 ms window ends faded");
        assert_eq!(last["source"], "node");
        // Without `limit.state`: inferred from the output (never zero here)
        // and the disable — fading to the end.
        let (states, last) = strip(&faded_session(false));
        assert_eq!(states, ["armed", "fading"]);
        assert_eq!(last["source"], "inferred");
    }
}
