//! Validation: everything about a graph file is checked before any node is
//! constructed — names, parameters, ports, connections, safety, cycles,
//! rates — and every problem is reported with its file, line and node.

mod connections;
pub mod interpolate;
mod names;
mod params;
mod partial;
pub mod prune;
mod rate_hint;
mod topology;
pub mod units;

use crate::diag::{Diagnostic, Diagnostics, Loc};
use crate::graph::Graph;
use crate::params::{Params, Value};
use crate::rate::Ratio;
use crate::registry::Registry;
use crate::spec::{Direction, NodeSpec, RateSpec};
use crate::suggest;
use std::path::PathBuf;

/// A port after `multi` ports were expanded and rates resolved.
#[derive(Debug, Clone)]
pub struct ResolvedPort {
    /// Port name.
    pub name: String,
    /// Input or output.
    pub dir: Direction,
    /// Unit of its samples.
    pub unit: &'static str,
    /// How its rate is declared.
    pub rate: RateSpec,
    /// Its rate relative to the base rate (resolved).
    pub ratio: Ratio,
}

/// A node after validation.
#[derive(Debug, Clone)]
pub struct CheckedNode {
    /// Name in the graph.
    pub name: String,
    /// The name it is built under ([`crate::node::BuildContext::node`]):
    /// its own, or for a shared sweep's copy of a node
    /// ([`crate::sweep_shared`]) its original's — so the copy seeds,
    /// labels and writes exactly as that node would.
    pub origin: String,
    /// Its declaration.
    pub spec: &'static NodeSpec,
    /// Validated parameters (defaults filled, variables substituted).
    pub params: Params,
    /// Ports: inputs and outputs in declaration order.
    pub ports: Vec<ResolvedPort>,
    /// The node's own rate relative to the base rate.
    pub ratio: Ratio,
    /// Where it is declared.
    pub loc: Loc,
}

impl CheckedNode {
    /// Index (among all ports) of the named port with that direction.
    pub fn port(&self, name: &str, dir: Direction) -> Option<usize> {
        self.ports.iter().position(|p| p.name == name && p.dir == dir)
    }
    /// Indices of input ports, in order.
    pub fn inputs(&self) -> impl Iterator<Item = usize> + '_ {
        self.ports.iter().enumerate().filter(|(_, p)| p.dir == Direction::In).map(|(i, _)| i)
    }
    /// Indices of output ports, in order.
    pub fn outputs(&self) -> impl Iterator<Item = usize> + '_ {
        self.ports.iter().enumerate().filter(|(_, p)| p.dir == Direction::Out).map(|(i, _)| i)
    }
}

/// A connection between resolved ports: (node index, port index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// Producer node and its output port index.
    pub from: (usize, usize),
    /// Consumer node and its input port index.
    pub to: (usize, usize),
}

/// A node left out of the plan, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Pruned {
    /// The node.
    pub node: String,
    /// Why it was left out.
    pub reason: String,
}

/// A fully validated graph, ready to be built into a plan.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The graph with command-line overrides applied.
    pub graph: Graph,
    /// Every node, in file order.
    pub nodes: Vec<CheckedNode>,
    /// Every connection.
    pub edges: Vec<Edge>,
    /// Nodes that enter the plan, in execution order.
    pub order: Vec<usize>,
    /// Nodes left out, with the reason.
    pub pruned: Vec<Pruned>,
    /// Cycle-breaking nodes that sit inside a feedback cycle.
    pub in_cycle: Vec<usize>,
}

impl Checked {
    /// Index of the node of that name.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }
    /// True when the node enters the plan.
    pub fn is_live(&self, i: usize) -> bool {
        self.order.contains(&i)
    }
}

/// A command-line override: `name=value` sets a graph variable,
/// `node.param=value` sets one node parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// `name` or `node.param`.
    pub key: String,
    /// The value.
    pub value: Value,
}

impl Override {
    /// Parses `key=value` (value in TOML syntax, or plain text).
    pub fn parse(s: &str) -> Result<Self, String> {
        let (k, v) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected `name=value`"))?;
        let k = k.trim();
        if k.is_empty() {
            return Err(format!("`{s}`: empty name"));
        }
        Ok(Self { key: k.to_string(), value: crate::graph::parse_cli_value(v.trim()) })
    }
}

pub(crate) struct Sink {
    pub file: PathBuf,
    pub diags: Vec<Diagnostic>,
}

impl Sink {
    pub fn err(&mut self, loc: Loc, node: Option<&str>, message: impl Into<String>, help: Option<String>) {
        self.diags.push(Diagnostic {
            file: self.file.clone(),
            loc,
            node: node.map(str::to_string),
            message: message.into(),
            help,
        });
    }
}

/// Validates a parsed graph against the registry, applying overrides.
pub fn check(graph: &Graph, registry: &Registry, overrides: &[Override]) -> Result<Checked, Diagnostics> {
    let mut sink = Sink { file: graph.file.clone(), diags: Vec::new() };
    let graph = apply_overrides(graph, overrides, &mut sink);
    names::sweeps(&graph, &mut sink);
    names::plots(&graph, &mut sink);
    names::nodes(&graph, &mut sink);
    let nodes = check_nodes(&graph, registry, &mut sink);
    let wiring = connections::connect(&graph, &nodes, &mut sink);
    wiring.check_inputs(&nodes, &registry.guard_words(), &mut sink);
    let edges = wiring.edges;

    if !sink.diags.is_empty() {
        // The rate and cycle errors of the rest, so one check reports them all.
        partial::topology_errors(&graph, &nodes, &edges, &mut sink);
        return Err(Diagnostics(sink.diags));
    }
    // Every node that failed validation has reported why; should one not
    // have, it is still an error here, never a panic.
    if let Some(k) = nodes.iter().position(Option::is_none) {
        let d = &graph.nodes[k];
        sink.err(d.loc, Some(&d.name), "this node could not be validated", None);
        return Err(Diagnostics(sink.diags));
    }
    let mut nodes: Vec<CheckedNode> = nodes.into_iter().flatten().collect();
    let topo = topology::analyse(&graph, &mut nodes, &edges, &mut sink);
    if !sink.diags.is_empty() {
        return Err(Diagnostics(sink.diags));
    }
    let (order, pruned, in_cycle) = topo;
    Ok(Checked { graph, nodes, edges, order, pruned, in_cycle })
}

/// Types, parameters, ports: each node checked against its type's spec
/// (`None` where it could not be).
fn check_nodes(graph: &Graph, registry: &Registry, sink: &mut Sink) -> Vec<Option<CheckedNode>> {
    let mut nodes: Vec<Option<CheckedNode>> = Vec::with_capacity(graph.nodes.len());
    for decl in &graph.nodes {
        let Some(spec) = registry.get(&decl.kind) else {
            if let Some(feature) = registry.absent(&decl.kind) {
                let help = format!(
                    "rebuild evflow with its cargo feature `{feature}` (on by default; e.g. `cargo build --release -p evflow --features {feature}`)"
                );
                sink.err(
                    decl.kind_loc,
                    Some(&decl.name),
                    format!("node type `{}` is not in this build of evflow", decl.kind),
                    Some(help),
                );
            } else if !decl.kind.is_empty() {
                let help = suggest::help(&decl.kind, registry.names());
                sink.err(decl.kind_loc, Some(&decl.name), format!("unknown node type `{}`", decl.kind), Some(help));
            }
            nodes.push(None);
            continue;
        };
        let params = params::check_params(decl, spec, &graph.vars, sink);
        let ports = params.as_ref().map(|p| params::resolve_ports(decl, spec, p, sink)).unwrap_or_default();
        nodes.push(params.map(|params| CheckedNode {
            name: decl.name.clone(),
            origin: decl.name.clone(),
            spec,
            params,
            ports,
            ratio: Ratio::ONE,
            loc: decl.loc,
        }));
    }
    nodes
}

fn apply_overrides(graph: &Graph, overrides: &[Override], sink: &mut Sink) -> Graph {
    let mut g = graph.clone();
    let cli = PathBuf::from("<command line>");
    for o in overrides {
        if let Some((node, param)) = o.key.split_once('.') {
            match g.nodes.iter_mut().find(|n| n.name == node) {
                Some(n) => match n.params.iter_mut().find(|p| p.name == param) {
                    Some(p) => p.value = o.value.clone(),
                    None => n.params.push(crate::graph::ParamDecl {
                        name: param.to_string(),
                        value: o.value.clone(),
                        loc: Loc::default(),
                    }),
                },
                None => {
                    let help = suggest::help(node, graph.nodes.iter().map(|n| n.name.as_str()));
                    sink.diags.push(Diagnostic {
                        file: cli.clone(),
                        loc: Loc::default(),
                        node: None,
                        message: format!("--set {}: no node `{node}`", o.key),
                        help: Some(help),
                    });
                }
            }
        } else {
            match g.vars.iter_mut().find(|v| v.name == o.key) {
                Some(v) => v.value = o.value.clone(),
                None => {
                    let help = if graph.vars.is_empty() {
                        "this graph declares no [vars]; use `--set node.param=value` to set a node parameter"
                            .to_string()
                    } else {
                        suggest::help(&o.key, graph.vars.iter().map(|v| v.name.as_str()))
                    };
                    sink.diags.push(Diagnostic {
                        file: cli.clone(),
                        loc: Loc::default(),
                        node: None,
                        message: format!("--set {}: no graph variable `{}`", o.key, o.key),
                        help: Some(help),
                    });
                }
            }
        }
    }
    g
}

#[cfg(test)]
mod tests;
