//! The parsed form of a graph file ([`Graph`] and its parts), before
//! validation; [`super::parse`] reads it from TOML, `save` writes it back.

use super::plot::PlotDecl;
use crate::diag::Loc;
use crate::params::Value;
use std::path::PathBuf;

/// The newest graph format this evflow reads and writes.
pub const FORMAT_VERSION: i64 = 1;

/// A graph file as written, before validation.
#[derive(Debug, Clone, PartialEq)]
pub struct Graph {
    /// The file it came from (for errors; `<memory>` when built in code).
    pub file: PathBuf,
    /// Format version (`[graph] format`).
    pub format: i64,
    /// The graph's name.
    pub name: String,
    /// Optional description.
    pub description: String,
    /// Base rate in Hz: the clock of the live runner; every rate in the graph
    /// is an integer multiple or divisor of it.
    pub rate: f64,
    /// Run length in seconds for graphs whose sources are endless.
    pub duration: Option<f64>,
    /// Seed for every random stream of the run.
    pub seed: u64,
    /// Graph variables (`[vars]`), overridable from the command line.
    pub vars: Vec<Var>,
    /// Sweep axes (`[sweep]`): a run covers every combination of their values.
    pub sweep: Vec<Axis>,
    /// Figures drawn from the results (`[[plot]]`).
    pub plots: Vec<PlotDecl>,
    /// Nodes in file order.
    pub nodes: Vec<NodeDecl>,
    /// Connections in file order.
    pub connections: Vec<Connection>,
    /// Where `[graph]` starts.
    pub loc: Loc,
}

/// A graph variable.
#[derive(Debug, Clone, PartialEq)]
pub struct Var {
    /// Name, used as `"$name"` in parameter values.
    pub name: String,
    /// Value.
    pub value: Value,
    /// Where it is set.
    pub loc: Loc,
}

/// One axis of a sweep: a graph variable and the values it takes in turn
/// (`[sweep]` table, `mass = [60.0, 85.0, 110.0]`), or one value per file
/// matching a pattern (`recording = { files = "recordings/*.json" }`,
/// expanded by [`crate::sweep_files::expand`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The variable swept (declared in `[vars]`).
    pub name: String,
    /// Its values, in order (empty for a files axis not yet expanded).
    pub values: Vec<Value>,
    /// The file pattern of a files axis, relative to the graph's folder.
    pub files: Option<String>,
    /// Per value, the other variables its run sets with it (read from
    /// each file's metadata by a files axis); empty for listed values.
    pub linked: Vec<Vec<(String, Value)>>,
    /// Where it is set.
    pub loc: Loc,
}

/// One node table (`[nodes.NAME]`).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeDecl {
    /// The node's name, unique in the graph.
    pub name: String,
    /// Its type (`type = "butterworth"`).
    pub kind: String,
    /// Where its `type` is written.
    pub kind_loc: Loc,
    /// Parameters in file order.
    pub params: Vec<ParamDecl>,
    /// Where the table starts.
    pub loc: Loc,
}

/// One parameter as written.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamDecl {
    /// Name.
    pub name: String,
    /// Value (possibly a `$variable`).
    pub value: Value,
    /// Where it is written.
    pub loc: Loc,
}

/// One end of a connection.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Endpoint {
    /// Node name.
    pub node: String,
    /// Port name.
    pub port: String,
}

impl std::fmt::Display for Endpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.node, self.port)
    }
}

/// A connection `"a.out -> b.in"`.
#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    /// The output.
    pub from: Endpoint,
    /// The input.
    pub to: Endpoint,
    /// Where it is written.
    pub loc: Loc,
}

impl Graph {
    /// An empty graph at the given base rate (for graphs built in code).
    pub fn new(name: &str, rate: f64) -> Self {
        Self {
            file: PathBuf::from("<memory>"),
            format: FORMAT_VERSION,
            name: name.to_string(),
            description: String::new(),
            rate,
            duration: None,
            seed: 0,
            vars: Vec::new(),
            sweep: Vec::new(),
            plots: Vec::new(),
            nodes: Vec::new(),
            connections: Vec::new(),
            loc: Loc::default(),
        }
    }

    /// Adds a node with parameters given as `(name, value)` pairs.
    pub fn add_node(&mut self, name: &str, kind: &str, params: &[(&str, Value)]) -> &mut Self {
        self.nodes.push(NodeDecl {
            name: name.to_string(),
            kind: kind.to_string(),
            kind_loc: Loc::default(),
            params: params
                .iter()
                .map(|(n, v)| ParamDecl { name: n.to_string(), value: v.clone(), loc: Loc::default() })
                .collect(),
            loc: Loc::default(),
        });
        self
    }

    /// The node declared with that name.
    pub fn node(&self, name: &str) -> Option<&NodeDecl> {
        self.nodes.iter().find(|n| n.name == name)
    }

    /// The same graph with every location cleared (to compare contents).
    pub fn without_locations(&self) -> Graph {
        let mut g = self.clone();
        g.file = PathBuf::new();
        g.loc = Loc::default();
        for v in &mut g.vars {
            v.loc = Loc::default();
        }
        for a in &mut g.sweep {
            a.loc = Loc::default();
        }
        for p in &mut g.plots {
            p.loc = Loc::default();
        }
        for n in &mut g.nodes {
            n.loc = Loc::default();
            n.kind_loc = Loc::default();
            for p in &mut n.params {
                p.loc = Loc::default();
            }
        }
        for c in &mut g.connections {
            c.loc = Loc::default();
        }
        g
    }
}
