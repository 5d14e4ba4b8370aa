//! Running the shipped graphs from a study: load with the node library and
//! `--set`-style overrides, plan, run offline, keep the report.

use super::StudyError;
use evflow_engine::{load_file, run_offline, Override, Plan, PlanOptions, RunMode, RunOptions, RunReport};
use std::path::Path;

/// Runs the graph `file` with `sets` (`name=value` or `node.param=value`,
/// TOML values) to its end, its outputs written under `out`.
pub fn run_graph(file: &Path, sets: &[String], out: &Path) -> Result<RunReport, StudyError> {
    run_graph_for(file, sets, out, None)
}

/// [`run_graph`] for `duration` seconds instead of the graph's own.
pub fn run_graph_for(file: &Path, sets: &[String], out: &Path, duration: Option<f64>) -> Result<RunReport, StudyError> {
    let err = |m: String| StudyError::Graph { file: file.to_path_buf(), message: m };
    let overrides = sets
        .iter()
        .map(|s| Override::parse(s).map_err(|e| err(format!("--set {e}"))))
        .collect::<Result<Vec<_>, _>>()?;
    let checked = load_file(file, &evflow_nodes::registry(), &overrides).map_err(|e| err(e.to_string()))?;
    std::fs::create_dir_all(out).map_err(|e| StudyError::Io { path: out.to_path_buf(), message: e.to_string() })?;
    let opts = PlanOptions {
        max_block: 1024,
        seed: None,
        base_dir: None,
        out_dir: Some(out.to_path_buf()),
        timing: true,
        mode: RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| err(e.to_string()))?;
    run_offline(&mut plan, RunOptions { duration, ..RunOptions::default() }).map_err(|e| err(e.to_string()))
}

/// The value `name` that node `node` reported in run `r`.
pub fn value(r: &RunReport, file: &Path, node: &str, name: &str) -> Result<f64, StudyError> {
    r.value(node, name).ok_or_else(|| StudyError::Graph {
        file: file.to_path_buf(),
        message: format!("the run reported no `{node}.{name}`"),
    })
}

/// A text value for `--set` (a TOML string).
pub fn text(s: &str) -> String {
    evflow_engine::params::toml_string(s)
}

/// A path for `--set` (a TOML string).
pub fn path(p: &Path) -> String {
    text(&p.display().to_string())
}
