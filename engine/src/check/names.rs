//! What the graph's names refer to: sweep axes name declared variables,
//! plots name known quantities, and no two nodes share a name.

use super::Sink;
use crate::graph::Graph;
use crate::suggest;

/// Sweep axes name declared variables, once each.
pub(super) fn sweeps(graph: &Graph, sink: &mut Sink) {
    for (i, a) in graph.sweep.iter().enumerate() {
        if graph.sweep[..i].iter().any(|b| b.name == a.name) {
            sink.err(a.loc, None, format!("sweep `{}` is given twice", a.name), None);
        } else if !graph.vars.iter().any(|v| v.name == a.name) {
            let help = if graph.vars.is_empty() {
                format!("declare it in [vars] (e.g. `{} = …`), then sweep it", a.name)
            } else {
                suggest::help(&a.name, graph.vars.iter().map(|v| v.name.as_str()))
            };
            sink.err(a.loc, None, format!("sweep `{}`: no graph variable `{}`", a.name, a.name), Some(help));
        }
    }
}

/// Plots name variables, nodes' reported values or run times.
pub(super) fn plots(graph: &Graph, sink: &mut Sink) {
    for p in &graph.plots {
        let known = |q: &str| -> bool {
            q == "seconds"
                || graph.vars.iter().any(|v| v.name == q)
                || q.split_once('.').is_some_and(|(n, v)| !v.is_empty() && graph.nodes.iter().any(|d| d.name == n))
        };
        for q in std::iter::once(&p.x).chain(&p.y) {
            if !known(q) {
                let names =
                    graph.vars.iter().map(|v| v.name.as_str()).chain(graph.nodes.iter().map(|n| n.name.as_str()));
                let help = format!(
                    "a quantity is a graph variable, `NODE.VALUE` (a value the node reports), `NODE.time` or `seconds`; {}",
                    suggest::help(q.split('.').next().unwrap_or(q), names)
                );
                sink.err(p.loc, None, format!("plot `{}`: unknown quantity `{q}`", p.file), Some(help));
            }
        }
        if !p.series.is_empty() && !graph.vars.iter().any(|v| v.name == p.series) {
            let help = suggest::help(&p.series, graph.vars.iter().map(|v| v.name.as_str()));
            sink.err(
                p.loc,
                None,
                format!("plot `{}`: `series` names no graph variable `{}`", p.file, p.series),
                Some(help),
            );
        }
    }
}

/// No two nodes share a name.
pub(super) fn nodes(graph: &Graph, sink: &mut Sink) {
    for (i, n) in graph.nodes.iter().enumerate() {
        if graph.nodes[..i].iter().any(|m| m.name == n.name) {
            sink.err(n.loc, Some(&n.name), "a node of this name is declared twice", None);
        }
    }
}
