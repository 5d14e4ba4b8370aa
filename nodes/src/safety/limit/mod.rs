//! `limit`: the safety limiter in front of every hardware output.

use super::envelope::Envelope;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Flag, Float, Words};
use evflow_engine::{BuildContext, Change, Io, Node, NodeError, NodeSpec, Params, PortSpec, Refused, Role, Summary};

/// The longest fade the limiter may take: the live runner's stop sequence
/// runs this long (plus one tick) before it ends a session.
pub const MAX_RAMP_S: f64 = 0.010;

/// What the limiter did at one sample, as its `state` output reports it
/// (the code is the sample's value). One per sample, so a reader (the
/// studio, a recording) never has to infer it from the signals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    /// Enabled, no fault latched, and neither clamp nor slew limit acted:
    /// the signal passes (also while the gate opens at the start or after
    /// a re-arm).
    Armed,
    /// Enabled, no fault latched, and the amplitude clamp or the slew-rate
    /// limit changed this sample.
    Clamping,
    /// `enable` is false and the gate is still closing: the output is not
    /// yet exactly zero.
    Fading,
    /// `enable` is false and the gate is closed: the output is exactly zero.
    Faded,
    /// A NaN/infinite input or a fault input latched the gate: it is
    /// closing or closed, until `enable` is set true again.
    Faulted,
}

/// `state` code of [`State::Armed`].
pub const STATE_ARMED: f64 = 0.0;
/// `state` code of [`State::Clamping`].
pub const STATE_CLAMPING: f64 = 1.0;
/// `state` code of [`State::Fading`].
pub const STATE_FADING: f64 = 2.0;
/// `state` code of [`State::Faded`].
pub const STATE_FADED: f64 = 3.0;
/// `state` code of [`State::Faulted`].
pub const STATE_FAULTED: f64 = 4.0;

impl State {
    /// Every state, in code order.
    pub const ALL: [State; 5] = [State::Armed, State::Clamping, State::Fading, State::Faded, State::Faulted];

    /// The value the `state` output carries.
    pub const fn code(self) -> f64 {
        match self {
            State::Armed => STATE_ARMED,
            State::Clamping => STATE_CLAMPING,
            State::Fading => STATE_FADING,
            State::Faded => STATE_FADED,
            State::Faulted => STATE_FAULTED,
        }
    }

    /// The state a `state` sample stands for; `None` for any other value.
    pub fn from_code(x: f64) -> Option<State> {
        State::ALL.into_iter().find(|s| s.code() == x)
    }

    /// Lower-case name (`armed`, `clamping`, `fading`, `faded`, `faulted`).
    pub const fn name(self) -> &'static str {
        match self {
            State::Armed => "armed",
            State::Clamping => "clamping",
            State::Fading => "fading",
            State::Faded => "faded",
            State::Faulted => "faulted",
        }
    }
}

/// Declaration of `limit`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "limit",
    "safety",
    Role::Filter,
    "Safety limiter: amplitude clamp, slew-rate limit, ramp to zero on NaN, fault or stop.",
    build,
)
.doc(
    "The last node before hardware: the loader refuses a graph in which a hardware output is fed by \
anything else (`docs/safety.md`). An actuation signal reaches a finger through a high-voltage \
amplifier (1.0 = 50 V at the amplifier output, ±1.0 = 100 Vpp; dissertation §5.2.3, Table 5.1's \
gain sweep), so the limiter guarantees, whatever arrives at `in`:\n\
\n\
* **Amplitude clamp**: |out| ≤ `amplitude` at every sample.\n\
* **Slew-rate limit**: the clamped signal moves at most `slew`/rate per sample (the default, \
4000 /s, leaves 1 kHz actuation untouched — a full ±1 swing in one 1 ms sample is 2000 /s — and \
limits faster rates and runaway signals).\n\
* **Gate**: the output is the slewed signal times a gate that moves linearly between 0 and 1 in \
`ramp` seconds (round(ramp·rate) samples, at least one). The gate opens at t = 0 (a session never \
starts with a step) and closes — reaching exactly 0 within `ramp` ≤ 10 ms — on: a NaN or infinite \
input sample (the signal is held at its last finite value while it fades); a nonzero (or NaN) \
sample on any fault input (one input per `faults` entry, e.g. a link or contact flag); or \
`enable` set to false (the live runner does this on stop, Ctrl-C, the end of the duration, a \
streak of deadline misses and device disconnects). NaN and fault-input faults latch: the output \
stays at zero until `enable` is set to true again (re-arming), after which it fades back in.\n\
\n\
**State**: the second output, `state`, says at every sample what the limiter did (the code is \
the sample's value; `evflow_nodes::safety::limit::State`): 0 = *armed* (the signal passes; also \
while the gate opens at the start or after a re-arm), 1 = *clamping* (the amplitude clamp or the \
slew-rate limit changed this sample), 2 = *fading* (`enable` false, the output not yet zero), \
3 = *faded* (`enable` false, the output exactly zero — from the round(ramp·rate)-th sample of the \
fade on), 4 = *faulted* (a NaN/infinite input or a fault input latched the gate: closing or \
closed, until re-armed). A latched fault outranks a disable, a disable outranks clamping. \
`state` is for monitoring (the studio, recordings), never an actuation signal: the loader lets \
only `out` feed hardware.\n\
\n\
Outputs are always finite. `enable` is the one parameter that changes live. The summary reports \
how many samples were clamped and slew-limited, and every fault with its sample index.\n\
\n\
**Checked against:** the clamp and slew bounds on random and extreme inputs (±1e300, steps, NaN \
bursts); the fade reaching exactly zero within round(ramp·rate) samples after a NaN, a fault \
input and a disable; the latch and re-arm; the `state` code at each transition; block ≡ per-sample processing (generic node test).",
)
.ports(PORTS)
.params(&[AMPLITUDE.spec(), SLEW.spec(), RAMP.spec(), FAULTS.spec(), ENABLE.spec()])
.safety_guard(ENABLE.name())
.bound(output_bound)
.example("amplitude = 1.0\nslew = 4000.0\nramp = 0.01");

/// The ports: the signal and one fault flag per `faults` entry in; the
/// limited signal and the limiter's state out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("in", "1", "actuation signal").view(),
    PortSpec::input("fault", "1", "fault flag: nonzero (or NaN) closes the gate and latches").per(FAULTS.name()),
    PortSpec::output("out", "1", "limited actuation signal"),
    PortSpec::output(
        "state",
        "1",
        "what the limiter did at each sample: 0 armed, 1 clamping, 2 fading, 3 faded, 4 faulted",
    )
    .view(),
];
/// `in`: the actuation signal.
const IN: InPort = InPort::named(PORTS, "in");
/// `fault`: the first fault flag; the k-th is `FAULT.nth(k)`.
const FAULT: InPort = InPort::named(PORTS, "fault");
/// `out`: the limited actuation signal.
const OUT: OutPort = OutPort::named(PORTS, "out");
/// `state`: what the limiter did, as a [`State`] code.
const STATE: OutPort = OutPort::named(PORTS, "state");

/// `amplitude`: the largest |out|.
pub const AMPLITUDE: Float = Float::new("amplitude", 0.0, 10.0, 1.0, "1", "largest |out| (1.0 = 50 V peak, 100 Vpp)");
/// `slew`: the largest rate of change.
const SLEW: Float = Float::new("slew", 1e-3, 1e12, 4000.0, "1/s", "largest rate of change of the clamped signal");
/// `ramp`: the gate's fade time.
const RAMP: Float = Float::new("ramp", 0.0, MAX_RAMP_S, MAX_RAMP_S, "s", "fade time of the gate (at most 10 ms)");
/// `faults`: the names of the fault-flag inputs.
const FAULTS: Words = Words::new("faults", "names of fault-flag inputs (e.g. [\"link\"]); none by default");
/// `enable`: the gate, changeable live.
pub const ENABLE: Flag = Flag::new("enable", true, "gate open; false fades to zero, true re-arms after a fault").live();

/// What closed the gate first.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fault {
    NotFinite { sample: u64 },
    Input { port: usize, sample: u64 },
}

struct Limit {
    amplitude: f64,
    /// Largest change per sample.
    step: f64,
    ramp_steps: u32,
    fault_names: Vec<String>,
    enabled: bool,
    latched: bool,
    /// The clamped, slew-limited signal.
    held: f64,
    gate: Envelope,
    clamped: u64,
    slewed: u64,
    faults: Vec<Fault>,
    /// Index at the node's rate of the next sample.
    next: u64,
}

/// Faults kept for the summary (more are counted, not listed).
const FAULTS_LISTED: usize = 16;

/// The output bound the stability suite checks: |out| ≤ `amplitude`.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.num(&AMPLITUDE.spec()), "|out| ≤ amplitude".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let ramp_steps = (RAMP.get(p) * ctx.rate).round().max(1.0);
    if ramp_steps > u32::MAX as f64 {
        return Err(NodeError::param(RAMP.name(), "too many samples at this rate"));
    }
    let fault_names = FAULTS.get(p).to_vec();
    for reserved in ["in", "out"] {
        if fault_names.iter().any(|n| n == reserved) {
            return Err(NodeError::param(
                FAULTS.name(),
                format!("`{reserved}` is taken by the signal port; rename it"),
            ));
        }
    }
    let mut node = Limit {
        amplitude: AMPLITUDE.get(p),
        step: SLEW.get(p) / ctx.rate,
        ramp_steps: ramp_steps as u32,
        fault_names,
        enabled: ENABLE.get(p),
        latched: false,
        held: 0.0,
        gate: Envelope::closed(1),
        clamped: 0,
        slewed: 0,
        faults: Vec::new(),
        next: 0,
    };
    node.reset();
    node.enabled = ENABLE.get(p);
    Ok(Box::new(node))
}

impl Limit {
    fn record(&mut self, f: Fault) {
        if self.faults.len() < FAULTS_LISTED {
            self.faults.push(f);
        }
    }
}

impl Node for Limit {
    fn prepare(&mut self, _: &evflow_engine::PrepareContext) -> Result<(), NodeError> {
        self.faults.reserve_exact(FAULTS_LISTED);
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        let n_faults = io.n_inputs() - 1;
        for i in 0..n {
            let x = io.input(IN)[i];
            let sample = self.next + i as u64;
            if !self.latched {
                if !x.is_finite() {
                    self.latched = true;
                    self.record(Fault::NotFinite { sample });
                } else if let Some(port) = (0..n_faults).find(|&k| io.input(FAULT.nth(k))[i] != 0.0) {
                    self.latched = true;
                    self.record(Fault::Input { port, sample });
                }
            }
            let mut acted = false;
            if x.is_finite() {
                let c = x.clamp(-self.amplitude, self.amplitude);
                if c != x {
                    self.clamped += 1;
                    acted = true;
                }
                let d = c - self.held;
                if d > self.step {
                    self.held += self.step;
                    self.slewed += 1;
                    acted = true;
                } else if d < -self.step {
                    self.held -= self.step;
                    self.slewed += 1;
                    acted = true;
                } else {
                    self.held = c;
                }
                // Rounding in `held ± step` cannot leave the clamp range.
                self.held = self.held.clamp(-self.amplitude, self.amplitude);
            }
            let g = self.gate.advance(self.enabled && !self.latched);
            io.output(OUT)[i] = g * self.held;
            let state = if self.latched {
                State::Faulted
            } else if !self.enabled {
                if g == 0.0 {
                    State::Faded
                } else {
                    State::Fading
                }
            } else if acted {
                State::Clamping
            } else {
                State::Armed
            };
            io.output(STATE)[i] = state.code();
        }
        self.next += n as u64;
        Ok(())
    }

    fn reset(&mut self) {
        self.latched = false;
        self.held = 0.0;
        self.gate = Envelope::closed(self.ramp_steps);
        self.clamped = 0;
        self.slewed = 0;
        self.faults.clear();
        self.next = 0;
    }

    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match ENABLE.changed(&c) {
            Some(enabled) => {
                self.enabled = enabled;
                if self.enabled {
                    self.latched = false;
                }
                Ok(())
            }
            None => Err(c.refused()),
        }
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let mut s = Summary::default().value("clamped", self.clamped as f64, "samples").value(
            "slew_limited",
            self.slewed as f64,
            "samples",
        );
        for f in &self.faults {
            s = s.line(match *f {
                Fault::NotFinite { sample } => format!("fault: non-finite input at sample {sample}; faded to zero"),
                Fault::Input { port, sample } => {
                    format!("fault: input `{}` raised at sample {sample}; faded to zero", self.fault_names[port])
                }
            });
        }
        if self.latched {
            s = s.line("ended with the gate latched closed (re-arm with enable = true)");
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests;
