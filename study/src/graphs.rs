//! Running the shipped graphs from a study: load with the node library and
//! typed overrides ([`Sets`], what `--set` gives the engine), plan, run
//! offline, keep the report — the one way every study runs a graph.
//!
//! [`run_graph`] and [`run_graph_for`] run a graph file into an output
//! folder; [`read`] and [`run`] let a study add probes to a graph (e.g. a
//! reference node and an `error` sink) before running it, and run it with no
//! output folder at all when it writes nothing.

use evflow_engine::sweep_shared;
use evflow_engine::{
    check, read_graph, run_offline, Checked, Graph, Override, Plan, PlanOptions, RunMode, RunOptions, RunReport, Value,
};
use std::path::{Path, PathBuf};

/// Why a graph could not be loaded or run, or did not report what a study reads.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {message}")]
pub struct GraphError {
    /// The graph file.
    pub file: PathBuf,
    /// What went wrong.
    pub message: String,
}

impl GraphError {
    fn new(file: &Path, message: String) -> Self {
        Self { file: file.to_path_buf(), message }
    }
}

/// The values a study sets on a graph (`name` for a `[vars]` variable,
/// `node.param` for a parameter), typed: what `--set name=value` gives
/// the engine, without writing text for the engine to parse again.
#[derive(Debug, Clone, Default)]
pub struct Sets(Vec<Override>);

impl Sets {
    /// No values.
    pub fn new() -> Self {
        Self::default()
    }

    fn with(mut self, key: &str, value: Value) -> Self {
        self.0.push(Override { key: key.to_string(), value });
        self
    }

    /// A real number.
    pub fn num(self, key: &str, v: f64) -> Self {
        self.with(key, Value::Float(v))
    }

    /// An integer (counts, seeds, repetitions).
    pub fn int(self, key: &str, v: impl Into<i64>) -> Self {
        self.with(key, Value::Int(v.into()))
    }

    /// A switch.
    pub fn flag(self, key: &str, v: bool) -> Self {
        self.with(key, Value::Bool(v))
    }

    /// Text (a sample name, a choice, a file name inside the output folder).
    pub fn text(self, key: &str, v: &str) -> Self {
        self.with(key, Value::Text(v.to_string()))
    }

    /// A file or folder.
    pub fn path(self, key: &str, p: &Path) -> Self {
        self.text(key, &p.display().to_string())
    }

    /// A list of numbers.
    pub fn nums(self, key: &str, v: &[f64]) -> Self {
        self.with(key, Value::FloatList(v.to_vec()))
    }

    /// A list of words (e.g. the scenes of a mesh node).
    pub fn words(self, key: &str, v: &[&str]) -> Self {
        self.with(key, Value::TextList(v.iter().map(|w| w.to_string()).collect()))
    }

    /// These values, then `more`'s (a later value for the same key wins).
    pub fn and(mut self, more: Sets) -> Self {
        self.0.extend(more.0);
        self
    }

    /// The overrides, in order.
    pub fn overrides(&self) -> &[Override] {
        &self.0
    }

    /// The value set for `key` last, if any.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.0.iter().rev().find(|o| o.key == key).map(|o| &o.value)
    }
}

/// Runs the graph `file` with `sets` to its end, its outputs written under `out`.
pub fn run_graph(file: &Path, sets: &Sets, out: &Path) -> Result<RunReport, GraphError> {
    run_graph_for(file, sets, out, None)
}

/// [`run_graph`] for `duration` seconds instead of the graph's own.
pub fn run_graph_for(file: &Path, sets: &Sets, out: &Path, duration: Option<f64>) -> Result<RunReport, GraphError> {
    run(&read(file)?, sets, Some(out), duration)
}

/// Runs the graph `file` once for each of `points` (the values each point
/// sets), for `duration` seconds (its own length if `None`), its outputs
/// under `out`: as [`run_graph_for`] at each point, with every node that
/// is the same at every point run once for all of them
/// ([`evflow_engine::sweep_shared`]) — the same results, one report per
/// point. Points that differ in structure run one by one.
pub fn run_sweep_for(
    file: &Path,
    points: &[Sets],
    out: &Path,
    duration: Option<f64>,
) -> Result<Vec<RunReport>, GraphError> {
    run_sweep(&read(file)?, points, Some(out), duration)
}

/// [`run_sweep_for`] of a graph already read (and perhaps probed, as
/// [`run`] takes it), its outputs under `out` if given.
pub fn run_sweep(
    graph: &Graph,
    points: &[Sets],
    out: Option<&Path>,
    duration: Option<f64>,
) -> Result<Vec<RunReport>, GraphError> {
    let file = graph.file.as_path();
    let err = |e: String| GraphError::new(file, e);
    let registry = evflow_nodes::registry();
    let checked = points
        .iter()
        .map(|p| check(graph, &registry, p.overrides()).map_err(|e| err(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let Ok(merged) = sweep_shared::merge(&checked) else {
        return points.iter().map(|p| run(graph, p, out, duration)).collect();
    };
    let report = run_checked(&merged.checked, out, duration).map_err(err)?;
    Ok((0..merged.points()).map(|k| merged.report(&report, k)).collect())
}

/// Reads and parses the graph file `file` (to add probes to it before [`run`]).
pub fn read(file: &Path) -> Result<Graph, GraphError> {
    read_graph(file).map_err(|e| GraphError::new(file, e.to_string()))
}

/// `graph` without its node `node` and every connection to or from it
/// (e.g. a sink that writes a file a study does not need).
pub fn without(mut graph: Graph, node: &str) -> Graph {
    graph.nodes.retain(|n| n.name != node);
    graph.connections.retain(|c| c.from.node != node && c.to.node != node);
    graph
}

/// Checks `graph` with the node library and `sets`, plans it with node
/// timing on and runs it offline for `duration` s (its own length if
/// `None`). Its outputs go under `out` (created); with `None` the run has no
/// output folder, for a graph that writes nothing.
pub fn run(graph: &Graph, sets: &Sets, out: Option<&Path>, duration: Option<f64>) -> Result<RunReport, GraphError> {
    let file = graph.file.as_path();
    let err = |e: String| GraphError::new(file, e);
    let checked = check(graph, &evflow_nodes::registry(), sets.overrides()).map_err(|e| err(e.to_string()))?;
    run_checked(&checked, out, duration).map_err(err)
}

/// Plans the checked graph with node timing on and runs it offline (see [`run`]).
fn run_checked(checked: &Checked, out: Option<&Path>, duration: Option<f64>) -> Result<RunReport, String> {
    if let Some(out) = out {
        std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    let opts = PlanOptions {
        max_block: 1024,
        seed: None,
        base_dir: None,
        out_dir: out.map(Path::to_path_buf),
        timing: true,
        mode: RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(checked, &opts).map_err(|e| e.to_string())?;
    run_offline(&mut plan, RunOptions { duration, ..RunOptions::default() }).map_err(|e| e.to_string())
}

/// The value `name` that node `node` reported in run `r` of the graph `file`.
pub fn value(r: &RunReport, file: &Path, node: &str, name: &str) -> Result<f64, GraphError> {
    r.value(node, name).ok_or_else(|| GraphError::new(file, format!("the run reported no `{node}.{name}`")))
}

/// The processing time of `nodes` together per base tick of run `r`, s.
pub fn seconds_per_tick(r: &RunReport, file: &Path, nodes: &[&str]) -> Result<f64, GraphError> {
    let mut total = 0.0;
    for node in nodes {
        let t = r
            .times
            .iter()
            .find(|t| t.node == *node)
            .ok_or_else(|| GraphError::new(file, format!("no time for node `{node}` (timing off?)")))?;
        total += t.process.as_secs_f64();
    }
    Ok(total / r.ticks.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_keep_types_and_order() {
        let s = Sets::new()
            .num("mass", 85.0)
            .int("rep", 2)
            .text("sample", "felt \"fabric\"")
            .flag("train.progress", false)
            .nums("train.hidden", &[15.0, 10.0])
            .and(Sets::new().num("mass", 60.0));
        assert_eq!(s.get("mass"), Some(&Value::Float(60.0)), "a later value wins");
        assert_eq!(s.get("rep"), Some(&Value::Int(2)));
        // Text goes through as it is: no quoting for the engine to undo.
        assert_eq!(s.get("sample"), Some(&Value::Text("felt \"fabric\"".into())));
        assert_eq!(s.get("train.progress"), Some(&Value::Bool(false)));
        assert_eq!(s.get("train.hidden"), Some(&Value::FloatList(vec![15.0, 10.0])));
        assert_eq!(s.get("speed"), None);
        let keys: Vec<&str> = s.overrides().iter().map(|o| o.key.as_str()).collect();
        assert_eq!(keys, ["mass", "rep", "sample", "train.progress", "train.hidden", "mass"]);
    }
}
