//! The unit of every output of a checked graph, as `check` shows it: the
//! declared unit, or for a [`SAME_AS_INPUT`] output the unit of what feeds
//! the node's first input, followed upstream (or the node's
//! [`UNIT_PARAM`] when set).

use super::{Checked, Direction};
use crate::params::Value;
use crate::ports::{SAME_AS_INPUT, UNIT_PARAM};

/// Shown for an output whose unit cannot be followed (nothing feeds the
/// node, or a feedback cycle).
pub const UNKNOWN: &str = "?";

/// The unit of output port `port` of node `node` (indices as in
/// [`Checked::nodes`] and its `ports`).
pub fn output_unit(c: &Checked, node: usize, port: usize) -> String {
    let mut seen = Vec::new();
    follow(c, node, port, &mut seen)
}

fn follow(c: &Checked, node: usize, port: usize, seen: &mut Vec<usize>) -> String {
    let n = &c.nodes[node];
    let declared = n.ports[port].unit;
    if declared != SAME_AS_INPUT {
        return declared.to_string();
    }
    if let Some(Value::Text(u)) = n.params.get(UNIT_PARAM) {
        if !u.is_empty() {
            return u.clone();
        }
    }
    if seen.contains(&node) {
        return UNKNOWN.into();
    }
    seen.push(node);
    feeding(c, node, seen)
}

/// The unit of what feeds node `node`'s first input, followed upstream
/// ([`UNKNOWN`] when nothing feeds it): the unit a sink reports values in
/// when it declares them [`SAME_AS_INPUT`] (`stats`' mean, RMS, …).
pub fn input_unit(c: &Checked, node: usize) -> String {
    feeding(c, node, &mut vec![node])
}

fn feeding(c: &Checked, node: usize, seen: &mut Vec<usize>) -> String {
    let n = &c.nodes[node];
    let first_input = n.ports.iter().position(|p| p.dir == Direction::In);
    let source = first_input.and_then(|i| c.edges.iter().find(|e| e.to == (node, i)));
    match source {
        Some(e) => follow(c, e.from.0, e.from.1, seen),
        None => UNKNOWN.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::parse_graph;
    use crate::harness::TAP;
    use crate::node::{BuildContext, Node, NodeError};
    use crate::params::Params;
    use crate::spec::{NodeSpec, ParamSpec, PortSpec, Role};
    use crate::Registry;
    use std::path::Path;

    fn never(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Err(NodeError::Other("not built in these tests".into()))
    }

    static FORCE: NodeSpec =
        NodeSpec::new("force", "test", Role::Source, "a force", never).ports(&[PortSpec::output("out", "N", "force")]);
    static SCALE: NodeSpec = NodeSpec::new("scale", "test", Role::Filter, "a gain", never)
        .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", SAME_AS_INPUT, "x")])
        .params(&[ParamSpec::text(UNIT_PARAM, "", "the unit where it converts")]);

    fn units(doc: &str) -> Vec<(String, String)> {
        let mut reg = Registry::new();
        reg.add(&FORCE).add(&SCALE).add(&TAP);
        let c = crate::check::check(&parse_graph(Path::new("u.toml"), doc).unwrap(), &reg, &[]).unwrap();
        let mut v: Vec<(String, String)> = (0..c.nodes.len())
            .filter_map(|i| c.nodes[i].outputs().next().map(|k| (c.nodes[i].name.clone(), output_unit(&c, i, k))))
            .collect();
        v.sort();
        v
    }

    #[test]
    fn an_output_as_its_input_follows_upstream_until_a_node_names_its_unit() {
        let doc = "[graph]\nformat = 1\nname = \"u\"\nrate = 1000\n\
                   connections = [\"f.out -> a.in\", \"a.out -> b.in\", \"b.out -> c.in\", \"c.out -> t.in\"]\n\
                   [nodes.f]\ntype = \"force\"\n[nodes.a]\ntype = \"scale\"\n\
                   [nodes.b]\ntype = \"scale\"\nunit = \"g\"\n[nodes.c]\ntype = \"scale\"\n\
                   [nodes.t]\ntype = \"harness.tap\"\n";
        let want = [("a", "N"), ("b", "g"), ("c", "g"), ("f", "N")];
        let got = units(doc);
        assert_eq!(got, want.map(|(a, b)| (a.to_string(), b.to_string())));
    }

    #[test]
    fn a_sink_reports_in_the_unit_of_what_feeds_it() {
        let doc = "[graph]\nformat = 1\nname = \"u\"\nrate = 1000\n\
                   connections = [\"f.out -> a.in\", \"a.out -> t.in\", \"f.out -> b.in\", \"b.out -> s.in\"]\n\
                   [nodes.f]\ntype = \"force\"\n[nodes.a]\ntype = \"scale\"\n\
                   [nodes.b]\ntype = \"scale\"\nunit = \"g\"\n\
                   [nodes.t]\ntype = \"harness.tap\"\n[nodes.s]\ntype = \"harness.tap\"\n";
        let mut reg = Registry::new();
        reg.add(&FORCE).add(&SCALE).add(&TAP);
        let c = crate::check::check(&parse_graph(Path::new("u.toml"), doc).unwrap(), &reg, &[]).unwrap();
        assert_eq!(input_unit(&c, c.index("t").unwrap()), "N");
        assert_eq!(input_unit(&c, c.index("s").unwrap()), "g");
        assert_eq!(input_unit(&c, c.index("f").unwrap()), UNKNOWN, "a source has no input");
    }
}
