//! Topology: feedback cycles, pruning and rates.

use super::{rate_hint, CheckedNode, Edge, Pruned, Sink};
use crate::graph::{Endpoint, Graph};
use crate::rate::Ratio;
use crate::spec::{Direction, RateSpec, Role};
use petgraph::algo::{kosaraju_scc, toposort};
use petgraph::graph::{DiGraph, NodeIndex};

type Analysis = (Vec<usize>, Vec<Pruned>, Vec<usize>);

/// Orders the nodes, finds what to leave out, and resolves every port's rate.
pub(super) fn analyse(graph: &Graph, nodes: &mut [CheckedNode], edges: &[Edge], sink: &mut Sink) -> Analysis {
    let n = nodes.len();
    let mut full: DiGraph<usize, ()> = DiGraph::with_capacity(n, edges.len());
    let mut reduced: DiGraph<usize, ()> = DiGraph::with_capacity(n, edges.len());
    for i in 0..n {
        full.add_node(i);
        reduced.add_node(i);
    }
    for e in edges {
        full.add_edge(NodeIndex::new(e.from.0), NodeIndex::new(e.to.0), ());
        if !nodes[e.to.0].spec.breaks_cycles {
            reduced.add_edge(NodeIndex::new(e.from.0), NodeIndex::new(e.to.0), ());
        }
    }

    // Cycles must pass through a cycle-breaking node.
    let topo: Vec<usize> = match toposort(&reduced, None) {
        Ok(order) => order.into_iter().map(|ix| ix.index()).collect(),
        Err(_) => {
            for scc in kosaraju_scc(&reduced) {
                let looped = scc.len() > 1 || reduced.contains_edge(scc[0], scc[0]);
                if looped {
                    let mut names: Vec<&str> = scc.iter().map(|ix| nodes[ix.index()].name.as_str()).collect();
                    names.sort_unstable();
                    let first = scc.iter().map(|ix| ix.index()).min().unwrap_or(0);
                    sink.err(
                        nodes[first].loc,
                        Some(&nodes[first].name),
                        format!("feedback cycle through {} is not broken by a `delay`", names.join(", ")),
                        Some("a cycle must pass through a `delay` node of at least one sample".into()),
                    );
                }
            }
            return (Vec::new(), Vec::new(), Vec::new());
        }
    };
    let mut in_cycle = Vec::new();
    for scc in kosaraju_scc(&full) {
        let looped = scc.len() > 1 || full.contains_edge(scc[0], scc[0]);
        if looped {
            in_cycle.extend(scc.iter().map(|ix| ix.index()).filter(|&i| nodes[i].spec.breaks_cycles));
        }
    }
    in_cycle.sort_unstable();

    resolve_rates(graph, nodes, edges, &topo, sink);

    // Pruning: keep what can reach a sink (constants are the planner's, super::prune).
    let is_sink = |i: usize| nodes[i].spec.role == Role::Sink;
    if !(0..n).any(is_sink) {
        sink.err(
            graph.loc,
            None,
            "the graph has no sink, so running it would have no effect",
            Some("add a sink such as `recording.out` or `metric`; `evflow nodes` lists them".into()),
        );
    }
    let live = super::prune::needed(n, edges, is_sink, |_| true);
    let pruned = (0..n)
        .filter(|&i| !live[i])
        .map(|i| Pruned { node: nodes[i].name.clone(), reason: "no sink is reachable from it".into() })
        .collect();
    let order = topo.into_iter().filter(|&i| live[i]).collect();
    (order, pruned, in_cycle)
}

fn resolve_rates(graph: &Graph, nodes: &mut [CheckedNode], edges: &[Edge], topo: &[usize], sink: &mut Sink) {
    let mut resolved = vec![false; nodes.len()];
    for &i in topo {
        let ratio = node_ratio(graph, nodes, edges, &resolved, i, sink);
        let port_ratios = port_ratios(graph, nodes, edges, &resolved, i, ratio, sink);
        let node = &mut nodes[i];
        node.ratio = ratio;
        for (p, r) in node.ports.iter_mut().zip(port_ratios) {
            p.ratio = r;
        }
        resolved[i] = true;
    }
    check_connection_rates(graph, nodes, edges, sink);
}

/// The ratio of `hz` to the base rate. A rate that does not fit is
/// reported at the line of the parameter that sets it, with the nearest
/// rates that fit (and taken as the base rate).
fn ratio_of(graph: &Graph, hz: f64, node: &CheckedNode, what: &str, param: &str, sink: &mut Sink) -> Ratio {
    let base = graph.rate;
    match Ratio::of(hz, base) {
        Some(r) => r,
        None => {
            let loc = (graph.nodes.iter().find(|d| d.name == node.name))
                .and_then(|d| d.params.iter().find(|p| p.name == param))
                .map_or(node.loc, |p| p.loc);
            sink.err(
                loc,
                Some(&node.name),
                format!(
                    "{what} runs at {hz} Hz (`{param}`), which is not an integer multiple or divisor of the base rate {base} Hz"
                ),
                Some(rate_hint::fitting_help(hz, base)),
            );
            Ratio::ONE
        }
    }
}

/// The rate of what feeds input `port` of node `i`, once its producer's
/// rates are resolved.
fn producer_ratio(edges: &[Edge], i: usize, port: usize, nodes: &[CheckedNode], resolved: &[bool]) -> Option<Ratio> {
    edges
        .iter()
        .find(|e| e.to == (i, port))
        .filter(|e| resolved[e.from.0])
        .map(|e| nodes[e.from.0].ports[e.from.1].ratio)
}

/// Node `i`'s own rate: its inputs' at the node's rate, else its rate
/// parameter's, else its any-rate inputs', else the base rate.
fn node_ratio(
    graph: &Graph,
    nodes: &[CheckedNode],
    edges: &[Edge],
    resolved: &[bool],
    i: usize,
    sink: &mut Sink,
) -> Ratio {
    let node = &nodes[i];
    let from_inputs = |rate: RateSpec| {
        node.ports
            .iter()
            .enumerate()
            .filter(|(_, p)| p.dir == Direction::In && p.rate == rate)
            .find_map(|(k, _)| producer_ratio(edges, i, k, nodes, resolved))
    };
    if let Some(r) = from_inputs(RateSpec::Node) {
        r
    } else if let Some(p) = node.spec.rate_param {
        let hz = node.params.f64(p);
        ratio_of(graph, hz, node, "the node", p, sink)
    } else if let Some(r) = from_inputs(RateSpec::Any) {
        r
    } else {
        Ratio::ONE
    }
}

/// The rate of each port of node `i`, whose own rate is `ratio`.
fn port_ratios(
    graph: &Graph,
    nodes: &[CheckedNode],
    edges: &[Edge],
    resolved: &[bool],
    i: usize,
    ratio: Ratio,
    sink: &mut Sink,
) -> Vec<Ratio> {
    let node = &nodes[i];
    let mut port_ratios = Vec::with_capacity(node.ports.len());
    for (k, p) in node.ports.iter().enumerate() {
        let r = match p.rate {
            RateSpec::Node => ratio,
            RateSpec::Param(name) => {
                ratio_of(graph, node.params.f64(name), node, &format!("port `{}`", p.name), name, sink)
            }
            RateSpec::Any => producer_ratio(edges, i, k, nodes, resolved).unwrap_or(ratio),
        };
        port_ratios.push(r);
    }
    port_ratios
}

/// Every connection joins equal rates (inputs of any rate take their
/// producer's); a mismatch is reported at the connection.
fn check_connection_rates(graph: &Graph, nodes: &mut [CheckedNode], edges: &[Edge], sink: &mut Sink) {
    let base = graph.rate;
    for e in edges {
        let out = nodes[e.from.0].ports[e.from.1].ratio;
        let inp = &nodes[e.to.0].ports[e.to.1];
        if inp.rate == RateSpec::Any {
            nodes[e.to.0].ports[e.to.1].ratio = out;
            continue;
        }
        if inp.ratio != out {
            let (producer, consumer) = (&nodes[e.from.0], &nodes[e.to.0]);
            let from = Endpoint { node: producer.name.clone(), port: producer.ports[e.from.1].name.clone() };
            let to = Endpoint { node: consumer.name.clone(), port: inp.name.clone() };
            let c = graph.connections.iter().find(|c| c.from == from && c.to == to);
            let loc = c.map(|c| c.loc).unwrap_or(consumer.loc);
            sink.err(
                loc,
                Some(&consumer.name),
                format!(
                    "rate mismatch: `{}.{}` runs at {} Hz but `{}.{}` at {} Hz",
                    from.node,
                    from.port,
                    out.hz(base),
                    to.node,
                    to.port,
                    inp.ratio.hz(base)
                ),
                Some(rate_hint::help(graph, &from, &to, out, inp.ratio)),
            );
        }
    }
}
