//! `mul`: the product of two streams.

use super::binary::Binary;
use evflow_engine::node::Constant;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::FoldArgs;
use evflow_engine::{BuildContext, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `mul`.
pub static SPEC: NodeSpec =
    NodeSpec::new("mul", "math", Role::Filter, "Product of two streams, y[n] = a[n] · b[n].", build)
        .doc(
            "Multiplies two streams sample by sample: an actuation waveform by an intensity or a \
gate (dissertation §3.1.2: a haptic effect switched on in one segment of eight; §4.1: a grain scaled \
by the rendered intensity). Both inputs and the output run at the node's rate, the rate of its \
producers. Exact: one IEEE multiplication per sample; a product beyond the range of f64 saturates at \
±f64::MAX instead of becoming infinite. A constant 0 on either input (the other is finite, as \
every node's output is) or two constant inputs make a constant output, which the planner holds and \
leaves out what fed only the other input (docs/pruning.md).",
        )
        .ports(PORTS)
        .example("")
        .fold(fold);

/// The ports: the two operands and the result.
const PORTS: &[PortSpec] = &[
    PortSpec::input("a", "1", "first factor"),
    PortSpec::input("b", "1", "second factor"),
    PortSpec::output("out", "1", "a · b"),
];
/// The first operand.
const A: InPort = InPort::named(PORTS, "a");
/// The second operand.
const B: InPort = InPort::named(PORTS, "b");
/// The result.
const OUT: OutPort = OutPort::named(PORTS, "out");

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Binary { a: A, b: B, out: OUT, op: |a, b| a * b }))
}

/// Constant when either factor is a constant 0, or both are constant.
fn fold(f: &FoldArgs<'_>) -> Option<Constant> {
    match (f.input(A.index()), f.input(B.index())) {
        (Some(a), Some(b)) => {
            Some(Constant::all(1, super::binary::saturate(a * b), format!("{a} · {b}, both constant")))
        }
        (Some(z), _) | (_, Some(z)) if z == 0.0 => Some(Constant::all(1, 0.0, "a factor is a constant 0")),
        _ => None,
    }
}
