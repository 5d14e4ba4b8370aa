//! The interpolation cross-validation on the display (dissertation
//! §5.3.3, Fig. 5.6/5.9; §6.4, Fig. 6.8): one run of
//! `graphs/texture-cross-validation.toml` at one condition with one scheme
//! — a grid of cells interpolated there and played on the virtual display,
//! beside the repeat baseline, record-and-playback over the playback grid
//! and "forces first" (the recorded forces interpolated, then the inverse
//! NARX model of the nearest trained condition).

use super::graphs::{run_graph, value, Sets};
use super::setup::{Cond, Profile};
use super::StudyError;
use std::path::{Path, PathBuf};

/// The cross-validation graph's file name.
pub const GRAPH: &str = "texture-cross-validation.toml";

/// The grids of one sample: folders of cells at its trained conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct Grids {
    /// The actuation cells played in the dissertation's order (each × its gain).
    pub cells: PathBuf,
    /// Record-and-playback's cells (normalized forces, each × its gain).
    pub playback: PathBuf,
    /// The recorded forces in newtons (gain 1), which forces first interpolates.
    pub forces: PathBuf,
}

/// Inputs of [`run`].
#[derive(Debug, Clone)]
pub struct XvalInputs<'a> {
    /// The folder of the shipped graphs.
    pub graphs: &'a Path,
    /// The folder of the recordings at `cond` (repetitions 1 and 2).
    pub recordings: &'a Path,
    /// The texture sample.
    pub sample: &'a str,
    /// The condition interpolated to.
    pub cond: Cond,
    /// The sample's grids.
    pub grids: &'a Grids,
    /// `interp`'s scheme: "basic" (§5.3.3) or "improved" (Eq. 6.4).
    pub scheme: &'a str,
    /// The sample's main wavelength, cm (`interp`'s `period`).
    pub period: f64,
    /// Forces first: the nearest trained condition's inverse NARX model.
    pub model: &'a Path,
    /// Forces first: that model's gain.
    pub ff_gain: f64,
    /// E_s band, Hz.
    pub band: [f64; 2],
    /// The lab profile of the tribometer, displays and sensors.
    pub profile: &'a Profile,
    /// Where the run's recording goes.
    pub dir: PathBuf,
}

/// What one run scored (E_s in the `metric` node's rect reading).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scores {
    /// The interpolated cells on the display.
    pub cells: f64,
    /// The interpolated playback cells on the display.
    pub playback: f64,
    /// Repetition 1 against repetition 2.
    pub repeat: f64,
    /// Forces first with the nearest inverse NARX model.
    pub ff_narx: f64,
    /// Main peak of the cells' force, Hz.
    pub cells_peak_hz: f64,
    /// Main peak of the forces-first force, Hz.
    pub ff_peak_hz: f64,
    /// Main peak of the real force, Hz.
    pub real_peak_hz: f64,
}

/// The recording a run writes (channels `narx_force` — the cells' force —,
/// `playback_force`, `real_force`, `u`, `steady`, `ff_force`, `ff_in` — the
/// interpolated force, N —, `velocity`).
pub fn recording(i: &XvalInputs<'_>) -> PathBuf {
    i.dir.join(format!("xval-{}-{}-{}", i.sample, i.cond.tag(), i.scheme))
}

/// Runs the cross-validation graph once.
pub fn run(i: &XvalInputs<'_>) -> Result<Scores, StudyError> {
    let c = i.cond;
    let graph = i.graphs.join(GRAPH);
    let mut sets = Sets::new()
        .path("recordings", i.recordings)
        .text("sample", i.sample)
        .and(c.sets())
        .path("grid", &i.grids.cells)
        .path("playback_grid", &i.grids.playback)
        .path("forces", &i.grids.forces)
        .num("force_scale", 1.0)
        .text("scheme", i.scheme)
        .num("period", i.period)
        .path("model", i.model)
        .num("ff_gain", i.ff_gain)
        .and(i.profile.sets());
    for node in ["narx_es", "playback_es", "repeat_es", "ff_es"] {
        sets = sets.num(&format!("{node}.fmin"), i.band[0]).num(&format!("{node}.fmax"), i.band[1]);
    }
    let r = run_graph(&graph, &sets, &i.dir)?;
    let v = |node: &str, name: &str| value(&r, &graph, node, name);
    Ok(Scores {
        cells: v("narx_es", "E_s")?,
        playback: v("playback_es", "E_s")?,
        repeat: v("repeat_es", "E_s")?,
        ff_narx: v("ff_es", "E_s")?,
        cells_peak_hz: v("narx_es", "peak_psd_freq_virtual")?,
        ff_peak_hz: v("ff_es", "peak_psd_freq_virtual")?,
        real_peak_hz: v("narx_es", "peak_psd_freq_real")?,
    })
}

/// The index of the trained condition in `trained` nearest to `c` (load
/// and speed each in units of its span; a tie goes to the first —
/// `narx::nearest`, as `narx.grid` chooses live).
pub fn nearest(c: &Cond, trained: &[Cond]) -> usize {
    let grid: Vec<(f64, f64)> = trained.iter().map(|t| (t.mass, t.speed)).collect();
    evflow_nodes::narx::nearest::nearest(&grid, c.mass, c.speed).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_corner_counts_each_axis_in_units_of_its_span() {
        let corners = [
            Cond { mass: 60.0, speed: 3.0 },
            Cond { mass: 60.0, speed: 7.0 },
            Cond { mass: 110.0, speed: 3.0 },
            Cond { mass: 110.0, speed: 7.0 },
        ];
        assert_eq!(nearest(&Cond { mass: 100.0, speed: 6.0 }, &corners), 3);
        assert_eq!(nearest(&Cond { mass: 65.0, speed: 6.5 }, &corners), 1);
        // The centre ties everywhere: the first corner.
        assert_eq!(nearest(&Cond { mass: 85.0, speed: 5.0 }, &corners), 0);
    }
}
