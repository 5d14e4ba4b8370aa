//! `add`: the sum of two streams.

use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `add`.
pub static SPEC: NodeSpec =
    NodeSpec::new("add", "math", Role::Filter, "Sum of two streams, y[n] = a[n] + b[n].", build)
        .doc(
            "Adds two streams sample by sample: e.g. a force and the display's own friction noise, \
to score what a perfect rendering would still carry (the display floor of `graphs/synthesize.toml`, \
docs/narx.md §11). Both inputs and the output run at the node's rate, the rate of its producers. \
Exact to one IEEE addition per sample.",
        )
        .ports(&[
            PortSpec::input("a", "1", "first term"),
            PortSpec::input("b", "1", "second term"),
            PortSpec::output("out", "1", "a + b"),
        ])
        .example("");

struct Add;

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Add))
}

impl Node for Add {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        for k in 0..n {
            let v = io.input(0)[k] + io.input(1)[k];
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
    fn adds_sample_by_sample() {
        let a: Vec<f64> = (0..50).map(|i| i as f64 * 0.5).collect();
        let b: Vec<f64> = (0..50).map(|i| if i % 3 == 0 { -2.0 } else { 1e-17 }).collect();
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
            assert_eq!(y[k], a[k] + b[k]);
        }
    }
}
