//! The real texture recordings of a study: two repetitions per texture and
//! condition, made on each lab profile's tribometer and sensor
//! (`graphs/record-textures.toml`), and what record-and-playback needs
//! from them.

use super::graphs::{run_graph, text};
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_nodes::filters::segment::SpeedRule;
use evflow_nodes::recording::format::Recording;
use std::path::{Path, PathBuf};

/// The recording `graphs/record-textures.toml` writes for `sample` at `c`, repetition `rep`.
pub fn name(sample: &str, c: &Cond, rep: u32) -> String {
    format!("{sample}-{}-r{rep}", c.tag())
}

/// Records repetitions 1 and 2 of `sample` at `c` on `profile` into `dir`
/// (one pass each; the force sensor's seed is the repetition).
pub fn record_pair(graphs: &Path, profile: &Profile, sample: &str, c: &Cond, dir: &Path) -> Result<(), StudyError> {
    for rep in [1, 2] {
        let sets = vec![
            format!("sample={}", text(sample)),
            format!("mass={}", c.mass),
            format!("speed={}", c.speed),
            "passes=1".to_string(),
            format!("rep={rep}"),
            profile.set(),
        ];
        run_graph(&graphs.join("record-textures.toml"), &sets, dir)?;
    }
    Ok(())
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
