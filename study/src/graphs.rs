//! Running the shipped graphs from a study: load with the node library and
//! typed overrides ([`Sets`], what `--set` gives the engine), plan, run
//! offline, keep the report.

use super::StudyError;
use evflow_engine::{load_file, run_offline, Override, Plan, PlanOptions, RunMode, RunOptions, RunReport, Value};
use std::path::Path;

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
pub fn run_graph(file: &Path, sets: &Sets, out: &Path) -> Result<RunReport, StudyError> {
    run_graph_for(file, sets, out, None)
}

/// [`run_graph`] for `duration` seconds instead of the graph's own.
pub fn run_graph_for(file: &Path, sets: &Sets, out: &Path, duration: Option<f64>) -> Result<RunReport, StudyError> {
    let err = |m: String| StudyError::Graph { file: file.to_path_buf(), message: m };
    let checked = load_file(file, &evflow_nodes::registry(), sets.overrides()).map_err(|e| err(e.to_string()))?;
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
