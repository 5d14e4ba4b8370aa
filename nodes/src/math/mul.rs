//! `mul`: the product of two streams.

use super::binary::Binary;
use evflow_engine::{BuildContext, Node, NodeError, NodeSpec, Params, PortSpec, Role};

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

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Binary(|a, b| a * b)))
}
