//! `gain`: multiplies a stream by a constant.

use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, ParamSpec, Params, PortSpec, Role};

/// Declaration of `gain`.
pub static SPEC: NodeSpec =
    NodeSpec::new("gain", "output", Role::Filter, "Multiplies a stream by a constant gain.", build)
        .doc(
            "y[n] = g · x[n]. Used to scale synthesized actuation signals before the display \
         (the gain sweep 0.6–1.4 of dissertation §5.3.1, Table 5.1; 1.0 corresponds to 100 Vpp \
         through the amplifier). Runs at the rate of its input.",
        )
        .ports(&[PortSpec::input("in", "1", "signal"), PortSpec::output("out", "1", "signal × gain")])
        .params(&[ParamSpec::float("gain", -1e6, 1e6, 1.0, "1", "multiplier")])
        .example("gain = 1.2");

struct Gain {
    gain: f64,
}

fn build(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Gain { gain: p.f64("gain") }))
}

impl Node for Gain {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(0, 0);
        for (y, x) in y.iter_mut().zip(x) {
            *y = self.gain * x;
        }
        Ok(())
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use std::path::Path;

    #[test]
    fn scales_by_the_gain() {
        let x: Vec<f64> = (0..100).map(|i| (i as f64 * 0.1).sin()).collect();
        let out = Single {
            spec: &SPEC,
            params: "gain = -2.5",
            inputs: vec![("in", x.clone(), 1000.0)],
            outputs: vec!["out"],
            base_rate: 1000.0,
            ticks: 100,
            block: 32,
            base_dir: Path::new("."),
        }
        .run()
        .unwrap();
        for (y, x) in out[0].iter().zip(&x) {
            assert_eq!(*y, -2.5 * x);
        }
    }
}
