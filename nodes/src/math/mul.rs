//! `mul`: the product of two streams.

use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `mul`.
pub static SPEC: NodeSpec =
    NodeSpec::new("mul", "math", Role::Filter, "Product of two streams, y[n] = a[n] · b[n].", build)
        .doc(
            "Multiplies two streams sample by sample: an actuation waveform by an intensity or a \
gate (dissertation §3.1.2: a haptic effect switched on in one segment of eight; §4.1: a grain scaled \
by the rendered intensity). Both inputs and the output run at the node's rate, the rate of its \
producers. Exact: one IEEE multiplication per sample.",
        )
        .ports(&[
            PortSpec::input("a", "1", "first factor"),
            PortSpec::input("b", "1", "second factor"),
            PortSpec::output("out", "1", "a · b"),
        ])
        .example("");

struct Mul;

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Mul))
}

impl Node for Mul {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        for k in 0..n {
            let v = io.input(0)[k] * io.input(1)[k];
            io.output(0)[k] = v;
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
    fn multiplies_sample_by_sample() {
        let a: Vec<f64> = (0..50).map(|i| i as f64 * 0.5).collect();
        let b: Vec<f64> = (0..50).map(|i| if i % 3 == 0 { -2.0 } else { 1.0 }).collect();
        let y = Single {
            spec: &SPEC,
            params: "",
            inputs: vec![("a", a.clone(), 1000.0), ("b", b.clone(), 1000.0)],
            outputs: vec!["out"],
            base_rate: 1000.0,
            ticks: 50,
            block: 7,
            base_dir: Path::new("."),
        }
        .run()
        .unwrap()
        .remove(0);
        for k in 0..50 {
            assert_eq!(y[k], a[k] * b[k]);
        }
    }
}
