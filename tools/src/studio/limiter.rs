//! A safety limiter's state as the page shows it — armed, clamping,
//! faulted (latched), fading, faded — inferred off the real-time thread
//! from what feeds the limiter, what leaves it, and its `enable` changes:
//!
//! * `enable` false: *fading* while the output is still nonzero, *faded*
//!   once it is exactly zero;
//! * `enable` true: *faulted* after a non-finite input, or when the output
//!   stays exactly zero over a whole window although the input is not —
//!   the gate latched on a fault; it stays faulted until `enable` is set
//!   true again (re-armed), as the node does;
//! * otherwise *clamping* when |in| exceeded `amplitude` in the window,
//!   else *armed*.

use super::describe::LimiterSpec;
use serde_json::{json, Value};

/// One limiter's tracker.
#[derive(Debug, Clone)]
pub(crate) struct LimiterTrack {
    pub spec: LimiterSpec,
    enabled: bool,
    latched: bool,
    state: &'static str,
    in_peak: f64,
    in_n: u64,
    in_bad: u64,
    out_peak: f64,
    out_n: u64,
    clamped: u64,
    non_finite: u64,
}

impl LimiterTrack {
    pub fn new(spec: LimiterSpec) -> Self {
        let enabled = spec.enabled;
        Self {
            spec,
            enabled,
            latched: false,
            state: if enabled { "armed" } else { "faded" },
            in_peak: 0.0,
            in_n: 0,
            in_bad: 0,
            out_peak: 0.0,
            out_n: 0,
            clamped: 0,
            non_finite: 0,
        }
    }

    /// Samples of what feeds `in`.
    pub fn input(&mut self, x: &[f64]) {
        for &v in x {
            if v.is_finite() {
                self.in_peak = self.in_peak.max(v.abs());
                if v.abs() > self.spec.amplitude {
                    self.clamped += 1;
                }
            } else {
                self.in_bad += 1;
                self.non_finite += 1;
            }
        }
        self.in_n += x.len() as u64;
    }

    /// Samples of `out`.
    pub fn output(&mut self, x: &[f64]) {
        for &v in x {
            self.out_peak = self.out_peak.max(if v.is_finite() { v.abs() } else { f64::INFINITY });
        }
        self.out_n += x.len() as u64;
    }

    /// `enable` changed (an applied parameter change); true re-arms.
    pub fn set_enable(&mut self, on: bool) {
        self.enabled = on;
        if on {
            self.latched = false;
        }
    }

    /// Closes the window: the state over it, with the session's counts.
    pub fn window(&mut self) -> Value {
        if self.out_n > 0 || self.in_n > 0 {
            self.state = if !self.enabled {
                if self.out_n > 0 && self.out_peak == 0.0 {
                    "faded"
                } else {
                    "fading"
                }
            } else {
                if self.in_bad > 0 || (self.out_n > 0 && self.out_peak == 0.0 && self.in_peak > 0.0) {
                    self.latched = true;
                }
                if self.latched {
                    "faulted"
                } else if self.in_peak > self.spec.amplitude {
                    "clamping"
                } else {
                    "armed"
                }
            };
        }
        let v = json!({
            "node": self.spec.node, "state": self.state, "enable": self.enabled,
            "in_peak": self.in_peak, "out_peak": if self.out_peak.is_finite() { self.out_peak } else { -1.0 },
            "clamped_samples": self.clamped, "non_finite_inputs": self.non_finite,
            "watching_input": self.spec.input.is_some(),
        });
        self.in_peak = 0.0;
        self.in_n = 0;
        self.in_bad = 0;
        self.out_peak = 0.0;
        self.out_n = 0;
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track() -> LimiterTrack {
        LimiterTrack::new(LimiterSpec {
            node: "limit".into(),
            index: 0,
            amplitude: 1.0,
            input: Some(0),
            output: Some(1),
            enabled: true,
        })
    }

    fn state(t: &mut LimiterTrack, input: &[f64], output: &[f64]) -> String {
        t.input(input);
        t.output(output);
        t.window()["state"].as_str().unwrap().to_string()
    }

    #[test]
    fn states_follow_the_signals_and_enable() {
        let mut t = track();
        assert_eq!(state(&mut t, &[0.5, -0.9], &[0.5, -0.9]), "armed");
        assert_eq!(state(&mut t, &[0.5, -1.5], &[0.5, -1.0]), "clamping");
        assert_eq!(t.window()["clamped_samples"], 1);
        // A NaN input latches: faulted even once the input is fine again.
        assert_eq!(state(&mut t, &[0.2, f64::NAN], &[0.2, 0.1]), "faulted");
        assert_eq!(state(&mut t, &[0.2, 0.3], &[0.0, 0.0]), "faulted");
        // Re-armed.
        t.set_enable(true);
        assert_eq!(state(&mut t, &[0.2, 0.3], &[0.1, 0.3]), "armed");
        // Disabled: fading until the output is exactly zero.
        t.set_enable(false);
        assert_eq!(state(&mut t, &[0.2, 0.3], &[0.1, 0.05]), "fading");
        assert_eq!(state(&mut t, &[0.2, 0.3], &[0.0, 0.0]), "faded");
    }

    #[test]
    fn a_gate_closed_on_a_nonzero_input_is_a_latched_fault() {
        let mut t = track();
        assert_eq!(state(&mut t, &[0.4; 50], &[0.0; 50]), "faulted");
        // Silence in and out says nothing new: still latched.
        assert_eq!(state(&mut t, &[0.0; 50], &[0.0; 50]), "faulted");
        // No samples in a window: the state stays.
        assert_eq!(t.window()["state"], "faulted");
    }
}
