//! Running a shipped graph for a curve: load it with `--set`-style
//! overrides, plan it with node timing on, run it offline and keep the report.

use super::PrecisionError;
use evflow_engine::{load_file, run_offline, Override, Plan, PlanOptions, RunMode, RunOptions, RunReport};
use std::path::Path;

/// Runs `file` with `sets` (`name=value`, TOML values) for at most
/// `duration` s (the graph's own length if `None`); nothing is written.
pub fn run(file: &Path, sets: &[String], duration: Option<f64>) -> Result<RunReport, PrecisionError> {
    let err = |m: String| PrecisionError::Graph { file: file.display().to_string(), message: m };
    let overrides = sets
        .iter()
        .map(|s| Override::parse(s).map_err(|e| err(format!("--set {e}"))))
        .collect::<Result<Vec<_>, _>>()?;
    let checked = load_file(file, &evflow_nodes::registry(), &overrides).map_err(|e| err(e.to_string()))?;
    let opts = PlanOptions {
        max_block: 1024,
        seed: None,
        base_dir: None,
        out_dir: None,
        timing: true,
        mode: RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| err(e.to_string()))?;
    run_offline(&mut plan, RunOptions { duration, ..RunOptions::default() }).map_err(|e| err(e.to_string()))
}

/// The value `name` node `node` reported.
pub fn value(r: &RunReport, file: &Path, node: &str, name: &str) -> Result<f64, PrecisionError> {
    r.value(node, name).ok_or_else(|| PrecisionError::Graph {
        file: file.display().to_string(),
        message: format!("the run reported no `{node}.{name}`"),
    })
}

/// Node `node`'s processing time per base tick, s.
pub fn seconds_per_tick(r: &RunReport, file: &Path, node: &str) -> Result<f64, PrecisionError> {
    let t = r.times.iter().find(|t| t.node == node).ok_or_else(|| PrecisionError::Graph {
        file: file.display().to_string(),
        message: format!("no time for node `{node}` (timing off?)"),
    })?;
    Ok(t.process.as_secs_f64() / r.ticks.max(1) as f64)
}
