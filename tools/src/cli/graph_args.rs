//! Arguments shared by the commands that load a graph.

use anyhow::{anyhow, Result};
use evflow_engine::{load_file, Checked, Override};
use std::path::{Path, PathBuf};

/// Loads and validates `file` with the node library and `sets` applied
/// (`name=value` or `node.param=value`, as `--set` takes them).
pub fn load_with(file: &Path, sets: &[impl AsRef<str>]) -> Result<Checked> {
    let overrides = sets
        .iter()
        .map(|s| Override::parse(s.as_ref()).map_err(|e| anyhow!("--set {e}")))
        .collect::<Result<Vec<_>>>()?;
    load_file(file, &evflow_nodes::registry(), &overrides).map_err(|e| anyhow!("{e}"))
}

/// A graph file and command-line overrides.
#[derive(clap::Args, Debug)]
pub struct GraphArgs {
    /// The graph file (TOML).
    pub file: PathBuf,
    /// Set a graph variable (`name=value`) or a node parameter
    /// (`node.param=value`); may be repeated. Values use TOML syntax
    /// (`85`, `2.5`, `"felt"`, `[1, 2]`); bare words are text.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl GraphArgs {
    /// The `--set` overrides.
    pub fn overrides(&self) -> Result<Vec<Override>> {
        self.set.iter().map(|s| Override::parse(s).map_err(|e| anyhow!("--set {e}"))).collect()
    }

    /// Loads and validates the graph with the node library.
    pub fn load(&self) -> Result<Checked> {
        load_with(&self.file, &self.set)
    }
}

/// `--duration`: a positive, finite number of seconds up to 1e7 (what the
/// engine runs; `inf` or `1e308` would run until killed).
pub fn parse_duration(s: &str) -> Result<f64, String> {
    let d: f64 = s.trim().parse().map_err(|_| format!("`{s}` is not a number of seconds"))?;
    evflow_engine::check_duration(d)
}
