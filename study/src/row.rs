//! One row of the texture study: one lab profile, texture and condition,
//! every method synthesized and scored the same way.

use super::gains::{choose, AtGain, Chosen};
use super::graphs::{run_graph, run_sweep_for, value, Sets};
use super::models::Models;
use super::recordings::{self, playback_range};
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_engine::RunReport;
use std::path::{Path, PathBuf};

/// A synthesis method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Inverse NARX model trained on binary excitation (§5.2).
    NarxBinary,
    /// Inverse NARX model trained on multilevel excitation (§5.4, §7.2).
    NarxMultilevel,
    /// Optimized synthesis through a forward model (docs/synthesis.md).
    Optimized,
    /// Record-and-playback, normalized per recording (§6.5.2, §5.2.2).
    Playback,
}

impl Method {
    /// Every method, in report order.
    pub const ALL: [Method; 4] = [Method::NarxBinary, Method::NarxMultilevel, Method::Optimized, Method::Playback];

    /// The chain's name in graphs/synthesize.toml.
    pub fn chain(&self) -> &'static str {
        match self {
            Method::NarxBinary => "narx",
            Method::NarxMultilevel => "narx_ml",
            Method::Optimized => "optimized",
            Method::Playback => "playback",
        }
    }

    /// Whether the method's actuation rides a Nyquist-rate carrier,
    /// u\[n\] = (−1)ⁿ·a\[n\] with a slowly varying envelope a: the optimized
    /// synthesis starts from that form and keeps it (97–99.8 % of the
    /// envelope's power below 0.43·f_N on the shipped cells). Its grid cells
    /// say so (`condition.carrier`), so that `interp` interpolates the
    /// envelopes and `playback` puts the carrier back.
    pub fn carrier(&self) -> bool {
        matches!(self, Method::Optimized)
    }

    /// A label for tables.
    pub fn label(&self) -> &'static str {
        match self {
            Method::NarxBinary => "inverse NARX, binary",
            Method::NarxMultilevel => "inverse NARX, multilevel",
            Method::Optimized => "optimized synthesis",
            Method::Playback => "fair playback",
        }
    }
}

/// Two readings of one E_s.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Reading {
    /// Rectangular one-second segments (the dissertation's, the `metric` default).
    #[serde(with = "super::exact")]
    pub rect: f64,
    /// Hann-windowed half-overlapping segments (Welch).
    #[serde(with = "super::exact")]
    pub welch: f64,
}

impl Reading {
    /// The smaller of each reading.
    pub fn min(self, o: Reading) -> Reading {
        Reading { rect: self.rect.min(o.rect), welch: self.welch.min(o.welch) }
    }
}

/// One method's result on a row.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MethodResult {
    /// The method.
    pub method: Method,
    /// Every gain of the sweep.
    pub sweep: Vec<AtGain>,
    /// The gains chosen.
    pub chosen: Chosen,
    /// Time to synthesize the actuation, s (0 for playback).
    #[serde(with = "super::exact")]
    pub seconds: f64,
}

/// The achievable floor's actuation: what optimizing through the display
/// itself reached (see [`super::floor`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Achievable {
    /// Its scores over the gain sweep (played like every method).
    pub sweep: Vec<AtGain>,
    /// The best of each reading over the sweep.
    pub reached: Reading,
    /// The optimizer's objective (E_s² against repetition 1, noise off) at the best start.
    #[serde(with = "super::exact")]
    pub objective: f64,
    /// Seconds the optimization took.
    #[serde(with = "super::exact")]
    pub seconds: f64,
}

/// One row.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    /// Lab profile.
    pub profile: String,
    /// Texture sample.
    pub sample: String,
    /// Condition.
    pub cond: Cond,
    /// Repetition 1 against repetition 2.
    pub repeat: Reading,
    /// Repetition 1 plus the display's own force with no actuation.
    pub display_floor: Reading,
    /// The achievable floor before it takes a better method's value (None: not computed).
    pub achievable: Option<Achievable>,
    /// Every method that ran.
    pub methods: Vec<MethodResult>,
    /// The folder of the row's runs (spectra recordings, actuations).
    pub dir: PathBuf,
}

impl Row {
    /// A method's result.
    pub fn method(&self, m: Method) -> Option<&MethodResult> {
        self.methods.iter().find(|r| r.method == m)
    }

    /// The achievable floor as defined (docs/synthesis.md): the best that
    /// optimizing through the display reached, or a method's value where one
    /// did better (the optimization then was not optimal) — under the
    /// best-E_s gain rule, per reading.
    pub fn floor(&self) -> Option<Reading> {
        let mut f = self.achievable.as_ref()?.reached;
        for m in &self.methods {
            f = f.min(Reading { rect: m.chosen.best_rect.rect, welch: m.chosen.best_welch.welch });
        }
        Some(f)
    }

    /// The recording graphs/synthesize.toml wrote for this row at `gain`
    /// (every method's actuation and force, the real force, the gate).
    pub fn recording(&self, gain: f64) -> PathBuf {
        self.dir.join(format!("synth-{}-{}-g{gain}", self.sample, self.cond.tag()))
    }
}

/// Inputs of [`run`].
pub struct RowInputs<'a> {
    /// The folder of the shipped graphs.
    pub graphs: &'a Path,
    /// The profile.
    pub profile: &'a Profile,
    /// The texture sample.
    pub sample: &'a str,
    /// The condition.
    pub cond: Cond,
    /// Its models.
    pub models: &'a Models,
    /// The folder holding the recordings.
    pub recordings: &'a Path,
    /// The gain sweep.
    pub gains: &'a [f64],
    /// The optimizer's iteration budget.
    pub iterations: usize,
    /// The optimized synthesis' objective.
    pub objective: &'a str,
    /// An optimized actuation computed before (e.g. by another study over
    /// the same recordings) to play instead of synthesizing one.
    pub optimized: Option<(PathBuf, f64)>,
    /// Where this row's runs go.
    pub dir: PathBuf,
}

/// Runs one row: the optimized synthesis, then graphs/synthesize.toml over
/// the gain sweep with every method.
pub fn run(i: &RowInputs<'_>) -> Result<Row, StudyError> {
    let c = i.cond;
    std::fs::create_dir_all(&i.dir).map_err(|e| StudyError::Io { path: i.dir.clone(), message: e.to_string() })?;
    let rep1 = i.recordings.join(recordings::name(i.sample, &c, 1));
    let (lo, hi) = playback_range(&rep1, c.speed)?;
    // Optimized synthesis, once (it does not depend on the gain).
    let (optimized, opt_seconds) = match &i.optimized {
        Some(done) => done.clone(),
        None => optimize(i)?,
    };
    // Every method over the gain sweep.
    let graph = i.graphs.join("synthesize.toml");
    let mut points = Vec::new();
    for &gain in i.gains {
        // Without a multilevel model its chain plays the binary one (and is not reported).
        let ml = i.models.narx_multilevel.as_ref().unwrap_or(&i.models.narx);
        let sets = Sets::new()
            .path("recordings", i.recordings)
            .text("sample", i.sample)
            .and(c.sets())
            .path("model", &i.models.narx)
            .path("optimized", &optimized)
            .num("gain", gain)
            .num("playback_min", lo)
            .num("playback_max", hi)
            .and(i.profile.sets())
            .path("model_ml", ml);
        points.push(sets);
    }
    // One run for the whole sweep: the syntheses and the baselines before the gains are the same at every gain.
    let reports = run_sweep_for(&graph, &points, &i.dir, None)?;
    let runs: Vec<(f64, RunReport)> = i.gains.iter().copied().zip(reports).collect();
    let first = &runs[0].1;
    let reading = |node: &str| -> Result<Reading, StudyError> {
        Ok(Reading {
            rect: value(first, &graph, &format!("{node}_es"), "E_s")?,
            welch: value(first, &graph, &format!("{node}_welch"), "E_s")?,
        })
    };
    let mut methods = Vec::new();
    for m in Method::ALL {
        if m == Method::NarxMultilevel && i.models.narx_multilevel.is_none() {
            continue;
        }
        let ch = m.chain();
        let mut sweep = Vec::new();
        for (gain, r) in &runs {
            sweep.push(AtGain {
                gain: *gain,
                rect: value(r, &graph, &format!("{ch}_es"), "E_s")?,
                welch: value(r, &graph, &format!("{ch}_welch"), "E_s")?,
                peak_ratio: value(r, &graph, &format!("{ch}_es"), "peak_psd_ratio")?,
            });
        }
        let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
        let seconds = match m {
            Method::Optimized => opt_seconds,
            Method::Playback => 0.0,
            Method::NarxBinary | Method::NarxMultilevel => {
                let node = if m == Method::NarxBinary { "narx" } else { "narx_ml" };
                first.times.iter().find(|t| t.node == node).map_or(0.0, |t| t.elapsed.as_secs_f64())
            }
        };
        methods.push(MethodResult { method: m, sweep, chosen, seconds });
    }
    Ok(Row {
        profile: i.profile.name.clone(),
        sample: i.sample.to_string(),
        cond: c,
        repeat: reading("repeat")?,
        display_floor: reading("floor")?,
        achievable: None,
        methods,
        dir: i.dir.clone(),
    })
}

/// Runs graphs/synthesize-optimized.toml for the row; returns the actuation
/// recording and the synthesis time.
pub fn optimize(i: &RowInputs<'_>) -> Result<(PathBuf, f64), StudyError> {
    let (u, r) = optimize_run(i)?;
    Ok((u, value(&r, &optimize_graph(i.graphs), "opt", "seconds")?))
}

/// The graph [`optimize`] runs, in the shipped graphs' folder `graphs`.
pub fn optimize_graph(graphs: &Path) -> PathBuf {
    graphs.join("synthesize-optimized.toml")
}

/// [`optimize`] with the whole run's report (node `opt` reports the
/// optimizer's objective, iterations, evaluations and seconds).
pub fn optimize_run(i: &RowInputs<'_>) -> Result<(PathBuf, RunReport), StudyError> {
    let c = i.cond;
    std::fs::create_dir_all(&i.dir).map_err(|e| StudyError::Io { path: i.dir.clone(), message: e.to_string() })?;
    let graph = optimize_graph(i.graphs);
    let sets = Sets::new()
        .path("recordings", i.recordings)
        .text("sample", i.sample)
        .and(c.sets())
        .path("forward", &i.models.forward)
        .path("narx_model", &i.models.narx)
        .int("iterations", i.iterations as i64)
        .text("objective", i.objective)
        .flag("record_time", true);
    let r = run_graph(&graph, &sets, &i.dir)?;
    Ok((i.dir.join(format!("u-{}-{}", i.sample, c.tag())), r))
}
