//! `evflow report interp --cells narx|optimized|playback`: the
//! cross-validation of Fig. 5.6, 5.9 and 6.8 through the whole chain, on
//! the texture study (`evflow_nodes::synth::study`). At every trained
//! condition of a sample's plan the study builds the models (inverse NARX,
//! forward), records the sample and scores every method over the gain sweep
//! (`graphs/synthesize.toml`, as `report textures` does); the chosen
//! method's actuation at its Table 5.1 gain becomes the cell U_ij of the
//! grid. For every untrained condition `graphs/texture-cross-validation.toml`
//! interpolates the grid with the basic (§5.3.3) and the improved (Eq. 6.4)
//! scheme, plays it on the virtual display under the tribometer at that
//! condition, and scores the display's force by E_s against the real
//! sample's recording there, beside the repeat baseline and
//! record-and-playback. As a control, the same runs at every trained
//! condition, where an interpolation must give the cell back.
//!
//! Beside the dissertation's order (interpolate the actuations), **forces
//! first**: the recorded forces interpolated by the same scheme, then the
//! actuation synthesized for the untrained condition with the nearest
//! trained condition's model — the inverse NARX model in the graph
//! (`--cells narx`), or the optimized synthesis offline through its forward
//! model (`--cells optimized`, `study::forces_first`). The table is
//! [`super::interp_cells_table`].

use super::interp::{plan_for, Args, Cells, GridPlan};
use super::interp_cells_table::{table, Cell, Run, SchemeRun};
use super::lab_recording::constant_speed_force;
use anyhow::{anyhow, bail, ensure, Context, Result};
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::recording::format::Recording;
use evflow_nodes::synth::study::cells::{write_actuation, write_force};
use evflow_nodes::synth::study::forces_first::{self, FfInputs};
use evflow_nodes::synth::study::models::{self, Models};
use evflow_nodes::synth::study::recordings::{self, record_pair};
use evflow_nodes::synth::study::row::{self, Method, Row, RowInputs};
use evflow_nodes::synth::study::setup::{Cond, Profile};
use evflow_nodes::synth::study::spectrum::gated;
use evflow_nodes::synth::study::xval::{self, Grids, XvalInputs, GRAPH};
use evflow_nodes::texture::freqvel::main_frequency;
use evflow_nodes::texture::kernel::INTERP_CUTOFF;
use evflow_tools::plot::{Plot, Series};
use std::path::Path;
use std::time::Instant;

/// The optimized synthesis' objective (`synth.optimize`), as `report
/// textures` uses by default; where a pass keeps less than one second at
/// constant speed (one pass at 7 cm/s) the waveform ("time") instead
/// (`study::recordings::objective_for`).
const OBJECTIVE: &str = "expected";

/// The method whose cells form the grid, its channel in
/// graphs/synthesize.toml's recording, and its grid folder's prefix.
fn method_of(cells: Cells) -> Result<(Method, &'static str, &'static str)> {
    Ok(match cells {
        Cells::Narx => (Method::NarxBinary, "u", "narx"),
        Cells::Optimized => (Method::Optimized, "optimized_u", "optimized"),
        Cells::Playback => (Method::Playback, "playback_u", "playback"),
        Cells::Recorded => bail!("--cells recorded has no synthesis"),
    })
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

/// A trained condition of one sample: its models and the row the study scored there.
struct Trained<'a> {
    models: &'a Models,
    row: Row,
}

impl Trained<'_> {
    fn gain(&self, m: Method) -> Result<f64> {
        Ok(self.row.method(m).ok_or_else(|| anyhow!("the study scored no {}", m.label()))?.chosen.table51.gain)
    }
}

/// Everything one sample's runs share.
struct Ctx<'a> {
    a: &'a Args,
    graphs: &'a Path,
    method: Method,
    recordings: &'a Path,
    work: &'a Path,
    sample: &'a str,
    period: f64,
    grids: Grids,
}

/// Runs the cross-validation at `c` with both schemes, and forces first
/// with the model of `near`.
fn cross_validate(x: &Ctx<'_>, c: &Cond, near: &Trained<'_>) -> Result<Run> {
    let band = [x.a.band[0], x.a.band[1]];
    let mut schemes = Vec::new();
    for scheme in ["basic", "improved"] {
        let what = || format!("{} at {}, {scheme} scheme", x.sample, c.label());
        let inputs = XvalInputs {
            graphs: x.graphs,
            recordings: x.recordings,
            sample: x.sample,
            cond: *c,
            grids: &x.grids,
            scheme,
            period: x.period,
            model: &near.models.narx,
            ff_gain: near.gain(Method::NarxBinary)?,
            band,
            dir: x.work.join("xval").join(format!("{}-{}-{scheme}", x.sample, c.tag())),
        };
        let scores = xval::run(&inputs).with_context(what)?;
        let recording = xval::recording(&inputs);
        let ff = match x.method {
            Method::Optimized => {
                let objective = recordings::objective_for(&recording, c.speed, OBJECTIVE)?;
                let f = forces_first::optimized(&FfInputs {
                    graphs: x.graphs,
                    recordings: x.recordings,
                    sample: x.sample,
                    cond: *c,
                    interpolated: &recording,
                    forward: &near.models.forward,
                    narx: &near.models.narx,
                    gain: near.gain(Method::Optimized)?,
                    iterations: x.a.iterations,
                    objective,
                    band,
                    dir: x.work.join("ff").join(format!("{}-{}-{scheme}", x.sample, c.tag())),
                })
                .with_context(what)?;
                let played = f.actuation.parent().map(|d| d.join("played").join("played")).unwrap_or_default();
                Some((f.es, f.peak_hz, played, "force"))
            }
            Method::NarxBinary => Some((scores.ff_narx, scores.ff_peak_hz, recording.clone(), "ff_force")),
            _ => None,
        };
        schemes.push(SchemeRun { scores, ff, recording });
    }
    let improved = schemes.pop().ok_or_else(|| anyhow!("no runs"))?;
    let basic = schemes.pop().ok_or_else(|| anyhow!("no runs"))?;
    Ok(Run { sample: x.sample.to_string(), cond: *c, near: near.row.cond, schemes: [basic, improved] })
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
        let path = recordings.join(recordings::name(sample, c, 1));
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

/// Spectra of the real force and of the display's force under each scheme
/// (and forces first, improved), over the constant-speed stretch.
fn spectra_plot(run: &Run, method: Method) -> Result<Plot> {
    let open = |p: &Path| Recording::open(p).map_err(|e| anyhow!("{e}"));
    let ch = |rec: &Recording, n: &str, p: &Path| -> Result<Vec<f64>> {
        rec.channel(n).map(|c| c.to_vec()).ok_or_else(|| anyhow!("{}: no `{n}` channel", p.display()))
    };
    let pts = |x: &[f64], gate: &[f64], rate: f64| -> Result<Vec<(f64, f64)>> {
        let s = gated(x, gate, rate)?;
        Ok(s.iter().enumerate().skip(2).take(199).map(|(f, y)| (f as f64, *y)).collect())
    };
    let mut series = Vec::new();
    for (k, s) in run.schemes.iter().enumerate() {
        let rec = open(&s.recording)?;
        let gate = ch(&rec, "steady", &s.recording)?;
        if k == 0 {
            series.push(Series::line(
                "real (repetition 2)",
                pts(&ch(&rec, "real_force", &s.recording)?, &gate, rec.rate())?,
            ));
        }
        let name = ["basic (§5.3.3)", "improved (Eq. 6.4)"][k];
        let force = ch(&rec, "narx_force", &s.recording)?;
        series.push(Series::line(format!("{name}, E_s {:.2}", s.scores.cells), pts(&force, &gate, rec.rate())?));
        if let (1, Some((es, _, path, channel))) = (k, &s.ff) {
            let ff = open(path)?;
            let (f, g) = (ch(&ff, channel, path)?, ch(&ff, "steady", path)?);
            series.push(Series::line(format!("forces first, improved, E_s {es:.2}"), pts(&f, &g, ff.rate())?));
        }
    }
    Ok(Plot {
        title: format!("{}, {}: interpolated cells ({}) on the display", run.sample, run.cond.label(), method.label()),
        x_label: "frequency (Hz)".into(),
        y_label: "magnitude".into(),
        log_x: false,
        log_y: true,
        series,
    })
}

/// Runs `evflow report interp --cells narx|optimized|playback` for `samples`.
pub(super) fn main(a: &Args, samples: &[String]) -> Result<()> {
    let (method, channel, prefix) = method_of(a.cells)?;
    ensure!(!a.gains.is_empty() && a.gains.iter().all(|g| g.is_finite() && *g > 0.0), "--gains: positive numbers");
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    for g in [
        "model-build.toml",
        "forward-build.toml",
        "record-textures.toml",
        "synthesize.toml",
        "synthesize-optimized.toml",
        "play-actuation.toml",
        GRAPH,
    ] {
        ensure!(graphs.join(g).is_file(), "--graphs: {} has no {g} (run from the repository root)", graphs.display());
    }
    let started = Instant::now();
    let out = std::fs::canonicalize(&a.out).with_context(|| format!("{}: cannot open", a.out.display()))?;
    let (model_dir, grids) = (out.join("models"), out.join("grids"));
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let work = tmp.path();
    let recordings = work.join("textures");
    let profile = Profile::nominal();

    let plans: Vec<GridPlan> = samples.iter().map(|s| plan_for(s)).collect();
    let conds = trained_conditions(&plans);
    let mut built = Vec::new();
    for (k, c) in conds.iter().enumerate() {
        built.push(match &a.models {
            Some(dir) => models::given(dir, c).map_err(|e| anyhow!("--models: {e}"))?,
            None => {
                eprintln!("[{}/{}] building the models at {} …", k + 1, conds.len(), c.label());
                models::build(&graphs, &profile, c, a.epochs, false, &model_dir)?
            }
        });
    }

    let steps: usize = plans.iter().map(|p| 2 * p.loads.len() * p.speeds.len() + p.validate.len()).sum();
    let mut step = 0;
    let (mut cells, mut rows, mut periods) = (Vec::new(), Vec::new(), Vec::new());
    for (s, p) in samples.iter().zip(&plans) {
        let trained_conds: Vec<Cond> =
            p.loads.iter().flat_map(|&mass| p.speeds.iter().map(move |&speed| Cond { mass, speed })).collect();
        let grid_of = |what: &str| grids.join(format!("{what}-{s}"));
        let mut trained = Vec::new();
        let mut above = Vec::new();
        for c in &trained_conds {
            step += 1;
            eprintln!("[{step}/{steps}] {s} at {} (trained): every method over {} gains …", c.label(), a.gains.len());
            record_pair(&graphs, &profile, s, c, &recordings)?;
            let m = &built[conds.iter().position(|x| x == c).ok_or_else(|| anyhow!("{}: no models", c.label()))?];
            let objective = recordings::objective_for(&recordings.join(recordings::name(s, c, 1)), c.speed, OBJECTIVE)?;
            let r = row::run(&RowInputs {
                graphs: &graphs,
                profile: &profile,
                sample: s,
                cond: *c,
                models: m,
                recordings: &recordings,
                gains: &a.gains,
                iterations: a.iterations,
                objective,
                optimized: None,
                dir: work.join("rows").join(format!("{s}-{}", c.tag())),
            })?;
            let t = Trained { models: m, row: r };
            let gain = t.gain(method)?;
            let cell = write_actuation(&t.row.recording(gain), channel, &grid_of(prefix), s, c, gain)?;
            let pg = t.gain(Method::Playback)?;
            write_actuation(&t.row.recording(pg), "playback_u", &grid_of("playback"), s, c, pg)?;
            write_force(&recordings.join(recordings::name(s, c, 1)), &grid_of("forces"), s, c)?;
            above.push(share_above_cutoff(&cell)?);
            trained.push(t);
        }
        let period = texture_period(&recordings, s, &trained_conds, &a.band)?;
        periods.push((s.clone(), period));
        let x = Ctx {
            a,
            graphs: &graphs,
            method,
            recordings: &recordings,
            work,
            sample: s,
            period,
            grids: Grids { cells: grid_of(prefix), playback: grid_of("playback"), forces: grid_of("forces") },
        };
        // The control: each trained condition through the graph, once the grid is whole.
        for (t, above_cutoff) in trained.iter().zip(above) {
            step += 1;
            let c = t.row.cond;
            eprintln!("[{step}/{steps}] {s} at {} (trained): the cell through interp, on the display …", c.label());
            let near = &trained[xval::nearest(&c, &trained_conds)];
            let run = cross_validate(&x, &c, near)?;
            let (chosen, played) = (t.row.method(method), t.row.method(Method::Playback));
            let (chosen, played) = chosen.zip(played).ok_or_else(|| anyhow!("the study scored no method"))?;
            cells.push(Cell {
                repeat: t.row.repeat.rect,
                cell: chosen.chosen.table51,
                playback: played.chosen.table51,
                above_cutoff,
                run,
            });
        }
        for &(mass, speed) in &p.validate {
            let c = Cond { mass, speed };
            step += 1;
            eprintln!("[{step}/{steps}] {s} at {} (untrained): interpolating, playing on the display …", c.label());
            record_pair(&graphs, &profile, s, &c, &recordings)?;
            let near = &trained[xval::nearest(&c, &trained_conds)];
            rows.push((p.velocity_interpolated(speed), cross_validate(&x, &c, near)?));
        }
    }
    let md = table(a, method, &periods, &cells, &rows, started.elapsed().as_secs_f64());
    print!("{md}");
    super::save_markdown(&out.join(format!("interp-{prefix}.md")), &md)?;
    for (_, run) in &rows {
        let name = format!("interp-{prefix}-{}-{}.png", run.sample, run.cond.tag());
        super::save_png(&spectra_plot(run, method)?, &out.join(name));
    }
    Ok(())
}
