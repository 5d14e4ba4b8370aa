//! The cross-validation of Fig. 5.6, 5.9 and 6.8 through the whole chain
//! (`evflow report interp --cells …`). At every trained condition of a
//! sample's plan ([`GridPlan`]) the study builds the models, records the
//! sample and scores every method over the gain sweep ([`row::run`]); the
//! chosen method's actuation at its Table 5.1 gain becomes the cell U_ij
//! of the grid. For every untrained condition [`xval::run`] interpolates
//! the grid with the basic (§5.3.3) and the improved (Eq. 6.4) scheme and
//! plays it on the virtual display, beside the repeat baseline and
//! record-and-playback; as a control, the same runs at every trained
//! condition, where an interpolation must give the cell back.
//!
//! Beside the dissertation's order, **forces first**: the recorded forces
//! interpolated, then the actuation synthesized for the untrained condition
//! with the nearest trained condition's model — the inverse NARX model in
//! the graph, or the optimized synthesis offline through its forward model
//! ([`forces_first::optimized`]).

use super::cells::{write_actuation, write_force};
use super::constant_speed;
use super::forces_first::{self, FfInputs};
use super::gains::AtGain;
use super::grid_plan::{trained_conditions, GridPlan};
use super::models::{self, Models};
use super::recordings::{self, record_pair};
use super::row::{self, Method, Row, RowInputs};
use super::setup::{Cond, Profile};
use super::xval::{self, Grids, Scores, XvalInputs};
use super::StudyError;
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::recording::format::Recording;
use evflow_nodes::texture::freqvel::main_frequency;
use evflow_nodes::texture::kernel::INTERP_CUTOFF;
use std::path::{Path, PathBuf};

/// The channel of graphs/synthesize.toml's recording that holds a method's
/// actuation, and the prefix of its grid folders (`PREFIX-SAMPLE`).
pub fn grid_of(method: Method) -> (&'static str, &'static str) {
    match method {
        Method::NarxBinary => ("u", "narx"),
        Method::NarxMultilevel => ("narx_ml_u", "narx-multilevel"),
        Method::Optimized => ("optimized_u", "optimized"),
        Method::Playback => ("playback_u", "playback"),
    }
}

/// What a cross-validation covers and how.
#[derive(Debug, Clone)]
pub struct CrossvalConfig<'a> {
    /// The folder of the shipped graphs.
    pub graphs: &'a Path,
    /// The texture samples (each with its [`GridPlan::of`]).
    pub samples: &'a [String],
    /// The method whose cells form the grid.
    pub method: Method,
    /// The gain sweep.
    pub gains: &'a [f64],
    /// The optimized synthesis' iteration budget.
    pub iterations: usize,
    /// Its objective (`synth.optimize` takes the waveform where a pass is
    /// shorter than one spectral segment).
    pub objective: &'a str,
    /// NARX training epochs at most.
    pub epochs: u32,
    /// E_s band, Hz (and where the main frequency is looked for).
    pub band: [f64; 2],
    /// A folder of models (`narx-…json`, `forward-…json` per condition) to
    /// use instead of building them.
    pub given_models: Option<&'a Path>,
    /// Where built models go.
    pub models_out: &'a Path,
    /// Where the grids go (`PREFIX-SAMPLE`, `playback-SAMPLE`, `forces-SAMPLE`).
    pub grids: &'a Path,
    /// Where recordings and runs go.
    pub work: &'a Path,
    /// The lab profile: its tribometer, display and sensor record, train and
    /// play everything.
    pub profile: &'a Profile,
}

/// One scheme's run at one condition.
#[derive(Debug, Clone)]
pub struct SchemeRun {
    /// What the cross-validation graph scored.
    pub scores: Scores,
    /// Forces first with the cells' method: E_s, main peak (Hz), and the
    /// recording and channel of the display's force (None: no such order,
    /// as for playback cells).
    pub ff: Option<(f64, f64, PathBuf, &'static str)>,
    /// The graph's recording.
    pub recording: PathBuf,
}

impl SchemeRun {
    /// Forces first's E_s (NaN without that order).
    pub fn ff_es(&self) -> f64 {
        self.ff.as_ref().map_or(f64::NAN, |f| f.0)
    }
}

/// One condition through the graph with both schemes.
#[derive(Debug, Clone)]
pub struct Run {
    /// The texture sample.
    pub sample: String,
    /// The condition.
    pub cond: Cond,
    /// The nearest trained condition (forces first).
    pub near: Cond,
    /// Basic, improved.
    pub schemes: [SchemeRun; 2],
}

/// One trained cell and the control run at its condition.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Repeat baseline at the condition (rect E_s).
    pub repeat: f64,
    /// The cell's method at its Table 5.1 gain, as graphs/synthesize.toml scored it.
    pub cell: AtGain,
    /// Record-and-playback at its Table 5.1 gain.
    pub playback: AtGain,
    /// Share of the cell's power above `interp`'s anti-alias cutoff.
    pub above_cutoff: f64,
    /// The control.
    pub run: Run,
}

/// What a cross-validation found.
#[derive(Debug, Clone)]
pub struct Crossval {
    /// Each sample's main spatial period, cm (`interp`'s `period`).
    pub periods: Vec<(String, f64)>,
    /// The trained cells with their controls.
    pub cells: Vec<Cell>,
    /// The untrained conditions: (interpolated over velocity, the run).
    pub rows: Vec<(bool, Run)>,
}

/// A trained condition of one sample: its models and the row the study scored there.
struct Trained<'a> {
    models: &'a Models,
    row: Row,
}

impl Trained<'_> {
    fn gain(&self, m: Method) -> Result<f64, StudyError> {
        let r = self.row.method(m).ok_or_else(|| StudyError::Config(format!("the study scored no {}", m.label())))?;
        Ok(r.chosen.table51.gain)
    }
}

/// Everything one sample's runs share.
struct Ctx<'a> {
    cfg: &'a CrossvalConfig<'a>,
    recordings: &'a Path,
    sample: &'a str,
    period: f64,
    grids: Grids,
}

/// Runs the cross-validation; `progress` hears (step, steps, what).
pub fn run(cfg: &CrossvalConfig<'_>, progress: &mut dyn FnMut(usize, usize, String)) -> Result<Crossval, StudyError> {
    if cfg.gains.is_empty() || cfg.gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(StudyError::Config("the gains must be positive numbers, at least one".into()));
    }
    let (channel, prefix) = grid_of(cfg.method);
    let recordings = cfg.work.join("textures");
    let profile = cfg.profile.clone();
    let plans: Vec<GridPlan> = cfg.samples.iter().map(|s| GridPlan::of(s)).collect();
    let conds = trained_conditions(&plans);
    let building = if cfg.given_models.is_some() { 0 } else { conds.len() };
    let steps = building + plans.iter().map(|p| 2 * p.trained().len() + p.validate.len()).sum::<usize>();
    let mut step = 0;
    let mut built = Vec::new();
    for c in &conds {
        built.push(match cfg.given_models {
            Some(dir) => models::given(dir, c)?,
            None => {
                step += 1;
                progress(step, steps, format!("building the models at {}", c.label()));
                models::build(cfg.graphs, &profile, c, cfg.epochs, false, true, cfg.models_out)?
            }
        });
    }
    let mut found = Crossval { periods: Vec::new(), cells: Vec::new(), rows: Vec::new() };
    for (s, p) in cfg.samples.iter().zip(&plans) {
        let trained_conds = p.trained();
        let grid_dir = |what: &str| cfg.grids.join(format!("{what}-{s}"));
        let mut trained = Vec::new();
        let mut above = Vec::new();
        for c in &trained_conds {
            step += 1;
            progress(
                step,
                steps,
                format!("{s} at {} (trained): every method over {} gains", c.label(), cfg.gains.len()),
            );
            record_pair(cfg.graphs, &profile, s, c, &recordings)?;
            let i = conds.iter().position(|x| x == c).unwrap_or(0);
            let rep1 = recordings.join(recordings::name(s, c, 1));
            let r = row::run(&RowInputs {
                graphs: cfg.graphs,
                profile: &profile,
                sample: s,
                cond: *c,
                models: &built[i],
                recordings: &recordings,
                gains: cfg.gains,
                iterations: cfg.iterations,
                objective: cfg.objective,
                optimized: None,
                dir: cfg.work.join("rows").join(format!("{s}-{}", c.tag())),
            })?;
            let t = Trained { models: &built[i], row: r };
            let gain = t.gain(cfg.method)?;
            let cell =
                write_actuation(&t.row.recording(gain), channel, &grid_dir(prefix), s, c, gain, cfg.method.carrier())?;
            let pg = t.gain(Method::Playback)?;
            write_actuation(&t.row.recording(pg), "playback_u", &grid_dir("playback"), s, c, pg, false)?;
            write_force(&rep1, &grid_dir("forces"), s, c)?;
            above.push(share_above_cutoff(&cell)?);
            trained.push(t);
        }
        let period = texture_period(&recordings, s, &trained_conds, cfg.band)?;
        found.periods.push((s.clone(), period));
        let x = Ctx {
            cfg,
            recordings: &recordings,
            sample: s,
            period,
            grids: Grids { cells: grid_dir(prefix), playback: grid_dir("playback"), forces: grid_dir("forces") },
        };
        // The control: each trained condition through the graph, once the grid is whole.
        for (t, above_cutoff) in trained.iter().zip(above) {
            step += 1;
            let c = t.row.cond;
            progress(step, steps, format!("{s} at {} (trained): the cell through interp, on the display", c.label()));
            let near = &trained[xval::nearest(&c, &trained_conds)];
            let run = cross_validate(&x, &c, near)?;
            let scored = |m: Method| {
                t.row.method(m).ok_or_else(|| StudyError::Config(format!("the study scored no {}", m.label())))
            };
            found.cells.push(Cell {
                repeat: t.row.repeat.rect,
                cell: scored(cfg.method)?.chosen.table51,
                playback: scored(Method::Playback)?.chosen.table51,
                above_cutoff,
                run,
            });
        }
        for &(mass, speed) in &p.validate {
            let c = Cond { mass, speed };
            step += 1;
            progress(step, steps, format!("{s} at {} (untrained): interpolating, playing on the display", c.label()));
            record_pair(cfg.graphs, &profile, s, &c, &recordings)?;
            let near = &trained[xval::nearest(&c, &trained_conds)];
            found.rows.push((p.velocity_interpolated(speed), cross_validate(&x, &c, near)?));
        }
    }
    Ok(found)
}

/// Runs the cross-validation at `c` with both schemes, and forces first
/// with the model of `near`.
fn cross_validate(x: &Ctx<'_>, c: &Cond, near: &Trained<'_>) -> Result<Run, StudyError> {
    let cfg = x.cfg;
    let mut schemes = Vec::new();
    for scheme in ["basic", "improved"] {
        let at = |e: StudyError| e.at(format!("{} at {}, {scheme} scheme", x.sample, c.label()));
        let inputs = XvalInputs {
            graphs: cfg.graphs,
            recordings: x.recordings,
            sample: x.sample,
            cond: *c,
            grids: &x.grids,
            scheme,
            period: x.period,
            model: &near.models.narx,
            ff_gain: near.gain(Method::NarxBinary)?,
            band: cfg.band,
            profile: cfg.profile,
            dir: cfg.work.join("xval").join(format!("{}-{}-{scheme}", x.sample, c.tag())),
        };
        let scores = xval::run(&inputs).map_err(at)?;
        let recording = xval::recording(&inputs);
        let ff = match cfg.method {
            Method::Optimized => {
                let f = forces_first::optimized(&FfInputs {
                    graphs: cfg.graphs,
                    recordings: x.recordings,
                    sample: x.sample,
                    cond: *c,
                    interpolated: &recording,
                    forward: &near.models.forward,
                    narx: &near.models.narx,
                    gain: near.gain(Method::Optimized)?,
                    iterations: cfg.iterations,
                    objective: cfg.objective,
                    band: cfg.band,
                    profile: cfg.profile,
                    dir: cfg.work.join("ff").join(format!("{}-{}-{scheme}", x.sample, c.tag())),
                })
                .map_err(at)?;
                let played = f.actuation.parent().map(|d| d.join("played").join("played")).unwrap_or_default();
                Some((f.es, f.peak_hz, played, "force"))
            }
            Method::NarxBinary => Some((scores.ff_narx, scores.ff_peak_hz, recording.clone(), "ff_force")),
            _ => None,
        };
        schemes.push(SchemeRun { scores, ff, recording });
    }
    let [basic, improved]: [SchemeRun; 2] =
        schemes.try_into().map_err(|_| StudyError::Config("two schemes expected".into()))?;
    Ok(Run { sample: x.sample.to_string(), cond: *c, near: near.row.cond, schemes: [basic, improved] })
}

/// Share of the power of the recording `path` (channel `u`) above
/// `interp`'s anti-alias cutoff (Welch, 256-sample Hann segments).
pub fn share_above_cutoff(path: &Path) -> Result<f64, StudyError> {
    let (rate, u) = recordings::channel(path, "u")?;
    let cfg = SpectrumConfig { rate, nfft: 256, window: Window::Hann, overlap: 0.5 };
    let s = averaged_spectrum(&u, cfg)
        .map_err(|e| StudyError::Recording(format!("{}: {e}", path.display())))?
        .ok_or_else(|| StudyError::Recording(format!("{}: too short for a spectrum", path.display())))?;
    let edge = INTERP_CUTOFF * (s.power.len() - 1) as f64;
    let above: f64 = s.power.iter().enumerate().filter(|(k, _)| *k as f64 > edge).map(|(_, p)| p).sum();
    Ok(above / s.power.iter().sum::<f64>().max(f64::MIN_POSITIVE))
}

/// The sample's main spatial period, cm: the main-component frequency of
/// its recordings at the trained conditions (repetition 1, constant-speed
/// force) against their speeds, a line through the origin (§6.3: f = v/λ).
/// `interp` rounds its loop to a whole number of it (its `period`).
pub fn texture_period(recordings: &Path, sample: &str, trained: &[Cond], band: [f64; 2]) -> Result<f64, StudyError> {
    let (mut vf, mut vv) = (0.0, 0.0);
    for c in trained {
        let path = recordings.join(recordings::name(sample, c, 1));
        let rec = Recording::open(&path).map_err(|e| StudyError::Recording(e.to_string()))?;
        let (rate, force) = constant_speed::of_recording(&rec, c.speed, &path)?;
        let f = main_frequency(&force, rate, band[0], band[1]).ok_or_else(|| {
            StudyError::Recording(format!("{}: no spectral peak in {}–{} Hz", path.display(), band[0], band[1]))
        })?;
        vf += c.speed * f;
        vv += c.speed * c.speed;
    }
    if vf <= 0.0 {
        return Err(StudyError::Recording(format!("{sample}: no main frequency to take a period from")));
    }
    Ok(vv / vf)
}
