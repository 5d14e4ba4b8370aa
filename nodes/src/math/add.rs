//! `add`: the sum of two streams.

use super::binary::Binary;
use evflow_engine::node::Constant;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::FoldArgs;
use evflow_engine::{BuildContext, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `add`.
pub static SPEC: NodeSpec =
    NodeSpec::new("add", "math", Role::Filter, "Sum of two streams, y[n] = a[n] + b[n].", build)
        .doc(
            "Adds two streams sample by sample: e.g. a force and the display's own friction noise, \
to score what a perfect rendering would still carry (the display floor of `graphs/synthesize.toml`, \
docs/narx.md §11). Both inputs and the output run at the node's rate, the rate of its producers. \
Exact to one IEEE addition per sample; a sum beyond the range of f64 saturates at ±f64::MAX \
instead of becoming infinite. Two constant inputs make a constant output, which the planner \
holds (docs/pruning.md).",
        )
        .ports(PORTS)
        .example("")
        .fold(fold);

/// The ports: the two operands and the result.
const PORTS: &[PortSpec] = &[
    PortSpec::input("a", "1", "first term"),
    PortSpec::input("b", "1", "second term"),
    PortSpec::output("out", "1", "a + b"),
];
/// The first operand.
const A: InPort = InPort::named(PORTS, "a");
/// The second operand.
const B: InPort = InPort::named(PORTS, "b");
/// The result.
const OUT: OutPort = OutPort::named(PORTS, "out");

fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Binary { a: A, b: B, out: OUT, op: |a, b| a + b }))
}

/// Constant when both terms are.
fn fold(f: &FoldArgs<'_>) -> Option<Constant> {
    let (a, b) = (f.input(A.index())?, f.input(B.index())?);
    Some(Constant::all(1, super::binary::saturate(a + b), format!("{a} + {b}, both constant")))
}
