//! `segment`: marks the constant-speed stretches of a scan (§5.1.1).

use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Choice, Float, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `segment`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "segment",
    "filters",
    Role::Filter,
    "Constant-speed gate: 1 while the scanning speed has stayed at `speed` (within `tolerance`) for `settle` seconds, else 0.",
    build,
)
.doc(
    "Dissertation §5.1.1: the tribometer accelerates, scans at a constant speed, decelerates and \
reverses; only the constant-speed part of each pass is used, the parts of all passes extracted and \
concatenated. `segment` marks them: its output is 1 at sample n when |v| has been within \
`tolerance` × `speed` of `speed` for every sample of the last `settle` seconds (round(settle·rate) \
samples, at least one), in the chosen `direction` (`both`, `forward` = +x only, `backward` = −x \
only), and 0 otherwise. One direction matters for training an inverse display model: friction \
opposes the motion, so the force's variations change sign with the direction of the pass. The settling time leaves out the \
high-pass filter's and the sensor's response to the reversal and the pen's stick-to-slip start. The \
stretch ends on the first sample that leaves the tolerance (deceleration), so nothing after it is \
kept.\n\n\
Sinks that take a gate (`metric` and `narx.train`, their `gate` parameter) keep only the samples \
where every gate is 1 and concatenate them: this is the extraction and concatenation of §5.1.1 \
over any number of passes.\n\n\
**Ports.** `velocity` (m/s) in, `gate` (1 or 0) out, at the rate of the input. A non-finite \
velocity counts as out of tolerance (and restarts the settling).\n\n\
Checked against: a trapezoidal velocity profile with known plateau starts and ends, both \
directions, the settling count, a NaN sample, block ≡ per-sample processing.",
)
.ports(PORTS)
.params(&[SPEED.spec(), TOLERANCE.spec(), SETTLE.spec(), DIRECTION.spec()])
.example("speed = 5.0\ntolerance = 0.02\nsettle = 0.1\ndirection = \"both\"");

/// The ports: the velocity in, the gate out, at the same rate.
const PORTS: &[PortSpec] = &[
    PortSpec::input("velocity", "m/s", "scanning velocity (e.g. the tribometer's)"),
    PortSpec::output("gate", "1", "1 inside a settled constant-speed stretch, else 0"),
];
/// The scanning velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// The gate.
const GATE: OutPort = OutPort::named(PORTS, "gate");

/// `speed`: the constant scanning speed.
const SPEED: Float =
    Float::new("speed", 1e-3, 1e4, 5.0, "cm/s", "the constant scanning speed (either direction)").required();
/// `tolerance`: the largest relative deviation of |v| from `speed`.
const TOLERANCE: Float =
    Float::new("tolerance", 1e-6, 0.5, 0.02, "1", "largest relative deviation of |v| from `speed`");
/// `settle`: how long |v| must have stayed in tolerance.
const SETTLE: Float = Float::new("settle", 0.0, 60.0, 0.1, "s", "time |v| must have stayed in tolerance");
/// `direction`: which passes count.
const DIRECTION: Choice<Pass> = Choice::new(
    "direction",
    &["both", "forward", "backward"],
    &[Pass::Both, Pass::Forward, Pass::Backward],
    "both",
    "which passes count: both, +x only or −x only",
);

/// Which passes of the scan count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pass {
    /// Both directions.
    Both,
    /// +x only.
    Forward,
    /// −x only.
    Backward,
}

impl Pass {
    /// The `direction` argument of [`SpeedRule::new`]: +1, −1 or 0.
    fn sign(self) -> f64 {
        match self {
            Pass::Both => 0.0,
            Pass::Forward => 1.0,
            Pass::Backward => -1.0,
        }
    }
}

/// The `gate` parameter of the sinks that take gates (`metric`,
/// `narx.train`, `narx.score`, `synth.train`): the names of their gate
/// inputs, one port `gate` each ([`PortSpec::per`]).
pub const GATES: Words = Words::new("gate", "names of gate inputs (e.g. [\"steady\"] from `segment`); none by default");

/// The constant-speed rule of `segment`, one sample at a time: the one
/// definition the node and the offline users of a recording's velocity
/// (e.g. `synth.optimize`) share.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedRule {
    /// |v| bounds in m/s.
    lo: f64,
    hi: f64,
    /// Samples in tolerance needed before the gate opens.
    settle: u64,
    /// Consecutive samples in tolerance so far.
    run: u64,
    /// +1: forward only, −1: backward only, 0: both.
    sign: f64,
}

impl SpeedRule {
    /// The rule for `speed` cm/s within `tolerance` (relative), settled for
    /// `settle` s at `rate` Hz, in `direction` (+1 forward, −1 backward, 0 both).
    pub fn new(speed_cm_s: f64, tolerance: f64, settle: f64, rate: f64, direction: f64) -> Self {
        let speed = speed_cm_s / 100.0;
        let settle = (settle * rate).round().max(1.0) as u64;
        // f64::signum(0.0) is 1: both directions need an explicit 0.
        let sign = if direction > 0.0 {
            1.0
        } else if direction < 0.0 {
            -1.0
        } else {
            0.0
        };
        Self { lo: speed * (1.0 - tolerance), hi: speed * (1.0 + tolerance), settle, run: 0, sign }
    }

    /// Takes the velocity v (m/s) of the next sample; true when the gate is open there.
    #[inline]
    pub fn step(&mut self, v: f64) -> bool {
        // Against the chosen direction, |v| counts as 0 (out of tolerance).
        let a = if self.sign == 0.0 || v * self.sign > 0.0 { v.abs() } else { 0.0 };
        // NaN fails both comparisons and restarts the count.
        self.run = if a >= self.lo && a <= self.hi { self.run.saturating_add(1) } else { 0 };
        self.run >= self.settle
    }

    /// The gate over a whole velocity series, from rest.
    pub fn gate(mut self, velocity: &[f64]) -> Vec<bool> {
        self.run = 0;
        velocity.iter().map(|&v| self.step(v)).collect()
    }
}

struct Segment {
    rule: SpeedRule,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let sign = DIRECTION.get(p).sign();
    Ok(Box::new(Segment { rule: SpeedRule::new(SPEED.get(p), TOLERANCE.get(p), SETTLE.get(p), ctx.rate, sign) }))
}

impl Node for Segment {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (v, gate) = io.io(VELOCITY, GATE);
        for (g, v) in gate.iter_mut().zip(v) {
            *g = if self.rule.step(*v) { 1.0 } else { 0.0 };
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.rule.run = 0;
    }
}

/// Most gate inputs a sink takes.
pub const MAX_GATES: usize = 8;

/// The gate inputs of a sink (its `gate` parameter, fed by `segment`): one
/// definition of "keep the samples where every gate is above 0.5" for the
/// sinks that take gates (`metric`, `narx.train`).
#[derive(Debug, Clone, Copy)]
pub struct Gates {
    /// The first gate input (they follow the data inputs).
    first: InPort,
    /// Number of gates.
    count: usize,
}

impl Gates {
    /// Reads the `gate` parameter ([`GATES`]); the gate inputs start at
    /// `first`, the node's repeated `gate` port. (A gate named like another
    /// input is refused by the validator: port names must be unique.)
    pub fn from_params(p: &Params, first: InPort) -> Result<Self, NodeError> {
        let count = GATES.get(p).len();
        if count > MAX_GATES {
            return Err(NodeError::param(GATES.name(), format!("{count} gates; at most {MAX_GATES}")));
        }
        Ok(Self { first, count })
    }

    /// Whether there are any gates.
    pub fn any(&self) -> bool {
        self.count > 0
    }

    /// Calls `keep(start, end)` for each maximal run of this call's samples
    /// with every gate open (the whole call when there are no gates);
    /// returns how many samples were kept. Does not allocate.
    pub fn open_runs(&self, io: &Io<'_>, keep: impl FnMut(usize, usize)) -> usize {
        let mut gates = [&[][..]; MAX_GATES];
        for (g, slot) in gates.iter_mut().enumerate().take(self.count) {
            *slot = io.input(self.first.nth(g));
        }
        let mut kept = 0;
        let mut keep = keep;
        open_runs(&gates[..self.count], io.len(), |a, b| {
            kept += b - a;
            keep(a, b);
        });
        kept
    }
}

/// Calls `keep(start, end)` for each maximal run `start..end` of indices
/// `0..len` with all `gates[g][i] > 0.5` (every index when `gates` is empty).
pub fn open_runs(gates: &[&[f64]], len: usize, mut keep: impl FnMut(usize, usize)) {
    let open = |i: usize| gates.iter().all(|g| g[i] > 0.5);
    let mut i = 0;
    while i < len {
        if !open(i) {
            i += 1;
            continue;
        }
        let start = i;
        while i < len && open(i) {
            i += 1;
        }
        keep(start, i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    fn run(params: &str, v: &[f64], block: usize) -> Vec<f64> {
        let single = Single::new(&SPEC, params)
            .input("velocity", v.to_vec(), 1000.0)
            .output("gate")
            .ticks(v.len() as u64)
            .block(block);
        single.run().expect("runs").remove(0)
    }

    /// A trapezoid: 100 samples at rest, a 200-sample ramp to ±speed, 1000 at
    /// speed, a 200-sample ramp down.
    fn trapezoid(speed: f64, dir: f64) -> Vec<f64> {
        let mut v = vec![0.0; 100];
        v.extend((0..200).map(|k| dir * speed * (k + 1) as f64 / 200.0));
        v.extend(std::iter::repeat_n(dir * speed, 1000));
        v.extend((0..200).map(|k| dir * speed * (199 - k) as f64 / 200.0));
        v
    }

    #[test]
    fn opens_after_settling_on_the_plateau_and_closes_when_it_ends() {
        for dir in [1.0, -1.0] {
            let v = trapezoid(0.05, dir);
            let g = run("speed = 5.0\ntolerance = 0.021\nsettle = 0.1", &v, 64);
            // In tolerance from ramp sample k with (k+1)/200 ≥ 0.98, i.e. k = 195:
            // index 100 + 195 = 295; open after 100 samples in tolerance, at 394.
            let first = g.iter().position(|&x| x == 1.0).expect("opens");
            assert_eq!(first, 394, "direction {dir}");
            // The last plateau sample is 1299; the ramp down leaves tolerance at
            // k with (199−k)/200 < 0.98: k = 4 → index 1304; samples 1300..1303 stay in.
            let last = g.iter().rposition(|&x| x == 1.0).expect("opens");
            assert_eq!(last, 1303);
            assert!(g[first..=last].iter().all(|&x| x == 1.0));
            assert_eq!(g.iter().filter(|&&x| x == 1.0).count(), 1303 - 394 + 1);
            // One direction only: the same pass counts or does not.
            let fwd = run("speed = 5.0\ntolerance = 0.021\ndirection = \"forward\"", &v, 64);
            let back = run("speed = 5.0\ntolerance = 0.021\ndirection = \"backward\"", &v, 64);
            let (with, without) = if dir > 0.0 { (fwd, back) } else { (back, fwd) };
            assert_eq!(with, g);
            assert!(without.iter().all(|&x| x == 0.0));
        }
    }

    #[test]
    fn a_non_finite_speed_restarts_the_settling_and_blocks_do_not_matter() {
        let mut v = vec![0.05; 500];
        v[250] = f64::INFINITY; // non-finite (the harness cannot feed NaN; NaN fails the same comparison)
        let g = run("speed = 5.0\nsettle = 0.1", &v, 1);
        assert_eq!(g.iter().position(|&x| x == 1.0), Some(99));
        assert_eq!(g[250], 0.0);
        assert_eq!(g[349], 0.0);
        assert_eq!(g[350], 1.0);
        assert_eq!(g, run("speed = 5.0\nsettle = 0.1", &v, 333));
    }

    #[test]
    fn open_runs_finds_the_runs_where_every_gate_is_open() {
        let a = [1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0];
        let b = [1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let mut runs = Vec::new();
        open_runs(&[&a, &b], 7, |s, e| runs.push((s, e)));
        assert_eq!(runs, vec![(0, 1), (3, 6)]);
        let mut all = Vec::new();
        open_runs(&[], 3, |s, e| all.push((s, e)));
        assert_eq!(all, vec![(0, 3)]);
    }
}
