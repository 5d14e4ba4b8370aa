//! `evflow report interp --cells narx`: the cross-validation of Fig. 5.6,
//! 5.9 and 6.8 through the whole chain of the dissertation. At every trained
//! condition of a sample's plan an inverse NARX model
//! (`graphs/model-build.toml`) synthesizes the actuation U_ij from the
//! sample's recorded force (`graphs/synthesize.toml`, the gain chosen over
//! the sweep as Table 5.1 does); these cells form the grid. For every
//! untrained condition `graphs/texture-cross-validation.toml` interpolates
//! the grid with the basic (§5.3.3) and the improved (Eq. 6.4) scheme, plays
//! the result on the virtual display under the tribometer at that condition,
//! and scores the display's force by E_s against the real sample's
//! recording there, beside the repeat baseline and record-and-playback
//! (the same interpolation over the recorded forces, played on the display).
//! As a control, the same graph runs at every trained condition, where an
//! interpolation must give the cell back.
//!
//! Beside the dissertation's order (interpolate the actuations), the graph
//! also runs **forces first**: the recorded forces interpolated by the same
//! scheme, then the inverse model of the nearest trained condition
//! synthesizes the actuation ([`nearest`]).

use super::interp::{plan_for, Args, GridPlan};
use super::lab_recording::{constant_speed_force, recording_in, Condition};
use super::synthesis::{
    check_graphs, gated_spectrum, models, record_pair, synth_dir, synthesize_condition, value, write_cell, Cond,
    Synthesis,
};
use crate::cli::graph_args::run_with;
use anyhow::{anyhow, ensure, Context, Result};
use evflow_engine::RunReport;
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::recording::format::Recording;
use evflow_nodes::texture::freqvel::main_frequency;
use evflow_nodes::texture::kernel::INTERP_CUTOFF;
use evflow_tools::plot::{Plot, Series};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The cross-validation graph, in `--graphs`.
const GRAPH: &str = "texture-cross-validation.toml";

/// What one run of the graph scored.
#[derive(Debug, Clone, Copy)]
struct Scores {
    /// E_s of the interpolated NARX actuation on the display.
    narx: f64,
    /// E_s of the interpolated recorded forces on the display.
    playback: f64,
    /// E_s of repetition 1 against repetition 2.
    repeat: f64,
    /// E_s of forces first: the interpolated forces, the nearest model's actuation, on the display.
    ff: f64,
    /// Main peak of the NARX chain's force, Hz.
    narx_peak_hz: f64,
    /// Main peak of the forces-first chain's force, Hz.
    ff_peak_hz: f64,
    /// Main peak of the real force, Hz.
    real_peak_hz: f64,
}

impl Scores {
    fn from(r: &RunReport) -> Result<Self> {
        Ok(Self {
            narx: value(r, "narx_es", "E_s")?,
            playback: value(r, "playback_es", "E_s")?,
            repeat: value(r, "repeat_es", "E_s")?,
            ff: value(r, "ff_es", "E_s")?,
            narx_peak_hz: value(r, "narx_es", "peak_psd_freq_virtual")?,
            ff_peak_hz: value(r, "ff_es", "peak_psd_freq_virtual")?,
            real_peak_hz: value(r, "narx_es", "peak_psd_freq_real")?,
        })
    }
}

/// One condition through the graph with both schemes.
struct Run {
    sample: String,
    cond: Cond,
    /// Basic, improved.
    scores: [Scores; 2],
    /// Their output folders.
    dirs: [PathBuf; 2],
}

/// One trained cell of one sample, and the control run at its condition.
struct Cell {
    syn: Synthesis,
    /// Share of the cell's power above `interp`'s anti-alias cutoff.
    above_cutoff: f64,
    run: Run,
}

/// Every trained condition of the plans, each once, in order of appearance.
fn trained_conditions(plans: &[GridPlan]) -> Vec<Cond> {
    let mut conds: Vec<Cond> = Vec::new();
    for p in plans {
        for &mass in &p.loads {
            for &speed in &p.speeds {
                let c = Cond { mass, speed };
                if !conds.contains(&c) {
                    conds.push(c);
                }
            }
        }
    }
    conds
}

/// The trained condition nearest to `c`, with its model and gain
/// (`evflow_nodes::narx::nearest`: load and speed each in units of its
/// span; a tie goes to the first in the plan's order, lower load then
/// lower speed).
fn nearest<'a>(c: &Cond, trained: &'a [(Cond, PathBuf, f64)]) -> &'a (Cond, PathBuf, f64) {
    let grid: Vec<(f64, f64)> = trained.iter().map(|t| (t.0.mass, t.0.speed)).collect();
    &trained[evflow_nodes::narx::nearest::nearest(&grid, c.mass, c.speed).unwrap_or(0)]
}

/// Runs the cross-validation graph for `sample` at `c` with both schemes,
/// the grids of `sample` in `grids` and its recordings in `recordings`.
/// `period` is the sample's main period (cm), to which `interp` rounds its
/// loop; `near` the model and gain of the nearest trained condition (forces first).
#[allow(clippy::too_many_arguments)]
fn cross_validate(
    a: &Args,
    grids: &Path,
    recordings: &Path,
    sample: &str,
    period: f64,
    c: &Cond,
    near: &(Cond, PathBuf, f64),
    work: &Path,
) -> Result<Run> {
    let grid = |what: &str| format!("{:?}", grids.join(format!("{what}-{sample}")).display().to_string());
    let mut scores = Vec::new();
    let mut dirs = Vec::new();
    for scheme in ["basic", "improved"] {
        let out = work.join(format!("xval-{sample}-{}-{}-{scheme}", c.mass, c.speed));
        std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
        let mut sets = vec![
            format!("recordings={:?}", recordings.display().to_string()),
            format!("sample=\"{sample}\""),
            format!("mass={}", c.mass),
            format!("speed={}", c.speed),
            format!("grid={}", grid("narx")),
            format!("playback_grid={}", grid("playback")),
            format!("scheme=\"{scheme}\""),
            format!("period={period}"),
            format!("model={:?}", near.1.display().to_string()),
            format!("ff_gain={}", near.2),
        ];
        for node in ["narx_es", "playback_es", "repeat_es", "ff_es"] {
            sets.push(format!("{node}.fmin={}", a.band[0]));
            sets.push(format!("{node}.fmax={}", a.band[1]));
        }
        let r = run_with(&a.graphs.join(GRAPH), &sets, &out)
            .with_context(|| format!("{sample} at {}, {scheme} scheme", c.label()))?;
        scores.push(Scores::from(&r).with_context(|| format!("{sample} at {}, {scheme} scheme", c.label()))?);
        dirs.push(out);
    }
    Ok(Run {
        sample: sample.into(),
        cond: *c,
        scores: [scores[0], scores[1]],
        dirs: [dirs[0].clone(), dirs[1].clone()],
    })
}

/// Share of the power of the recording `path` (channel `u`) above
/// `interp`'s anti-alias cutoff (Welch, 256-sample Hann segments).
fn share_above_cutoff(path: &Path) -> Result<f64> {
    let rec = Recording::open(path).map_err(|e| anyhow!("{e}"))?;
    let u = rec.channel("u").ok_or_else(|| anyhow!("{}: no `u` channel", path.display()))?;
    let cfg = SpectrumConfig { rate: rec.rate(), nfft: 256, window: Window::Hann, overlap: 0.5 };
    let s = averaged_spectrum(u, cfg)
        .map_err(|e| anyhow!("{}: {e}", path.display()))?
        .ok_or_else(|| anyhow!("{}: too short for a spectrum", path.display()))?;
    let edge = INTERP_CUTOFF * (s.power.len() - 1) as f64;
    let above: f64 = s.power.iter().enumerate().filter(|(k, _)| *k as f64 > edge).map(|(_, p)| p).sum();
    Ok(above / s.power.iter().sum::<f64>().max(f64::MIN_POSITIVE))
}

/// The sample's main spatial period, cm: the main-component frequency of
/// its recordings at the trained conditions (repetition 1, constant-speed
/// force) against their speeds, a line through the origin (§6.3: f = v/λ).
/// `interp` rounds its loop to a whole number of it (its `period`).
fn texture_period(recordings: &Path, sample: &str, trained: &[Cond], band: &[f64]) -> Result<f64> {
    let (mut vf, mut vv) = (0.0, 0.0);
    for c in trained {
        let name = Condition { sample, mass: c.mass, speed: c.speed, passes: 1, rep: 1 }.name();
        let path = recordings.join(name);
        let rec = Recording::open(&path).map_err(|e| anyhow!("{e}"))?;
        let (rate, force) = constant_speed_force(&rec, c.speed, &path)?;
        let f = main_frequency(&force, rate, band[0], band[1])
            .ok_or_else(|| anyhow!("{}: no spectral peak in {}–{} Hz", path.display(), band[0], band[1]))?;
        vf += c.speed * f;
        vv += c.speed * c.speed;
    }
    ensure!(vf > 0.0, "{sample}: no main frequency to take a period from");
    Ok(vv / vf)
}

/// Spectra of the real force and of the display's force under each scheme,
/// over the constant-speed stretch (as `metric` takes them).
fn spectra_plot(run: &Run) -> Result<Plot> {
    let mut series = Vec::new();
    for (k, dir) in run.dirs.iter().enumerate() {
        let rec = recording_in(dir)?;
        let ch = |n: &str| rec.channel(n).ok_or_else(|| anyhow!("{}: no `{n}` channel", dir.display()));
        let gate = ch("steady")?;
        let pts = |x: &[f64]| -> Result<Vec<(f64, f64)>> {
            let s = gated_spectrum(x, gate, rec.rate())?;
            Ok(s.iter().enumerate().skip(2).take(199).map(|(f, y)| (f as f64, *y)).collect())
        };
        if k == 0 {
            series.push(Series::line("real (repetition 2)", pts(ch("real_force")?)?));
        }
        let name = ["basic (§5.3.3)", "improved (Eq. 6.4)"][k];
        series.push(Series::line(format!("{name}, E_s {:.2}", run.scores[k].narx), pts(ch("narx_force")?)?));
        if k == 1 {
            series.push(Series::line(
                format!("forces first, improved, E_s {:.2}", run.scores[k].ff),
                pts(ch("ff_force")?)?,
            ));
        }
    }
    Ok(Plot {
        title: format!("{}, {}: interpolated NARX cells on the display", run.sample, run.cond.label()),
        x_label: "frequency (Hz)".into(),
        y_label: "magnitude".into(),
        log_x: false,
        log_y: true,
        series,
    })
}

/// Runs `evflow report interp --cells narx` for `samples`.
pub(super) fn main(a: &Args, samples: &[String]) -> Result<()> {
    ensure!(!a.gains.is_empty() && a.gains.iter().all(|g| g.is_finite() && *g > 0.0), "--gains: positive numbers");
    check_graphs(&a.graphs, &["model-build.toml", "record-textures.toml", "synthesize.toml", GRAPH])?;
    let started = Instant::now();
    let model_dir = a.out.join("models");
    let grids = a.out.join("grids");
    for d in [&model_dir, &grids] {
        std::fs::create_dir_all(d).with_context(|| format!("{}: cannot create", d.display()))?;
    }
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let recordings = tmp.path().join("textures");
    std::fs::create_dir_all(&recordings).with_context(|| format!("{}: cannot create", recordings.display()))?;

    let plans: Vec<GridPlan> = samples.iter().map(|s| plan_for(s)).collect();
    let conds = trained_conditions(&plans);
    let built = models(a.models.as_deref(), &a.graphs, a.epochs, &conds, &model_dir)?;
    let model_of = |c: &Cond| &built[conds.iter().position(|x| x == c).expect("every trained condition has a model")];

    let steps: usize = plans.iter().map(|p| 2 * p.loads.len() * p.speeds.len() + p.validate.len()).sum();
    let mut step = 0;
    let (mut cells, mut rows, mut periods) = (Vec::new(), Vec::new(), Vec::new());
    for (s, p) in samples.iter().zip(&plans) {
        let trained: Vec<Cond> =
            p.loads.iter().flat_map(|&mass| p.speeds.iter().map(move |&speed| Cond { mass, speed })).collect();
        let mut syns = Vec::new();
        for c in &trained {
            step += 1;
            eprintln!("[{step}/{steps}] {s} at {} (trained): the cell, over {} gains …", c.label(), a.gains.len());
            let syn = synthesize_condition(&a.graphs, s, c, &model_of(c).path, &a.gains, &recordings, tmp.path())?;
            let narx_run = synth_dir(tmp.path(), s, c, syn.narx.gain);
            let cell = write_cell(&narx_run, "u", &grids.join(format!("narx-{s}")), s, c, syn.narx.gain)?;
            let played = synth_dir(tmp.path(), s, c, syn.playback.gain);
            write_cell(&played, "playback_u", &grids.join(format!("playback-{s}")), s, c, syn.playback.gain)?;
            syns.push((syn, share_above_cutoff(&cell)?));
        }
        let near: Vec<(Cond, PathBuf, f64)> =
            trained.iter().zip(&syns).map(|(c, (syn, _))| (*c, model_of(c).path.clone(), syn.narx.gain)).collect();
        let period = texture_period(&recordings, s, &trained, &a.band)?;
        periods.push((s.clone(), period));
        // The control: each trained condition through the graph, once the grid is whole.
        for (c, (syn, above_cutoff)) in trained.iter().zip(syns) {
            step += 1;
            eprintln!("[{step}/{steps}] {s} at {} (trained): the cell through interp, on the display …", c.label());
            let run = cross_validate(a, &grids, &recordings, s, period, c, nearest(c, &near), tmp.path())?;
            cells.push(Cell { syn, above_cutoff, run });
        }
        for &(mass, speed) in &p.validate {
            let c = Cond { mass, speed };
            step += 1;
            eprintln!("[{step}/{steps}] {s} at {} (untrained): interpolating, playing on the display …", c.label());
            record_pair(&a.graphs, s, &c, &recordings)?;
            let near = nearest(&c, &near);
            let run = cross_validate(a, &grids, &recordings, s, period, &c, near, tmp.path())?;
            rows.push((p.velocity_interpolated(speed), run, near.0));
        }
    }
    let md = table(a, &periods, &cells, &rows, started.elapsed().as_secs_f64());
    print!("{md}");
    super::save_markdown(&a.out.join("interp-narx.md"), &md)?;
    for (_, run, _) in &rows {
        let name = format!("interp-narx-{}-{}g-{}cms.png", run.sample, run.cond.mass, run.cond.speed);
        super::save_png(&spectra_plot(run)?, &a.out.join(name));
    }
    Ok(())
}

/// The Markdown report: the trained cells with their control, then the
/// cross-validation.
fn table(a: &Args, periods: &[(String, f64)], cells: &[Cell], rows: &[(bool, Run, Cond)], seconds: f64) -> String {
    let (lo, hi) = (a.band[0], a.band[1]);
    let mut md = String::new();
    let _ = write!(md, "Loops of whole main periods (`interp`'s `period`, measured on the trained recordings):");
    for (k, (s, p)) in periods.iter().enumerate() {
        let _ = write!(md, "{} {s} {:.4} mm", if k == 0 { "" } else { "," }, p * 10.0);
    }
    let _ = writeln!(md, ".\n");
    let _ = writeln!(
        md,
        "## Trained cells U_ij and the control\n\nE_s (Eq. 5.2, {lo}–{hi} Hz, constant-speed stretch) against \
         repetition 2 at the trained condition itself. `synthesize`: the cell as graphs/synthesize.toml scored it \
         (gain chosen over {:?} as Table 5.1 does). `through interp`: the grid interpolated at the cell's own \
         condition by graphs/{GRAPH} — no interpolation is needed there, so both schemes should give the cell back. \
         `above cutoff`: the share of the cell's power above {:.0} % of the Nyquist frequency, which `interp`'s \
         re-sampling kernel removes.\n",
        a.gains,
        INTERP_CUTOFF * 100.0
    );
    let _ = writeln!(
        md,
        "| sample | condition | repeat baseline | NARX E_s, synthesize | gain | through interp: basic | improved | above cutoff | record-and-playback E_s | its gain | forces first: basic | improved |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for c in cells {
        let [b, i] = c.run.scores;
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {} | {:.3} | {:.3} | {:.0} % | {:.3} | {} | {:.3} | {:.3} |",
            c.run.sample,
            c.run.cond.label(),
            c.syn.repeat,
            c.syn.narx.es,
            c.syn.narx.gain,
            b.narx,
            i.narx,
            c.above_cutoff * 100.0,
            c.syn.playback.es,
            c.syn.playback.gain,
            b.ff,
            i.ff
        );
    }
    let _ = writeln!(
        md,
        "\n## Cross-validation on the display (Fig. 5.6, 5.9, 6.8)\n\nThe grid interpolated to each untrained \
         condition and played on the virtual display there (graphs/{GRAPH}); E_s ({lo}–{hi} Hz) against \
         repetition 2 of the real recording at that condition; the main peak of each force.\n"
    );
    let _ = writeln!(
        md,
        "| sample | load (g) | speed (cm/s) | repeat baseline | NARX basic (§5.3.3) | NARX improved (Eq. 6.4) | improved better | main peak, Hz: real / basic / improved | record-and-playback basic | record-and-playback improved | forces first: model | basic | improved | improved better | main peak, Hz: basic / improved |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---|---|---:|---:|---|---:|---:|---|---|");
    for (velocity, r, near) in rows {
        let [b, i] = r.scores;
        let verdict = |better: bool| match (velocity, better) {
            (false, _) => "— (no velocity step)",
            (true, true) => "yes",
            (true, false) => "**no**",
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {} | {} / {} / {} | {:.3} | {:.3} | {} | {:.3} | {:.3} | {} | {} / {} |",
            r.sample,
            r.cond.mass,
            r.cond.speed,
            i.repeat,
            b.narx,
            i.narx,
            verdict(i.narx < b.narx),
            i.real_peak_hz,
            b.narx_peak_hz,
            i.narx_peak_hz,
            b.playback,
            i.playback,
            near.label(),
            b.ff,
            i.ff,
            verdict(i.ff < b.ff),
            b.ff_peak_hz,
            i.ff_peak_hz
        );
    }
    let mean = |f: &dyn Fn(&Run) -> f64| rows.iter().map(|(_, r, _)| f(r)).sum::<f64>() / rows.len().max(1) as f64;
    let velocity: Vec<&Run> = rows.iter().filter(|(v, _, _)| *v).map(|(_, r, _)| r).collect();
    let wins = velocity.iter().filter(|r| r.scores[1].narx < r.scores[0].narx).count();
    let ff_wins = velocity.iter().filter(|r| r.scores[1].ff < r.scores[0].ff).count();
    let _ = writeln!(
        md,
        "\nMean E_s: repeat {:.3}; NARX basic {:.3}, improved {:.3}; record-and-playback basic {:.3}, improved {:.3}. \
         The improved scheme is better on {wins} of {} velocity-interpolated conditions.\n\n\
         Forces first (the recorded forces interpolated, then the nearest trained condition's inverse model): \
         mean E_s basic {:.3}, improved {:.3}; the improved scheme is better on {ff_wins} of {} velocity-interpolated \
         conditions. Whole report: {seconds:.0} s.",
        mean(&|r| r.scores[1].repeat),
        mean(&|r| r.scores[0].narx),
        mean(&|r| r.scores[1].narx),
        mean(&|r| r.scores[0].playback),
        mean(&|r| r.scores[1].playback),
        velocity.len(),
        mean(&|r| r.scores[0].ff),
        mean(&|r| r.scores[1].ff),
        velocity.len()
    );
    md
}
