//! Graphviz output of a checked graph (`evflow dot`).

use crate::check::Checked;
use std::fmt::Write;

/// The graph in Graphviz `dot` syntax: nodes labelled with type and rate,
/// edges with port names; pruned nodes dashed and grey.
pub fn to_dot(c: &Checked) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "digraph {:?} {{", c.graph.name);
    let _ = writeln!(s, "  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];");
    for (i, n) in c.nodes.iter().enumerate() {
        let style = if c.is_live(i) { "" } else { ", style=dashed, color=grey, fontcolor=grey" };
        let _ = writeln!(
            s,
            "  {:?} [label=\"{}\\n{} · {} Hz\"{style}];",
            n.name,
            n.name,
            n.spec.name,
            n.ratio.hz(c.graph.rate)
        );
    }
    for e in &c.edges {
        let a = &c.nodes[e.from.0];
        let b = &c.nodes[e.to.0];
        let _ = writeln!(
            s,
            "  {:?} -> {:?} [label=\"{} → {}\"];",
            a.name, b.name, a.ports[e.from.1].name, b.ports[e.to.1].name
        );
    }
    s.push_str("}\n");
    s
}
