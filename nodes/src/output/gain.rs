//! `gain`: multiplies a stream by a constant.

use evflow_engine::node::Constant;
use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT, UNIT_PARAM};
use evflow_engine::spec::{BoundArgs, FoldArgs, PortBound};
use evflow_engine::typed_params::{Float, Text};
use evflow_engine::{BuildContext, Change, Io, Node, NodeError, NodeSpec, Params, PortSpec, Refused, Role};

/// Declaration of `gain`.
pub static SPEC: NodeSpec =
    NodeSpec::new("gain", "output", Role::Filter, "Multiplies a stream by a constant gain.", build)
        .doc(
            "y[n] = g · x[n]. Used to scale synthesized actuation signals before the display \
         (the gain sweep 0.6–1.4 of dissertation §5.3.1, Table 5.1; 1.0 corresponds to 100 Vpp \
         through the amplifier). Runs at the rate of its input; its output has its input's unit, or \
         `unit` where the gain converts one into another (the load cell's N into g). A product beyond the range of \
         f64 saturates at ±f64::MAX instead of becoming infinite.\n\n\
         `gain` changes live (a session's parameter queue): the multiplier then moves linearly \
         from its current value to the new one over `ramp` seconds (round(ramp·rate) samples, at \
         least one), so a change never clicks; a change during a ramp starts a new ramp from where \
         the gain is. Checked by the exact ramp values in its unit tests and the generic \
         block ≡ per-sample test.\n\n\
         **Pruning** (docs/pruning.md): a gain of 0 makes the output the constant 0, and a \
         constant input c makes it g·c; the planner then holds the output and leaves out what fed \
         only this node. A live plan never folds on `gain`, which may change while it runs.",
        )
        .ports(PORTS)
        .params(&[GAIN.spec(), RAMP.spec(), UNIT.spec()])
        .bound(output_bound)
        .example("gain = 1.2")
        .fold(fold);

/// The ports: one signal in, the scaled signal out.
const PORTS: &[PortSpec] =
    &[PortSpec::input("in", "1", "signal"), PortSpec::output("out", SAME_AS_INPUT, "signal × gain")];
const IN: InPort = InPort::named(PORTS, "in");
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `gain`: the multiplier, changeable live.
const GAIN: Float = Float::new("gain", -1e6, 1e6, 1.0, "1", "multiplier").live();
/// `ramp`: how long a live change takes.
const RAMP: Float = Float::new("ramp", 0.0, 10.0, 0.01, "s", "time a live change of `gain` takes");

/// `unit`: the output's unit where the gain converts.
const UNIT: Text = Text::new(
    UNIT_PARAM,
    "",
    "unit of the output where the gain converts (e.g. `g` for N → g; shown by `check`); empty: its input's",
);

/// Constant when the gain is 0 (inputs are finite), or of a constant input.
fn fold(f: &FoldArgs<'_>) -> Option<Constant> {
    let g = f.f64(GAIN.name())?;
    if g == 0.0 {
        return Some(Constant::all(1, 0.0, "gain = 0"));
    }
    f.input(IN.index())
        .map(|x| Constant::all(1, (g * x).clamp(-f64::MAX, f64::MAX), format!("gain {g} × constant input {x}")))
}

struct Gain {
    /// The gain at t = 0.
    initial: f64,
    gain: f64,
    /// Where a ramp ends, its step per sample and the samples it has left.
    target: f64,
    delta: f64,
    left: u64,
    ramp_samples: u64,
}

/// The output bound the stability suite checks: |out| ≤ |gain|·max |in| (none when that overflows).
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    let g = b.num(&GAIN.spec());
    (g * b.input_max()).is_finite().then(|| ("out", g.abs() * b.input_max(), "|gain|·max|in|".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let g = GAIN.get(p);
    let ramp_samples = (RAMP.get(p) * ctx.rate).round().max(1.0) as u64;
    Ok(Box::new(Gain { initial: g, gain: g, target: g, delta: 0.0, left: 0, ramp_samples }))
}

impl Node for Gain {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(IN, OUT);
        if self.left == 0 {
            for (y, x) in y.iter_mut().zip(x) {
                *y = (self.gain * x).clamp(-f64::MAX, f64::MAX);
            }
            return Ok(());
        }
        for (y, x) in y.iter_mut().zip(x) {
            if self.left > 0 {
                self.left -= 1;
                self.gain = if self.left == 0 { self.target } else { self.gain + self.delta };
            }
            *y = (self.gain * x).clamp(-f64::MAX, f64::MAX);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.gain = self.initial;
        self.target = self.initial;
        self.left = 0;
    }

    fn set(&mut self, c: Change) -> Result<(), Refused> {
        let Some(value) = GAIN.changed(&c) else { return Err(c.refused()) };
        self.target = value;
        self.left = self.ramp_samples;
        self.delta = (value - self.gain) / self.ramp_samples as f64;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    #[test]
    fn scales_by_the_gain() {
        let x: Vec<f64> = (0..100).map(|i| (i as f64 * 0.1).sin()).collect();
        let out = Single::new(&SPEC, "gain = -2.5")
            .input("in", x.clone(), 1000.0)
            .output("out")
            .ticks(100)
            .block(32)
            .run()
            .unwrap();
        for (y, x) in out[0].iter().zip(&x) {
            assert_eq!(*y, -2.5 * x);
        }
    }

    #[test]
    fn folds_a_zero_gain_and_constant_inputs_but_never_a_live_gain() {
        let params = |g: f64| {
            let mut m = std::collections::BTreeMap::new();
            m.insert("gain".to_string(), evflow_engine::Value::Float(g));
            m.insert("ramp".to_string(), evflow_engine::Value::Float(0.01));
            Params::from_map(m)
        };
        let fold = SPEC.fold.unwrap();
        let (zero, two) = (params(0.0), params(2.0));
        let k = fold(&FoldArgs::new(&SPEC, &zero, &[None], 1, true)).unwrap();
        assert_eq!((k.outputs, k.reason.as_str()), (vec![Some(0.0)], "gain = 0"));
        assert_eq!(fold(&FoldArgs::new(&SPEC, &two, &[Some(-1.5)], 1, true)).unwrap().outputs, [Some(-3.0)]);
        assert!(fold(&FoldArgs::new(&SPEC, &two, &[None], 1, true)).is_none());
        // A plan that takes live changes may not rely on `gain`.
        assert!(fold(&FoldArgs::new(&SPEC, &zero, &[Some(1.0)], 1, false)).is_none());
    }

    #[test]
    fn a_product_beyond_f64_saturates() {
        let y = evflow_engine::harness::Single::new(&SPEC, "gain = -2.0")
            .input("in", vec![f64::MAX, 1e300, -f64::MAX], 1000.0)
            .output("out")
            .ticks(3)
            .block(2)
            .run()
            .unwrap();
        assert_eq!(y[0], [-f64::MAX, -2e300, f64::MAX]);
    }

    #[test]
    fn a_live_change_ramps_linearly_and_lands_exactly() {
        let mut g = Gain { initial: 1.0, gain: 1.0, target: 1.0, delta: 0.0, left: 0, ramp_samples: 4 };
        let x = [2.0; 8];
        let mut y = [0.0; 8];
        let pool = vec![x.to_vec()];
        let run = |g: &mut Gain, y: &mut [f64; 8]| {
            let mut outs = vec![vec![0.0; 8]];
            let mut io = Io::new(&pool, &[0], &[8], &mut outs, &[8], 0);
            g.process(&mut io).unwrap();
            y.copy_from_slice(&outs[0]);
        };
        g.set(Change { param: "gain", value: 0.2 }).unwrap();
        run(&mut g, &mut y);
        for (a, b) in y[..3].iter().zip([1.6, 1.2, 0.8]) {
            assert!((a - b).abs() < 1e-15);
        }
        assert_eq!(y[3], 0.4);
        assert!(y[4..].iter().all(|&v| v == 0.4));
        assert!(g.set(Change { param: "ramp", value: 1.0 }).is_err());
        g.reset();
        run(&mut g, &mut y);
        assert!(y.iter().all(|&v| v == 2.0));
    }
}
