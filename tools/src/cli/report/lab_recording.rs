//! Texture recordings made on the spot for the reports: one condition of
//! `graphs/record-textures.toml` run on the simulated lab, reduced to its
//! constant-speed segments (§5.1.1).

use crate::cli::graph_args::run_with;
use anyhow::{anyhow, Context, Result};
use evflow_nodes::recording::format::Recording;
use std::path::Path;

/// One recording condition.
#[derive(Debug, Clone, Copy)]
pub struct Condition<'a> {
    /// Texture sample.
    pub sample: &'a str,
    /// Stylus mass, g.
    pub mass: f64,
    /// Speed, cm/s.
    pub speed: f64,
    /// Tribometer passes.
    pub passes: u32,
    /// Repetition (the force sensor's seed).
    pub rep: u32,
}

impl Condition<'_> {
    /// The name graphs/record-textures.toml gives its recording.
    pub fn name(&self) -> String {
        format!("{}-{}g-{}cms-r{}", self.sample, self.mass, self.speed, self.rep)
    }

    /// The `--set` values that make graphs/record-textures.toml record it.
    pub fn sets(&self) -> [String; 5] {
        [
            format!("sample=\"{}\"", self.sample),
            format!("speed={}", self.speed),
            format!("mass={}", self.mass),
            format!("passes={}", self.passes),
            format!("rep={}", self.rep),
        ]
    }
}

/// Records `c` with `graph` into a folder under `dir` and returns the rate
/// and the constant-speed force: runs within 2 % of the set speed, less
/// their first 100 ms (the high-pass filter's response to the reversal),
/// each less its mean (the friction's sign flips between passes) and faded
/// in and out over 50 ms so that the joins add no steps, concatenated.
pub fn record(graph: &Path, c: &Condition<'_>, dir: &Path) -> Result<(f64, Vec<f64>)> {
    let out = dir.join(c.name());
    std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
    run_with(graph, &c.sets(), &out)?;
    constant_speed_force(&recording_in(&out)?, c.speed, &out)
}

/// The rate and the constant-speed force (see [`record`]) of `rec`, a
/// recording of graphs/record-textures.toml at `speed_cm_s` read from `what`.
pub fn constant_speed_force(rec: &Recording, speed_cm_s: f64, what: &Path) -> Result<(f64, Vec<f64>)> {
    evflow_study::constant_speed::of_recording(rec, speed_cm_s, what).map_err(|e| anyhow!("{e}"))
}

/// The only recording a graph run wrote into `dir`.
pub fn recording_in(dir: &Path) -> Result<Recording> {
    let wav = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot read", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "wav"))
        .ok_or_else(|| anyhow!("{}: the graph wrote no recording", dir.display()))?;
    Recording::open(&wav).map_err(|e| anyhow!("{e}"))
}
