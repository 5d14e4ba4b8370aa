//! Arguments shared by the commands that load a graph.

use anyhow::{anyhow, Result};
use evflow_engine::{load_file, run_offline, Checked, Override, Plan, PlanOptions, RunOptions, RunReport};
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

/// Loads `file` with `sets` and runs it offline to its end, its outputs
/// written under `out`: what the reports do with the shipped graphs.
#[cfg_attr(not(feature = "synth"), allow(dead_code))]
pub fn run_with(file: &Path, sets: &[impl AsRef<str>], out: &Path) -> Result<RunReport> {
    let checked = load_with(file, sets)?;
    let opts = PlanOptions {
        max_block: 1024,
        seed: None,
        base_dir: None,
        out_dir: Some(out.to_path_buf()),
        timing: false,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| anyhow!("{}: {e}", file.display()))?;
    run_offline(&mut plan, RunOptions { duration: None, progress: None })
        .map_err(|e| anyhow!("{}: {e}", file.display()))
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
