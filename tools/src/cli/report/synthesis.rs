//! The synthesis pipeline of chapter 5 that several reports share: inverse
//! NARX models trained per condition (`graphs/model-build.toml`), texture
//! recordings (`graphs/record-textures.toml`), synthesis over the gain
//! sweep (`graphs/synthesize.toml`) with the gain chosen as Table 5.1 does,
//! and the grid cells U_ij that `interp` reads, cut from a synthesis run.

use super::lab_recording::{recording_in, Condition};
use crate::cli::graph_args::run_with;
use anyhow::{anyhow, ensure, Context, Result};
use evflow_engine::RunReport;
use evflow_nodes::filters::segment::open_runs;
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::path::{Path, PathBuf};

/// A (load, velocity) condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Cond {
    /// Stylus mass, g.
    pub(super) mass: f64,
    /// Scanning speed, cm/s.
    pub(super) speed: f64,
}

impl Cond {
    /// Parses `MASS:SPEED` (g and cm/s).
    pub(super) fn parse(s: &str) -> Result<Self> {
        let (m, v) = s.split_once(':').ok_or_else(|| anyhow!("--conditions: `{s}` is not MASS:SPEED"))?;
        let (mass, speed) = (
            m.trim().parse::<f64>().map_err(|_| anyhow!("--conditions: mass `{m}` is not a number"))?,
            v.trim().parse::<f64>().map_err(|_| anyhow!("--conditions: speed `{v}` is not a number"))?,
        );
        ensure!(mass > 0.0 && speed > 0.0, "--conditions: `{s}`: mass and speed must be positive");
        Ok(Self { mass, speed })
    }

    /// "60 g, 3 cm/s".
    pub(super) fn label(&self) -> String {
        format!("{} g, {} cm/s", self.mass, self.speed)
    }

    /// The file model-build.toml writes for this condition.
    pub(super) fn model_name(&self) -> String {
        format!("narx-{}g-{}cms.json", self.mass, self.speed)
    }
}

/// A model built for a condition.
pub(super) struct Built {
    /// The model file.
    pub(super) path: PathBuf,
}

/// One scored chain of synthesize.toml at its chosen gain.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scored {
    /// The chosen gain.
    pub(super) gain: f64,
    /// E_s at that gain.
    pub(super) es: f64,
    /// Virtual over real peak power density at that gain.
    pub(super) ratio: f64,
}

/// The value `name` that node `node` reported in run `r`.
pub(super) fn value(r: &RunReport, node: &str, name: &str) -> Result<f64> {
    r.summaries
        .iter()
        .find(|(n, _)| n == node)
        .and_then(|(_, s)| s.get(name))
        .ok_or_else(|| anyhow!("the run reported no `{node}.{name}`"))
}

/// The gain whose peak power density is nearest the real one (on a log scale).
pub(super) fn choose(runs: &[(f64, RunReport)], node: &str) -> Result<Scored> {
    let mut best: Option<Scored> = None;
    for (gain, r) in runs {
        let s = Scored { gain: *gain, es: value(r, node, "E_s")?, ratio: value(r, node, "peak_psd_ratio")? };
        if best.is_none_or(|b| s.ratio.ln().abs() < b.ratio.ln().abs()) {
            best = Some(s);
        }
    }
    best.ok_or_else(|| anyhow!("no gains"))
}

/// Magnitude spectrum (rect, 1 Hz bins, as `metric` takes it) of the gated samples.
pub(super) fn gated_spectrum(x: &[f64], gate: &[f64], rate: f64) -> Result<Vec<f64>> {
    let mut kept = Vec::new();
    open_runs(&[gate], x.len().min(gate.len()), |a, b| kept.extend_from_slice(&x[a..b]));
    let cfg = SpectrumConfig { rate, nfft: rate.round() as usize, window: Window::Rect, overlap: 0.0 };
    averaged_spectrum(&kept, cfg)
        .map_err(|e| anyhow!("{e}"))?
        .map(|s| s.magnitude)
        .ok_or_else(|| anyhow!("no constant-speed samples to take a spectrum of"))
}

/// Writes channel `channel` of the synthesis run in `from` (its
/// constant-speed stretch) as the grid cell U_ij of `sample` at `c` into
/// `grid`: channel `u`, condition load, velocity, material and `gain`
/// (Table 5.1, which `interp`'s `apply_gain` multiplies in). The `narx`
/// node's output lags the force by its look-ahead; a grid cell is a texture
/// loop, so that shift of a few samples does not matter. Returns the
/// recording's path (without extension).
pub(super) fn write_cell(
    from: &Path,
    channel: &str,
    grid: &Path,
    sample: &str,
    c: &Cond,
    gain: f64,
) -> Result<PathBuf> {
    let rec = recording_in(from)?;
    let ch = |n: &str| rec.channel(n).ok_or_else(|| anyhow!("{}: no `{n}` channel", from.display()));
    let (u, gate) = (ch(channel)?, ch("steady")?);
    let mut kept = Vec::new();
    open_runs(&[gate], u.len().min(gate.len()), |a, b| kept.extend_from_slice(&u[a..b]));
    ensure!(!kept.is_empty(), "{}: no constant-speed samples", from.display());
    std::fs::create_dir_all(grid).with_context(|| format!("{}: cannot create", grid.display()))?;
    let mut meta = RecordingMeta::new(rec.rate(), vec![Channel::new("u", "1")]);
    meta.condition.load_g = Some(c.mass);
    meta.condition.velocity_cm_s = Some(c.speed);
    meta.condition.material = Some(sample.into());
    meta.condition.gain = Some(gain);
    meta.source = format!("evflow report: graphs/synthesize.toml, `{channel}` over the constant-speed stretch");
    let path = grid.join(format!("u-{sample}-{}g-{}cms", c.mass, c.speed));
    let mut w = RecordingWriter::create(&path, meta).map_err(|e| anyhow!("{e}"))?;
    w.write_interleaved(&kept).map_err(|e| anyhow!("{e}"))?;
    w.finish().map_err(|e| anyhow!("{e}"))?;
    Ok(path)
}

/// Checks that the folder `graphs` (`--graphs`) holds every graph in `names`.
pub(super) fn check_graphs(graphs: &Path, names: &[&str]) -> Result<()> {
    for g in names {
        ensure!(graphs.join(g).is_file(), "--graphs: {} has no {g} (run from the repository root)", graphs.display());
    }
    Ok(())
}

/// Records repetitions 1 and 2 of `sample` at `c` into `dir` (one pass each).
pub(super) fn record_pair(graphs: &Path, sample: &str, c: &Cond, dir: &Path) -> Result<()> {
    for rep in [1, 2] {
        let rec = Condition { sample, mass: c.mass, speed: c.speed, passes: 1, rep };
        run_with(&graphs.join("record-textures.toml"), &rec.sets(), dir)?;
    }
    Ok(())
}

/// The folder of the synthesize.toml run of `sample` at `c` and `gain` under `work`.
pub(super) fn synth_dir(work: &Path, sample: &str, c: &Cond, gain: f64) -> PathBuf {
    work.join(format!("synth-{sample}-{}-{}-{gain}", c.mass, c.speed))
}

/// Runs graphs/synthesize.toml for `sample` at `c` with `model` once per
/// gain, each run's outputs in its own folder under `work` ([`synth_dir`]).
pub(super) fn synthesize(
    graphs: &Path,
    sample: &str,
    c: &Cond,
    model: &Path,
    gains: &[f64],
    recordings: &Path,
    work: &Path,
) -> Result<Vec<(f64, RunReport)>> {
    let mut runs = Vec::new();
    for &gain in gains {
        let out = synth_dir(work, sample, c, gain);
        std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
        let sets = [
            format!("recordings={:?}", recordings.display().to_string()),
            format!("model={:?}", model.display().to_string()),
            format!("sample=\"{sample}\""),
            format!("mass={}", c.mass),
            format!("speed={}", c.speed),
            format!("gain={gain}"),
        ];
        runs.push((gain, run_with(&graphs.join("synthesize.toml"), &sets, &out)?));
    }
    Ok(runs)
}

/// One texture at one trained condition: the repeat baseline, the display
/// floor and the NARX and record-and-playback chains at their chosen gains.
pub(super) struct Synthesis {
    /// E_s of repetition 1 against repetition 2.
    pub(super) repeat: f64,
    /// NARX synthesis.
    pub(super) narx: Scored,
    /// Record-and-playback.
    pub(super) playback: Scored,
}

/// Records `sample` at `c` (into `recordings`), synthesizes it with `model`
/// over `gains` (runs under `work`) and chooses each chain's gain.
pub(super) fn synthesize_condition(
    graphs: &Path,
    sample: &str,
    c: &Cond,
    model: &Path,
    gains: &[f64],
    recordings: &Path,
    work: &Path,
) -> Result<Synthesis> {
    record_pair(graphs, sample, c, recordings)?;
    let runs = synthesize(graphs, sample, c, model, gains, recordings, work)?;
    Ok(Synthesis {
        repeat: value(&runs[0].1, "repeat_es", "E_s")?,
        narx: choose(&runs, "narx_es")?,
        playback: choose(&runs, "playback_es")?,
    })
}

/// Trains the model of `c` with graphs/model-build.toml (plus `extra`
/// overrides) into `dir` and returns its path.
pub(super) fn train_model(graphs: &Path, c: &Cond, epochs: u32, extra: &[String], dir: &Path) -> Result<PathBuf> {
    let mut sets = vec![
        format!("mass={}", c.mass),
        format!("speed={}", c.speed),
        format!("epochs={epochs}"),
        "train.progress=false".to_string(),
        "train.record_time=true".to_string(),
    ];
    sets.extend(extra.iter().cloned());
    run_with(&graphs.join("model-build.toml"), &sets, dir)?;
    let path = dir.join(c.model_name());
    std::fs::canonicalize(&path).with_context(|| format!("{}: model-build.toml wrote no model", path.display()))
}

/// The model of each condition: read from `given` (`--models`), or trained
/// into `dir` with `epochs` at most.
pub(super) fn models(
    given: Option<&Path>,
    graphs: &Path,
    epochs: u32,
    conds: &[Cond],
    dir: &Path,
) -> Result<Vec<Built>> {
    let mut built = Vec::new();
    for (k, c) in conds.iter().enumerate() {
        if let Some(m) = given {
            let path = m.join(c.model_name());
            ensure!(path.is_file(), "--models: {} is missing (train it with graphs/model-build.toml)", path.display());
            built.push(Built { path: std::fs::canonicalize(&path)? });
            continue;
        }
        eprintln!("[{}/{}] training the inverse model at {} …", k + 1, conds.len(), c.label());
        built.push(Built { path: train_model(graphs, c, epochs, &[], dir)? });
    }
    Ok(built)
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::Summary;

    fn report(es: f64, ratio: f64) -> RunReport {
        let s = Summary::default().value("E_s", es, "1").value("peak_psd_ratio", ratio, "1");
        RunReport {
            ticks: 0,
            base_rate: 1000.0,
            elapsed: std::time::Duration::ZERO,
            times: vec![],
            summaries: vec![("narx_es".into(), s)],
        }
    }

    #[test]
    fn the_gain_is_the_one_whose_peak_power_matches_on_a_log_scale() {
        // Ratios 0.3, 0.8, 1.5, 3: |ln| = 1.20, 0.22, 0.41, 1.10 → 0.8 wins,
        // although 1.5 is nearer 1 on a linear scale than 0.3 is.
        let runs =
            vec![(0.6, report(0.9, 0.3)), (0.8, report(0.5, 0.8)), (1.0, report(0.4, 1.5)), (1.2, report(0.7, 3.0))];
        let s = choose(&runs, "narx_es").unwrap();
        assert_eq!((s.gain, s.es, s.ratio), (0.8, 0.5, 0.8));
        assert!(choose(&runs, "other").is_err());
    }

    #[test]
    fn conditions_parse_and_refuse_nonsense() {
        let c = Cond::parse("60:3").unwrap();
        assert_eq!((c.mass, c.speed), (60.0, 3.0));
        assert_eq!(c.model_name(), "narx-60g-3cms.json");
        for bad in ["60", "a:3", "60:-1", "0:3"] {
            assert!(Cond::parse(bad).is_err(), "{bad}");
        }
    }
}
