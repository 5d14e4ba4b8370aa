//! A safety limiter's state as the page shows it — armed, clamping,
//! fading, faded, faulted — taken off the real-time thread from the
//! limiter's own `state` output (`evflow_nodes::safety::limit::State`:
//! one code per sample, so nothing is guessed), window by window:
//!
//! * the state of the window's last sample, except that a window ending
//!   *armed* in which the clamp or the slew limit acted shows *clamping*
//!   (a 50 ms window would otherwise hide brief clamping);
//! * counted over the session: samples clamped or slew-limited (state
//!   *clamping*), faults (entries into *faulted*), and — when what feeds
//!   the limiter is tapped — non-finite inputs.
//!
//! A recorded session made before the limiter had a `state` output has
//! none; its state is then inferred, as the studio did before, from what
//! feeds the limiter, what leaves it and the `enable` changes (marked
//! `"source": "inferred"` for the page):
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
use evflow_nodes::safety::limit::State;
use serde_json::{json, Value};

/// One limiter's tracker.
#[derive(Debug, Clone)]
pub(crate) struct LimiterTrack {
    pub spec: LimiterSpec,
    enabled: bool,
    latched: bool,
    state: State,
    in_peak: f64,
    in_n: u64,
    in_bad: u64,
    out_peak: f64,
    out_n: u64,
    /// `state` samples in this window, the last of them, and whether one
    /// was *clamping*.
    st_n: u64,
    st_last: State,
    st_clamped: bool,
    /// Previous `state` sample (for counting entries into *faulted*).
    st_prev: State,
    clamped: u64,
    non_finite: u64,
    faults: u64,
    /// `state` samples that were no state code (none from a real limiter).
    unknown: u64,
}

impl LimiterTrack {
    pub fn new(spec: LimiterSpec) -> Self {
        let enabled = spec.enabled;
        let state = if enabled { State::Armed } else { State::Faded };
        Self {
            spec,
            enabled,
            latched: false,
            state,
            in_peak: 0.0,
            in_n: 0,
            in_bad: 0,
            out_peak: 0.0,
            out_n: 0,
            st_n: 0,
            st_last: state,
            st_clamped: false,
            st_prev: state,
            clamped: 0,
            non_finite: 0,
            faults: 0,
            unknown: 0,
        }
    }

    /// True when the limiter's `state` output is tapped (or recorded).
    fn reported(&self) -> bool {
        self.spec.state.is_some()
    }

    /// Samples of the limiter's `state` output.
    pub fn states(&mut self, x: &[f64]) {
        for &v in x {
            let Some(s) = State::from_code(v) else {
                self.unknown += 1;
                continue;
            };
            if s == State::Clamping {
                self.clamped += 1;
                self.st_clamped = true;
            }
            if s == State::Faulted && self.st_prev != State::Faulted {
                self.faults += 1;
            }
            self.st_prev = s;
            self.st_last = s;
            self.st_n += 1;
        }
    }

    /// Samples of what feeds `in`.
    pub fn input(&mut self, x: &[f64]) {
        let reported = self.reported();
        for &v in x {
            if v.is_finite() {
                self.in_peak = self.in_peak.max(v.abs());
                if !reported && v.abs() > self.spec.amplitude {
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

    /// The state over the window from the limiter's `state` samples.
    fn reported_state(&self) -> State {
        if self.st_last == State::Armed && self.st_clamped {
            State::Clamping
        } else {
            self.st_last
        }
    }

    /// The state over the window inferred from the signals and `enable`.
    fn inferred_state(&mut self) -> State {
        if !self.enabled {
            return if self.out_n > 0 && self.out_peak == 0.0 { State::Faded } else { State::Fading };
        }
        if self.in_bad > 0 || (self.out_n > 0 && self.out_peak == 0.0 && self.in_peak > 0.0) {
            self.latched = true;
        }
        if self.latched {
            State::Faulted
        } else if self.in_peak > self.spec.amplitude {
            State::Clamping
        } else {
            State::Armed
        }
    }

    /// Closes the window: the state over it, with the session's counts.
    pub fn window(&mut self) -> Value {
        if self.reported() {
            if self.st_n > 0 {
                self.state = self.reported_state();
            }
        } else if self.out_n > 0 || self.in_n > 0 {
            self.state = self.inferred_state();
        }
        let v = json!({
            "node": self.spec.node, "state": self.state.name(), "enable": self.enabled,
            "source": if self.reported() { "node" } else { "inferred" },
            "in_peak": self.in_peak, "out_peak": if self.out_peak.is_finite() { self.out_peak } else { -1.0 },
            "clamped_samples": self.clamped, "non_finite_inputs": self.non_finite, "faults": self.faults,
            "unknown_codes": self.unknown,
            "watching_input": self.spec.input.is_some(),
        });
        self.in_peak = 0.0;
        self.in_n = 0;
        self.in_bad = 0;
        self.out_peak = 0.0;
        self.out_n = 0;
        self.st_n = 0;
        self.st_clamped = false;
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_nodes::safety::limit::{STATE_ARMED, STATE_CLAMPING, STATE_FADED, STATE_FADING, STATE_FAULTED};

    fn spec(state: Option<usize>) -> LimiterSpec {
        LimiterSpec {
            node: "limit".into(),
            index: 0,
            amplitude: 1.0,
            input: Some(0),
            output: Some(1),
            state,
            enabled: true,
        }
    }

    fn state(t: &mut LimiterTrack, input: &[f64], output: &[f64]) -> String {
        t.input(input);
        t.output(output);
        t.window()["state"].as_str().unwrap().to_string()
    }

    fn reported(t: &mut LimiterTrack, codes: &[f64]) -> Value {
        t.states(codes);
        t.window()
    }

    #[test]
    fn the_node_s_state_is_shown_as_reported() {
        let mut t = LimiterTrack::new(spec(Some(2)));
        let w = reported(&mut t, &[STATE_ARMED; 4]);
        assert_eq!((w["state"].as_str(), w["source"].as_str()), (Some("armed"), Some("node")));
        // Brief clamping inside a window that ends armed still shows.
        let w = reported(&mut t, &[STATE_ARMED, STATE_CLAMPING, STATE_CLAMPING, STATE_ARMED]);
        assert_eq!(w["state"], "clamping");
        assert_eq!(w["clamped_samples"], 2);
        assert_eq!(reported(&mut t, &[STATE_ARMED; 3])["state"], "armed");
        // The window's last sample decides otherwise.
        assert_eq!(reported(&mut t, &[STATE_CLAMPING, STATE_FADING])["state"], "fading");
        assert_eq!(reported(&mut t, &[STATE_FADING, STATE_FADED])["state"], "faded");
        let w = reported(&mut t, &[STATE_ARMED, STATE_FAULTED, STATE_FAULTED]);
        assert_eq!((w["state"].as_str(), w["faults"].as_u64()), (Some("faulted"), Some(1)));
        // No samples in a window: the state stays; a fault counts once.
        let w = reported(&mut t, &[]);
        assert_eq!((w["state"].as_str(), w["faults"].as_u64()), (Some("faulted"), Some(1)));
        let w = reported(&mut t, &[STATE_FAULTED, STATE_ARMED, STATE_FAULTED]);
        assert_eq!(w["faults"], 2);
        // Signals say nothing once the node reports: an input over the
        // amplitude is not counted as clamped by the studio (3 clamping
        // samples reported so far).
        assert_eq!(state(&mut t, &[5.0, 5.0], &[0.0, 0.0]), "faulted");
        assert_eq!(t.window()["clamped_samples"], 3);
        // A value that is no state code is counted, not shown.
        let w = reported(&mut t, &[7.5]);
        assert_eq!((w["state"].as_str(), w["unknown_codes"].as_u64()), (Some("faulted"), Some(1)));
    }

    #[test]
    fn without_a_state_stream_states_follow_the_signals_and_enable() {
        let mut t = LimiterTrack::new(spec(None));
        assert_eq!(state(&mut t, &[0.5, -0.9], &[0.5, -0.9]), "armed");
        assert_eq!(t.window()["source"], "inferred");
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
    fn without_a_state_stream_a_gate_closed_on_a_nonzero_input_is_a_latched_fault() {
        let mut t = LimiterTrack::new(spec(None));
        assert_eq!(state(&mut t, &[0.4; 50], &[0.0; 50]), "faulted");
        // Silence in and out says nothing new: still latched.
        assert_eq!(state(&mut t, &[0.0; 50], &[0.0; 50]), "faulted");
        // No samples in a window: the state stays.
        assert_eq!(t.window()["state"], "faulted");
    }

    #[test]
    fn every_code_the_node_writes_has_a_badge_name() {
        for s in State::ALL {
            let mut t = LimiterTrack::new(spec(Some(2)));
            assert_eq!(reported(&mut t, &[s.code()])["state"], s.name());
        }
    }

    #[test]
    fn the_page_styles_every_state() {
        let (css, js) = (include_str!("assets/studio.css"), include_str!("assets/studio.js"));
        for s in State::ALL {
            assert!(css.contains(&format!(".badge.{}", s.name())), "studio.css has no badge for {}", s.name());
            assert!(js.contains(&format!("{}: \"#", s.name())), "studio.js has no timeline colour for {}", s.name());
        }
    }
}
