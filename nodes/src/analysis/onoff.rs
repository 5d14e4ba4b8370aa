//! `onoff`: the friction increase while an effect is on, against while it is off.

use crate::wide_sum::WideSum;
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `onoff`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "onoff",
    "analysis",
    Role::Sink,
    "Mean friction with an effect on minus with it off: the static friction increase (§3.1.2).",
    build,
)
.doc(
    "The static-friction measure of dissertation §3.1.2 (Fig. 3.4): the effect is enabled in \
some segments of the travel and disabled in the others; \"we computed two average forces from the \
segments when electrovibration was on and off and used their difference to represent the increase \
of static friction force\". Inputs: the tangential `force`, the `gate` that switched the effect \
(on where gate > 0.5) and the sliding `velocity`. Friction opposes motion, so on a tribometer \
that passes left and right the force changes sign with the direction: each sample counts as \
force·sign(velocity) — the friction magnitude along the motion — and samples slower than \
`min_speed` (rest, turnarounds) are left out, as are the first `settle` seconds after every \
switch of the gate or start of motion (the transient of the force and its filter).\n\
\n\
Reports `on_mean`, `off_mean`, `increase` = on − off (N) and the samples counted in each. Ports \
at any one rate (the node's). An error if either state has no counted sample, or on a NaN. The \
sums scale by a power of two where a plain one would overflow (forces near ±f64::MAX), so the \
means of finite forces are right; an `increase` beyond ±f64::MAX is reported as ±f64::MAX, with \
a line saying so.\n\
\n\
**Checked against:** a synthetic force of known friction levels with a known gate, in both \
directions, with a transient that `settle` removes.",
)
.ports(PORTS)
.params(&[MIN_SPEED.spec(), SETTLE.spec()])
.example("min_speed = 0.005\nsettle = 0.0");

/// The ports: force, gate and velocity, at the node's rate.
const PORTS: &[PortSpec] = &[
    PortSpec::input("force", "N", "tangential force (low-passed)"),
    PortSpec::input("gate", "1", "the effect's state: on where > 0.5"),
    PortSpec::input("velocity", "m/s", "sliding velocity: its sign gives the friction's direction"),
];
/// The tangential force.
const FORCE: InPort = InPort::named(PORTS, "force");
/// The effect's state.
const GATE: InPort = InPort::named(PORTS, "gate");
/// The sliding velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");

/// `min_speed`: slower samples are left out.
const MIN_SPEED: Float =
    Float::new("min_speed", 0.0, 10.0, 0.005, "m/s", "slower samples (rest, turnarounds) are left out");
/// `settle`: time left out after a switch or a start.
const SETTLE: Float =
    Float::new("settle", 0.0, 100.0, 0.05, "s", "time left out after each switch of the gate or start of motion");

struct OnOff {
    min_speed: f64,
    settle: u64,
    /// Samples still to skip.
    skip: u64,
    last_on: Option<bool>,
    moving: bool,
    sum: [WideSum<f64>; 2],
    count: [u64; 2],
    n: u64,
    bad: Option<u64>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(OnOff {
        min_speed: MIN_SPEED.get(p),
        settle: (SETTLE.get(p) * ctx.rate).round() as u64,
        skip: 0,
        last_on: None,
        moving: false,
        sum: [WideSum::default(); 2],
        count: [0; 2],
        n: 0,
        bad: None,
    }))
}

impl Node for OnOff {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            let (f, g, v) = (io.input(FORCE)[k], io.input(GATE)[k], io.input(VELOCITY)[k]);
            self.n += 1;
            if !(f.is_finite() && g.is_finite() && v.is_finite()) {
                self.bad.get_or_insert(self.n - 1);
                continue;
            }
            let on = g > 0.5;
            let moving = v.abs() >= self.min_speed;
            if self.last_on != Some(on) || (moving && !self.moving) {
                self.skip = self.settle;
            }
            self.last_on = Some(on);
            self.moving = moving;
            if !moving {
                continue;
            }
            if self.skip > 0 {
                self.skip -= 1;
                continue;
            }
            let i = usize::from(on);
            self.sum[i].add(f * v.signum());
            self.count[i] += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.skip = 0;
        self.last_on = None;
        self.moving = false;
        self.sum = [WideSum::default(); 2];
        self.count = [0; 2];
        self.n = 0;
        self.bad = None;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        if let Some(i) = self.bad {
            return Err(NodeError::Data(format!("sample {i}: an input is NaN or infinite")));
        }
        for (i, state) in ["off", "on"].iter().enumerate() {
            if self.count[i] == 0 {
                return Err(NodeError::Data(format!(
                    "no moving sample with the effect {state} (after leaving out turnarounds and settling)"
                )));
            }
        }
        let off = self.sum[0].mean(self.count[0] as f64);
        let on = self.sum[1].mean(self.count[1] as f64);
        let increase = on - off;
        let s = Summary::default()
            .value("on_mean", on, "N")
            .value("off_mean", off, "N")
            .value("increase", increase.clamp(-f64::MAX, f64::MAX), "N")
            .value("on_samples", self.count[1] as f64, "1")
            .value("off_samples", self.count[0] as f64, "1");
        Ok(if increase.is_finite() {
            s
        } else {
            s.line(format!(
                "the increase {on:e} − ({off:e}) N is beyond f64::MAX: reported as {:e}",
                increase.signum() * f64::MAX
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    fn run(force: Vec<f64>, gate: Vec<f64>, vel: Vec<f64>, params: &str) -> Result<Summary, String> {
        let ticks = force.len() as u64;
        let s = Single::new(&SPEC, params)
            .input("force", force, 1000.0)
            .input("gate", gate, 1000.0)
            .input("velocity", vel, 1000.0)
            .ticks(ticks);
        s.summary()
    }

    fn get(s: &Summary, k: &str) -> f64 {
        s.get(k).unwrap_or_else(|| panic!("no value `{k}`"))
    }

    #[test]
    fn measures_the_increase_in_both_directions() {
        // 4 s: right then left at 5 cm/s, resting 0.2 s between; effect on for
        // 0.25 s of every second; friction 0.1 N off, 0.16 N on, with a 30 ms
        // overshoot after each switch that `settle` removes.
        let n = 4000;
        let vel: Vec<f64> = (0..n)
            .map(|i| {
                if i < 1800 {
                    0.05
                } else if i < 2000 {
                    0.0
                } else {
                    -0.05
                }
            })
            .collect();
        let gate: Vec<f64> = (0..n).map(|i| if i % 1000 < 250 { 1.0 } else { 0.0 }).collect();
        let force: Vec<f64> = (0..n)
            .map(|i| {
                let level = if gate[i] > 0.5 { 0.16 } else { 0.1 };
                let phase = i % 1000;
                let since = if phase >= 250 { phase - 250 } else { phase };
                let kick = if since < 30 { 0.5 } else { 0.0 };
                (level + kick) * vel[i].signum()
            })
            .collect();
        let s = run(force.clone(), gate.clone(), vel.clone(), "settle = 0.05").unwrap();
        assert!((get(&s, "increase") - 0.06).abs() < 1e-12, "{}", get(&s, "increase"));
        assert!((get(&s, "off_mean") - 0.1).abs() < 1e-12);
        let raw = run(force, gate, vel, "settle = 0.0").unwrap();
        assert!((get(&raw, "increase") - 0.06).abs() > 1e-3, "the transient must matter without settling");
    }

    #[test]
    fn forces_near_max_give_finite_true_means() {
        // On for the first half at +MAX, off for the second at −MAX, moving
        // right: the plain sums overflowed (on_mean, off_mean, increase inf).
        let (n, half) = (40, 20);
        let force: Vec<f64> = (0..n).map(|i| if i < half { f64::MAX } else { -f64::MAX }).collect();
        let gate: Vec<f64> = (0..n).map(|i| if i < half { 1.0 } else { 0.0 }).collect();
        let s = run(force, gate, vec![0.05; n], "settle = 0.0").unwrap();
        let close = |v: f64, want: f64| (v - want).abs() <= 1e-15 * want.abs();
        assert!(close(get(&s, "on_mean"), f64::MAX) && close(get(&s, "off_mean"), -f64::MAX), "{s:?}");
        assert_eq!(get(&s, "increase"), f64::MAX);
        assert!(s.lines.iter().any(|l| l.contains("beyond f64::MAX")), "{:?}", s.lines);
        // Half the on samples at MAX, half at 0: the mean is MAX/2 and in range.
        let force: Vec<f64> = (0..n).map(|i| if i < half / 2 { f64::MAX } else { 0.0 }).collect();
        let gate: Vec<f64> = (0..n).map(|i| if i < half { 1.0 } else { 0.0 }).collect();
        let s = run(force, gate, vec![0.05; n], "settle = 0.0").unwrap();
        assert!(close(get(&s, "on_mean"), f64::MAX / 2.0) && close(get(&s, "increase"), f64::MAX / 2.0), "{s:?}");
        assert_eq!(get(&s, "off_mean"), 0.0);
        assert!(s.lines.is_empty(), "{:?}", s.lines);
    }

    #[test]
    fn a_missing_state_is_an_error() {
        let e = run(vec![0.1; 500], vec![0.0; 500], vec![0.05; 500], "").unwrap_err();
        assert!(e.contains("effect on"), "{e}");
    }
}
