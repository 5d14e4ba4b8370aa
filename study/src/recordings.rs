//! The real texture recordings of a study: two repetitions per texture and
//! condition, made on each lab profile's tribometer and sensor
//! (`graphs/record-textures.toml`), and what record-and-playback needs
//! from them.

use super::constant_speed;
use super::graphs::{run_graph, Sets};
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_nodes::filters::segment::SpeedRule;
use evflow_nodes::recording::format::Recording;
use std::path::{Path, PathBuf};

/// The recording `graphs/record-textures.toml` writes for `sample` at `c`, repetition `rep`.
pub fn name(sample: &str, c: &Cond, rep: u32) -> String {
    format!("{sample}-{}-r{rep}", c.tag())
}

/// One condition of `graphs/record-textures.toml`: what it records.
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

    /// The values that make graphs/record-textures.toml record it.
    pub fn sets(&self) -> Sets {
        Sets::new()
            .text("sample", self.sample)
            .num("mass", self.mass)
            .num("speed", self.speed)
            .int("passes", self.passes)
            .int("rep", self.rep)
    }
}

/// Records repetitions 1 and 2 of `sample` at `c` on `profile` into `dir`
/// (one pass each; the force sensor's seed is the repetition).
pub fn record_pair(graphs: &Path, profile: &Profile, sample: &str, c: &Cond, dir: &Path) -> Result<(), StudyError> {
    for rep in [1, 2] {
        let at = Condition { sample, mass: c.mass, speed: c.speed, passes: 1, rep };
        run_graph(&graphs.join("record-textures.toml"), &at.sets().and(profile.sets()), dir)?;
    }
    Ok(())
}

/// Records `c` with `graph` (graphs/record-textures.toml or a graph like
/// it) on the nominal lab into a folder under `dir` and returns the rate
/// and the constant-speed force ([`constant_speed::of_recording`]): what
/// `report freqvel` and `report interp` record on the spot.
pub fn record(graph: &Path, c: &Condition<'_>, dir: &Path) -> Result<(f64, Vec<f64>), StudyError> {
    let out = dir.join(c.name());
    run_graph(graph, &c.sets(), &out)?;
    let rec = recording_in(&out)?;
    constant_speed::of_recording(&rec, c.speed, &out)
}

/// The only recording a graph run wrote into `dir`.
pub fn recording_in(dir: &Path) -> Result<Recording, StudyError> {
    let io = |e: std::io::Error| StudyError::Io { path: dir.to_path_buf(), message: e.to_string() };
    let wav = std::fs::read_dir(dir)
        .map_err(io)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "wav"))
        .ok_or_else(|| StudyError::Recording(format!("{}: the graph wrote no recording", dir.display())))?;
    Recording::open(&wav).map_err(|e| StudyError::Recording(e.to_string()))
}

/// A recording's channel.
pub fn channel(path: &Path, name: &str) -> Result<(f64, Vec<f64>), StudyError> {
    let rec = Recording::open_channels(path, &[name]).map_err(|e| StudyError::Recording(e.to_string()))?;
    let data = rec.channel(name).unwrap_or_default().to_vec();
    Ok((rec.rate(), data))
}

/// The constant-speed gate of a recording with a `velocity` channel, by
/// `segment`'s rule as graphs/synthesize.toml applies it (2 %, 100 ms, both directions).
pub fn gate(path: &Path, speed_cm_s: f64) -> Result<Vec<bool>, StudyError> {
    let (rate, v) = channel(path, "velocity")?;
    Ok(SpeedRule::new(speed_cm_s, 0.02, 0.1, rate, 0.0).gate(&v))
}

/// Record-and-playback's normalization of a recording (§5.2.2: each force
/// sequence normalized): the extremes of its force over its constant-speed
/// stretch, which `normalize` maps to ±1.
pub fn playback_range(path: &Path, speed_cm_s: f64) -> Result<(f64, f64), StudyError> {
    let (_, f) = channel(path, "force")?;
    let keep = gate(path, speed_cm_s)?;
    let (lo, hi) = f
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (v, _)| (lo.min(*v), hi.max(*v)));
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(StudyError::Recording(format!(
            "{}: no constant-speed stretch at {speed_cm_s} cm/s, or a constant force",
            path.display()
        )));
    }
    Ok((lo, hi))
}

/// The folder of a profile's recordings under `work`.
pub fn folder(work: &Path, profile: &Profile) -> PathBuf {
    work.join("recordings").join(&profile.name)
}
