//! `pulse`: a rectangular gate that switches between two levels.

use evflow_engine::ports::OutPort;
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `pulse`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "pulse",
    "sources",
    Role::Source,
    "Rectangular wave: `high` for the first `duty` of each period, `low` for the rest.",
    build,
)
.doc(
    "y[n] = high if ((n − delay·fs) mod P) < duty·P else low, with P = period·fs samples (both \
rounded to whole samples), and `low` before the first period starts (n < delay·fs). An endless \
source. Used to switch an effect on and off in segments — the on/off static friction measurement \
of dissertation §3.1.2 (Fig. 3.4: the effect on for one segment in eight) — and as a gate or a \
square test signal.\n\
\n\
**Port** `out` at the rate set by `rate`. Each sample depends only on its index, so block and \
one-sample processing agree and `reset` returns to n = 0.\n\
\n\
**Checked against:** the exact count of high samples per period and the switching indices.",
)
.ports(PORTS)
.params(&[PERIOD.spec(), DUTY.spec(), DELAY.spec(), HIGH.spec(), LOW.spec(), RATE.spec()])
.rate_param(RATE.name())
.bound(output_bound)
.example("period = 1.0\nduty = 0.125\nrate = 1000.0");

/// The port: the gate out.
const PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "the gate: high or low")];
/// `out`: the gate.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `period`: P, rounded to whole samples.
const PERIOD: Float = Float::new("period", 1e-6, 1e6, 1.0, "s", "period P (rounded to whole samples, at least 1)");
/// `duty`: the fraction of each period at `high`.
const DUTY: Float = Float::new("duty", 0.0, 1.0, 0.5, "1", "fraction of each period at `high`");
/// `delay`: when the first period starts.
const DELAY: Float = Float::new("delay", 0.0, 1e6, 0.0, "s", "time of the first period's start");
/// `high`: the level of the first part of a period.
const HIGH: Float = Float::new("high", -1e6, 1e6, 1.0, "1", "level during the first part of a period");
/// `low`: the level of the rest.
const LOW: Float = Float::new("low", -1e6, 1e6, 0.0, "1", "level during the rest");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

struct Pulse {
    period: u64,
    on: u64,
    delay: u64,
    high: f64,
    low: f64,
}

/// The output bound the stability suite checks: |out| ≤ max(|high|, |low|).
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("out", b.num(&HIGH.spec()).abs().max(b.num(&LOW.spec()).abs()), "max(|high|, |low|)".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let fs = ctx.rate;
    let period = (PERIOD.get(p) * fs).round().max(1.0);
    let delay = (DELAY.get(p) * fs).round();
    if period >= 1e15 || delay >= 1e15 {
        return Err(NodeError::param(PERIOD.name(), "period or delay is too long at this rate"));
    }
    let period = period as u64;
    let on = ((DUTY.get(p) * period as f64).round() as u64).min(period);
    Ok(Box::new(Pulse { period, on, delay: delay as u64, high: HIGH.get(p), low: LOW.get(p) }))
}

impl Node for Pulse {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let start = io.start();
        for (k, y) in io.output(OUT).iter_mut().enumerate() {
            let n = start + k as u64;
            *y = if n >= self.delay && (n - self.delay) % self.period < self.on { self.high } else { self.low };
        }
        Ok(())
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    fn run(params: &str, ticks: u64) -> Vec<f64> {
        Single::new(&SPEC, params).output("out").ticks(ticks).run().unwrap().remove(0)
    }

    #[test]
    fn one_segment_in_eight_is_high() {
        let y = run("period = 0.8\nduty = 0.125\nrate = 1000.0", 8000);
        assert_eq!(y.iter().filter(|&&v| v == 1.0).count(), 1000);
        for (n, v) in y.iter().enumerate() {
            assert_eq!(*v, if n % 800 < 100 { 1.0 } else { 0.0 }, "sample {n}");
        }
    }

    #[test]
    fn delay_and_levels() {
        let y = run("period = 0.01\nduty = 0.5\ndelay = 0.003\nhigh = 2.0\nlow = -1.0\nrate = 1000.0", 30);
        assert_eq!(&y[..5], &[-1.0, -1.0, -1.0, 2.0, 2.0]);
        assert_eq!(y[8], -1.0);
        assert_eq!(y[13], 2.0);
    }
}
