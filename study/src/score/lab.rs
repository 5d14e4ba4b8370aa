//! A stroke's actuations played on a lab profile's virtual display under
//! the recorded finger, scored as `report live` scores every chain:
//! graphs/texture-live-play.toml with the finger's true velocity and load
//! and the real force read from the real recording instead of `sim.user`
//! and `sim.texture` — × `gain`, `limit` (|u| ≤ 1), `sim.display` with the
//! chains' noise seed (2, under the graph seed 11), the texture's force
//! modulation added for the display floor, both forces high-passed at
//! 10 Hz (4th-order Butterworth), E_s over 2–200 Hz in the rect and the
//! Welch (Hann, half-overlapping one-second segments) readings. On the
//! simulated lab, where the recording holds `sim.user`'s own numbers, every
//! reading is the one `report live` gets, bit for bit (tools/tests/score.rs).
//!
//! The graph is written into the score's work folder (`score-play.toml`),
//! where it can be read and rerun.

use super::Played;
use crate::gains::AtGain;
use crate::graphs::{self, value, Sets};
use crate::live::play;
use crate::setup::Profile;
use crate::StudyError;
use evflow_engine::Graph;
use evflow_nodes::recording::format::Recording;
use std::path::{Path, PathBuf};

/// The play graph's file name in the work folder.
pub const GRAPH_FILE: &str = "score-play.toml";

/// The play graph at `rate` Hz.
pub fn graph_text(rate: f64) -> String {
    format!(
        r#"# Written by `evflow score` (evflow_study::score::lab): an actuation played
# on a lab profile's virtual display under a recorded finger and scored
# against the real force along the same path — graphs/texture-live-play.toml
# with the finger and the real force read from `path` (channels velocity
# m/s, load N, force N) instead of sim.user and sim.texture. `actuation`
# holds `u` and `add` (a force added to the display's, N: the display
# floor's texture modulation, else 0).

[graph]
format = 1
name = "score-play"
description = "A recorded actuation × gain → limit → virtual display under a recorded finger; E_s (rect and Welch) against the real force"
rate = {rate:?}
seed = 11
connections = [
    "path.force -> highpass.in",
    "act.u -> gain.in",
    "gain.out -> limit.in",
    "limit.out -> display.u",
    "path.load -> display.load",
    "path.velocity -> display.velocity",
    "display.force -> plus.a",
    "act.add -> plus.b",
    "plus.out -> display_hp.in",
    "display_hp.out -> es.virtual",
    "highpass.out -> es.real",
    "display_hp.out -> welch.virtual",
    "highpass.out -> welch.real",
    "display_hp.out -> forces.rendered",
    "highpass.out -> forces.real",
]

[vars]
path = "stroke-truth"
actuation = "actuation"
profile = ""
gain = 1.0
record = "forces"

[nodes.path]
type = "recording.in"
path = "$path"
channels = ["velocity", "load", "force"]

[nodes.highpass]
type = "butterworth"
kind = "highpass"
order = 4
cutoff = 10.0

[nodes.act]
type = "recording.in"
path = "$actuation"
channels = ["u", "add"]

[nodes.gain]
type = "gain"
gain = "$gain"

[nodes.limit]
type = "limit"
amplitude = 1.0

[nodes.display]
type = "sim.display"
profile = "$profile"
seed = 2

[nodes.plus]
type = "add"

[nodes.display_hp]
type = "butterworth"
kind = "highpass"
order = 4
cutoff = 10.0

[nodes.es]
type = "metric"
fmin = 2.0
fmax = 200.0

[nodes.welch]
type = "metric"
window = "hann"
overlap = 0.5
fmin = 2.0
fmax = 200.0

[nodes.forces]
type = "recording.out"
path = "$record"
channels = ["rendered", "real"]
units = ["N", "N"]
source = "evflow score: the display's force and the real force, both high-passed at 10 Hz"
"#
    )
}

/// A lab profile's display under the recorded finger.
#[derive(Debug)]
pub struct LabPlayer {
    profile: Profile,
    file: PathBuf,
    graph: Graph,
    quiet: Graph,
    real: PathBuf,
    dir: PathBuf,
    rate: f64,
    seconds: f64,
}

impl LabPlayer {
    /// Writes the play graph into `dir` for the real recording `real` (its
    /// path and force) at `rate` Hz over `seconds`.
    pub fn new(profile: Profile, real: &Path, dir: &Path, rate: f64, seconds: f64) -> Result<Self, StudyError> {
        let io = |p: &Path, e: std::io::Error| StudyError::Io { path: p.to_path_buf(), message: e.to_string() };
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let file = dir.join(GRAPH_FILE);
        std::fs::write(&file, graph_text(rate)).map_err(|e| io(&file, e))?;
        let graph = graphs::read(&file)?;
        let quiet = graphs::without(graph.clone(), "forces");
        let real = std::path::absolute(real).map_err(|e| io(real, e))?;
        Ok(Self { profile, file, graph, quiet, real, dir: dir.to_path_buf(), rate, seconds })
    }

    fn sets(&self, file: &Path, gain: f64, record: &str) -> Sets {
        Sets::new()
            .path("path", &self.real)
            .path("actuation", file)
            .and(self.profile.sets())
            .num("gain", gain)
            .text("record", record)
    }

    /// Writes `u` and `add` as `dir/NAME`.
    fn write(&self, name: &str, u: &[f64], add: &[f64]) -> Result<PathBuf, StudyError> {
        play::write(&self.dir.join(name), self.rate, u, add, &format!("evflow score: {name}"))
    }
}

impl super::Player for LabPlayer {
    fn sweep(&mut self, name: &str, u: &[f64], add: &[f64], gains: &[f64]) -> Result<Vec<AtGain>, StudyError> {
        let file = self.write(name, u, add)?;
        let mut out = Vec::with_capacity(gains.len());
        for &gain in gains {
            let r = graphs::run(&self.quiet, &self.sets(&file, gain, ""), Some(&self.dir), Some(self.seconds))?;
            let g = &self.file;
            out.push(AtGain {
                gain,
                rect: value(&r, g, "es", "E_s")?,
                welch: value(&r, g, "welch", "E_s")?,
                peak_ratio: value(&r, g, "es", "peak_psd_ratio")?,
            });
        }
        Ok(out)
    }

    fn play(&mut self, name: &str, u: &[f64], add: &[f64]) -> Result<Played, StudyError> {
        let file = self.write(name, u, add)?;
        let record = format!("{name}-forces");
        let r = graphs::run(&self.graph, &self.sets(&file, 1.0, &record), Some(&self.dir), Some(self.seconds))?;
        let g = &self.file;
        let at = AtGain {
            gain: 1.0,
            rect: value(&r, g, "es", "E_s")?,
            welch: value(&r, g, "welch", "E_s")?,
            peak_ratio: value(&r, g, "es", "peak_psd_ratio")?,
        };
        let rec = Recording::open(&self.dir.join(&record)).map_err(|e| StudyError::Recording(e.to_string()))?;
        let ch = |c: &str| rec.channel(c).map(<[f64]>::to_vec).unwrap_or_default();
        Ok(Played { at, rendered: ch("rendered"), real: ch("real") })
    }

    fn optimize_goals(
        &mut self,
        stroke: &crate::live::stroke::Stroke,
        goals: &[(&crate::live::floor::Goal, &crate::live::floor::Seeds)],
        iterations: usize,
    ) -> Result<Vec<(Vec<crate::live::floor::Candidate>, f64)>, StudyError> {
        let lab = match &self.profile.path {
            Some(p) => {
                evflow_nodes::lab::profile::LabProfile::load(p).map_err(|e| StudyError::Config(e.issues_text()))?
            }
            None => evflow_nodes::lab::profile::LabProfile::default(),
        };
        crate::live::floor::optimize_goals(stroke, &lab, goals, iterations)
    }
}
