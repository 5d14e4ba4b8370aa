//! The errors a graph's topology would add when its nodes or connections
//! already have some: feedback cycles and rates, checked over the nodes
//! that did validate, so that one `evflow check` reports every error it can
//! rather than the next batch only after the first is fixed.
//!
//! Only what the errors found so far cannot have caused is kept: an error
//! at a node that failed validation, that lost one of its connections, or
//! that lies downstream of either (its rate may follow theirs) is dropped,
//! and so is the graph-wide "no sink" (a sink may be among the failed).

use super::{topology, CheckedNode, Edge, Sink};
use crate::graph::Graph;

/// Adds to `sink` the topology errors of the validated part of `graph`
/// (`nodes[k]` is `None` where node `k` failed) that the errors already in
/// `sink` cannot explain.
pub(super) fn topology_errors(graph: &Graph, nodes: &[Option<CheckedNode>], edges: &[Edge], sink: &mut Sink) {
    let tainted = tainted(graph, nodes, edges);
    // The validated nodes, renumbered, and the edges between them.
    let mut index = vec![usize::MAX; nodes.len()];
    let mut sub: Vec<CheckedNode> = Vec::new();
    for (k, n) in nodes.iter().enumerate() {
        if let Some(n) = n {
            index[k] = sub.len();
            sub.push(n.clone());
        }
    }
    let sub_edges: Vec<Edge> = edges
        .iter()
        .filter(|e| index[e.from.0] != usize::MAX && index[e.to.0] != usize::MAX)
        .map(|e| Edge { from: (index[e.from.0], e.from.1), to: (index[e.to.0], e.to.1) })
        .collect();
    let mut more = Sink { file: sink.file.clone(), diags: Vec::new() };
    topology::analyse(graph, &mut sub, &sub_edges, &mut more);
    let clean = |name: &str| graph.nodes.iter().position(|d| d.name == name).is_some_and(|k| !tainted[k]);
    sink.diags.extend(more.diags.into_iter().filter(|d| d.node.as_deref().is_some_and(clean)));
}

/// Per declared node: failed, lost an incoming connection, or downstream
/// of such a node along the declared connections.
fn tainted(graph: &Graph, nodes: &[Option<CheckedNode>], edges: &[Edge]) -> Vec<bool> {
    let at = |name: &str| graph.nodes.iter().position(|d| d.name == name);
    let mut bad: Vec<bool> = nodes.iter().map(Option::is_none).collect();
    for (k, d) in graph.nodes.iter().enumerate() {
        let declared = graph.connections.iter().filter(|c| c.to.node == d.name).count();
        let made = edges.iter().filter(|e| e.to.0 == k).count();
        if made < declared {
            bad[k] = true;
        }
    }
    // Downstream, to a fixed point (graphs are small; cycles terminate).
    let mut changed = true;
    while changed {
        changed = false;
        for c in &graph.connections {
            if let (Some(a), Some(b)) = (at(&c.from.node), at(&c.to.node)) {
                if bad[a] && !bad[b] {
                    bad[b] = true;
                    changed = true;
                }
            }
        }
    }
    bad
}
