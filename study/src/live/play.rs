//! Actuations computed outside a graph, played and scored like every live
//! chain (graphs/texture-live-play.toml: × gain, `limit`, the virtual
//! display with the chains' noise seed, the same metric): the stroke's
//! floor candidates, and the display floor.

use super::scope::{LiveScope, User};
use super::stroke::Stroke;
use crate::gains::AtGain;
use crate::graphs::{run_sweep_for, value, Sets};
use crate::row::Reading;
use crate::setup::Profile;
use crate::StudyError;
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::path::{Path, PathBuf};

/// The play graph's file name.
pub const GRAPH: &str = "texture-live-play.toml";

/// Writes `u` (actuation) and `add` (force added to the display's, N) as
/// the recording `file`.
pub fn write(file: &Path, rate: f64, u: &[f64], add: &[f64], source: &str) -> Result<PathBuf, StudyError> {
    let mut meta = RecordingMeta::new(rate, vec![Channel::new("u", "1"), Channel::new("add", "N")]);
    meta.source = source.into();
    let io = |e: evflow_nodes::recording::format::RecordingError| StudyError::Io {
        path: file.into(),
        message: e.to_string(),
    };
    let mut w = RecordingWriter::create(file, meta).map_err(io)?;
    let frames: Vec<f64> = u.iter().zip(add).flat_map(|(a, b)| [*a, *b]).collect();
    w.write_interleaved(&frames).map_err(io)?;
    w.finish().map_err(io)?;
    Ok(file.to_path_buf())
}

/// Where one row plays: the shipped graphs, the study's scope, the lab
/// profile, the sample and the user; the runs' files go to `dir`.
#[derive(Debug, Clone, Copy)]
pub struct Stage<'a> {
    /// The folder of the shipped graphs.
    pub graphs: &'a Path,
    /// The study's scope (its run length).
    pub scope: &'a LiveScope,
    /// The lab profile.
    pub profile: &'a Profile,
    /// The texture sample.
    pub sample: &'a str,
    /// The virtual user.
    pub user: &'a User,
    /// The row's folder.
    pub dir: &'a Path,
}

/// Plays the recording `file` on `at` at each of `gains`.
pub fn sweep(at: &Stage<'_>, file: &Path, gains: &[f64]) -> Result<Vec<AtGain>, StudyError> {
    let (scope, profile, sample, user, dir) = (at.scope, at.profile, at.sample, at.user, at.dir);
    let graph = at.graphs.join(GRAPH);
    let points: Vec<Sets> = gains
        .iter()
        .map(|&gain| {
            Sets::new()
                .text("sample", sample)
                .path("actuation", file)
                .and(profile.sets())
                .num("gain", gain)
                .and(user.sets())
        })
        .collect();
    // One run for the whole sweep: the user, the sample and the actuation read once.
    let reports = run_sweep_for(&graph, &points, dir, Some(scope.seconds))?;
    let mut out = Vec::new();
    for (&gain, r) in gains.iter().zip(&reports) {
        out.push(AtGain {
            gain,
            rect: value(r, &graph, "es", "E_s")?,
            welch: value(r, &graph, "welch", "E_s")?,
            peak_ratio: value(r, &graph, "es", "peak_psd_ratio")?,
        });
    }
    Ok(out)
}

/// The display floor of a stroke: no actuation, the texture's own force
/// modulation added to the display's force.
pub fn display_floor(at: &Stage<'_>, stroke: &Stroke) -> Result<Reading, StudyError> {
    let file = write(
        &at.dir.join("display-floor"),
        stroke.rate,
        &vec![0.0; stroke.len()],
        &stroke.modulation,
        "evflow live study: the display floor (no actuation; the texture's force modulation added)",
    )?;
    let s = sweep(at, &file, &[1.0])?;
    Ok(Reading { rect: s[0].rect, welch: s[0].welch })
}
