//! The graph's connections: each resolved to a producer's output and a
//! consumer's input, every input fed exactly once, and hardware fed only
//! through a safety guard.

use super::{CheckedNode, Edge, Sink};
use crate::diag::Loc;
use crate::graph::{Endpoint, Graph};
use crate::spec::Direction;
use crate::suggest;

/// Each node's inputs' producer: its index, the connection's place and
/// the producing endpoint.
type Producers = Vec<Vec<Option<(usize, Loc, Endpoint)>>>;

/// The connections found: the edges, each input's producer, and the inputs
/// named by a connection (resolved or not).
pub(super) struct Wiring {
    /// One per resolved connection.
    pub edges: Vec<Edge>,
    /// By node, then port.
    producer: Producers,
    /// Inputs fed by a connection that could not be resolved (already
    /// reported) must not also be reported as having no producer.
    covered: Vec<(String, String)>,
}

/// Resolves the connections into edges, reporting unknown endpoints and
/// inputs with two producers.
pub(super) fn connect(graph: &Graph, nodes: &[Option<CheckedNode>], sink: &mut Sink) -> Wiring {
    let mut edges = Vec::new();
    let mut producer: Producers =
        nodes.iter().map(|n| n.as_ref().map(|n| vec![None; n.ports.len()]).unwrap_or_default()).collect();
    let mut covered: Vec<(String, String)> = Vec::new();
    for c in &graph.connections {
        covered.push((c.to.node.clone(), c.to.port.clone()));
        let from = endpoint(graph, nodes, &c.from, Direction::Out, c.loc, sink);
        let to = endpoint(graph, nodes, &c.to, Direction::In, c.loc, sink);
        if let (Some(f), Some(t)) = (from, to) {
            match &producer[t.0][t.1] {
                Some((_, first_loc, first)) => {
                    let msg = format!(
                        "input `{}` has two producers: `{}` (line {}) and `{}`",
                        c.to, first, first_loc.line, c.from
                    );
                    sink.err(
                        c.loc,
                        Some(&c.to.node),
                        msg,
                        Some("an input takes exactly one producer; add a node that combines them".into()),
                    );
                }
                None => {
                    producer[t.0][t.1] = Some((f.0, c.loc, c.from.clone()));
                    edges.push(Edge { from: f, to: t });
                }
            }
        }
    }
    Wiring { edges, producer, covered }
}

impl Wiring {
    /// Reports inputs without a producer and hardware inputs not fed by a
    /// safety guard's first output.
    /// `guards` names the registry's safety guards ([`crate::Registry::guard_words`]).
    pub(super) fn check_inputs(&self, nodes: &[Option<CheckedNode>], guards: &str, sink: &mut Sink) {
        let producer = &self.producer;
        for (i, n) in nodes.iter().enumerate() {
            let Some(n) = n else { continue };
            for p in n.inputs() {
                if producer[i][p].is_none()
                    && !self.covered.iter().any(|(nn, pp)| *nn == n.name && *pp == n.ports[p].name)
                {
                    sink.err(
                        n.loc,
                        Some(&n.name),
                        format!("input `{}.{}` has no producer", n.name, n.ports[p].name),
                        Some(format!("connect an output to it: \"SOURCE.out -> {}.{}\"", n.name, n.ports[p].name)),
                    );
                }
            }
            if n.spec.hardware {
                for p in n.inputs() {
                    if let Some((src, _, from)) = &producer[i][p] {
                        // Only a guard's first output is the guarded signal (the
                        // others, like `limit.state`, are for monitoring).
                        let guarded = nodes[*src].as_ref().is_some_and(|s| {
                            s.spec.is_guard() && s.outputs().next().is_some_and(|o| s.ports[o].name == from.port)
                        });
                        if !guarded {
                            sink.err(
                                n.loc,
                                Some(&n.name),
                                format!(
                                    "hardware output `{}.{}` is not fed by a {guards} node",
                                    n.name, n.ports[p].name
                                ),
                                Some(format!(
                                    "every signal that reaches hardware must pass a {guards} node (amplitude clamp, \
                                     slew limit, ramp to zero on faults)"
                                )),
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Resolves one end of a connection to (node, port), reporting an unknown
/// node or port, or a port of the wrong direction.
fn endpoint(
    graph: &Graph,
    nodes: &[Option<CheckedNode>],
    e: &Endpoint,
    dir: Direction,
    loc: Loc,
    sink: &mut Sink,
) -> Option<(usize, usize)> {
    let Some(i) = graph.nodes.iter().position(|n| n.name == e.node) else {
        let help = suggest::help(&e.node, graph.nodes.iter().map(|n| n.name.as_str()));
        sink.err(loc, None, format!("connection names unknown node `{}`", e.node), Some(help));
        return None;
    };
    let n = nodes[i].as_ref()?;
    if let Some(p) = n.port(&e.port, dir) {
        return Some((i, p));
    }
    let (what, other) = match dir {
        Direction::Out => ("output", "an input"),
        Direction::In => ("input", "an output"),
    };
    if n.ports.iter().any(|p| p.name == e.port) {
        sink.err(
            loc,
            Some(&e.node),
            format!("`{e}` is {other}, not {}", if dir == Direction::Out { "an output" } else { "an input" }),
            Some("connections go \"producer.output -> consumer.input\"".into()),
        );
        return None;
    }
    let names: Vec<&str> = n.ports.iter().filter(|p| p.dir == dir).map(|p| p.name.as_str()).collect();
    let help = suggest::help(&e.port, names.iter().copied());
    sink.err(loc, Some(&e.node), format!("node type `{}` has no {what} port `{}`", n.spec.name, e.port), Some(help));
    None
}
