//! "Forces first" with the optimized synthesis: the recorded forces at the
//! trained conditions are interpolated to an untrained one (a
//! cross-validation run's channel `ff_in`, see [`super::xval`]), the
//! actuation for that interpolated force is optimized offline
//! (`graphs/synthesize-optimized.toml`, `synth.optimize`) through the
//! forward model of the nearest trained condition, and played on the
//! display at the untrained condition (`graphs/play-actuation.toml`),
//! scored against the real recording there.

use super::graphs::{run_graph, value, Sets};
use super::setup::{Cond, Profile};
use super::StudyError;
use std::path::{Path, PathBuf};

/// Inputs of [`optimized`].
#[derive(Debug, Clone)]
pub struct FfInputs<'a> {
    /// The folder of the shipped graphs.
    pub graphs: &'a Path,
    /// The folder of the real recordings at `cond` (repetition 2 scores).
    pub recordings: &'a Path,
    /// The texture sample.
    pub sample: &'a str,
    /// The untrained condition.
    pub cond: Cond,
    /// A recording with the interpolated force (channel `ff_in`, N) and the
    /// tribometer's `velocity` over the pass at `cond`.
    pub interpolated: &'a Path,
    /// The nearest trained condition's forward model.
    pub forward: &'a Path,
    /// Its inverse NARX model (the optimizer's fallback start).
    pub narx: &'a Path,
    /// The gain the actuation is played at (the nearest trained condition's Table 5.1 gain).
    pub gain: f64,
    /// The optimizer's iteration budget.
    pub iterations: usize,
    /// `synth.optimize`'s objective.
    pub objective: &'a str,
    /// E_s band, Hz.
    pub band: [f64; 2],
    /// The lab profile the actuation is played on.
    pub profile: &'a Profile,
    /// Where the runs go.
    pub dir: PathBuf,
}

/// What forces first with the optimized synthesis scored.
#[derive(Debug, Clone, PartialEq)]
pub struct FfScore {
    /// E_s (rect, the `metric` default) against repetition 2 at the condition.
    pub es: f64,
    /// Main peak of the display's force, Hz.
    pub peak_hz: f64,
    /// Seconds the synthesis took.
    pub seconds: f64,
    /// The actuation (channel `u`).
    pub actuation: PathBuf,
}

/// Synthesizes and scores (see the module).
pub fn optimized(i: &FfInputs<'_>) -> Result<FfScore, StudyError> {
    let c = i.cond;
    let graph = i.graphs.join("synthesize-optimized.toml");
    let sets = Sets::new()
        .text("sample", i.sample)
        .and(c.sets())
        .path("forward", i.forward)
        .path("narx_model", i.narx)
        .int("iterations", i.iterations as i64)
        .text("objective", i.objective)
        .path("opt.target", i.interpolated)
        .text("opt.channel", "ff_in")
        .flag("record_time", true);
    let r = run_graph(&graph, &sets, &i.dir)?;
    let seconds = value(&r, &graph, "opt", "seconds")?;
    let actuation = i.dir.join(format!("u-{}-{}", i.sample, c.tag()));
    let play = i.graphs.join("play-actuation.toml");
    let sets = Sets::new()
        .path("recordings", i.recordings)
        .text("sample", i.sample)
        .and(c.sets())
        .path("actuation", &actuation)
        .num("gain", i.gain)
        .and(i.profile.sets())
        .num("es.fmin", i.band[0])
        .num("es.fmax", i.band[1]);
    let played = run_graph(&play, &sets, &i.dir.join("played"))?;
    Ok(FfScore {
        es: value(&played, &play, "es", "E_s")?,
        peak_hz: value(&played, &play, "es", "peak_psd_freq_virtual")?,
        seconds,
        actuation,
    })
}
