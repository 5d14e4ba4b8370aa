//! The achievable floor (docs/synthesis.md): the E_s reached by optimizing
//! the actuation through the lab's own simulated display — its twin
//! ([`super::twin`]): the same equations, noise off — from several starts,
//! u in [−1, 1]. The evaluation knows the display; a renderer that only
//! sees recordings can approach this figure, not pass it. The actuation
//! found is then played like every method (graphs/play-actuation.toml,
//! noise on, the gain sweep) and scored against repetition 2; where a
//! method does better, [`super::row::Row::floor`] takes the method's value.
//!
//! Objective: E_s² in the Welch reading (Hann, half-overlapping one-second
//! segments — a smoother function of u than one or two rectangular
//! segments) of the twin's force, through the sensor and the 10 Hz
//! high-pass, against repetition 1 over its constant-speed stretch.
//! Starts: the square-law envelope on a Nyquist-rate carrier with the
//! display's true carrier gain at half, one and twice the least offset, and
//! the optimized synthesis' own actuation.

use super::gains::{AtGain, Chosen};
use super::graphs::{run_graph, value, Sets};
use super::recordings::{self, channel};
use super::row::{Achievable, Reading, RowInputs};
use super::twin::{DisplayTwin, SensorTwin, Tapes};
use super::StudyError;
use crate::starts::{minimize_starts, Objective};
use evflow_nodes::lab::integrator::Method;
use evflow_nodes::lab::profile::LabProfile;
use evflow_nodes::lab::tribometer_model::TribometerModel;
use evflow_nodes::metric::spectral_error::Band;
use evflow_nodes::metric::spectrum::{SpectrumConfig, Window};
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use evflow_nodes::synth::lbfgsb::Options;
use evflow_nodes::synth::output_filter::OutputFilter;
use evflow_nodes::synth::spectral::SpectralTarget;
use evflow_nodes::synth::start::carrier_scaled;
use std::time::Instant;

/// Iterations per start.
pub const ITERATIONS: usize = 150;

/// The carrier starts' offsets, relative to the least that keeps the
/// envelope real (c = −min f): the noise-free objective is nearly flat in
/// the offset, while the display's friction noise grows with it.
pub const START_OFFSETS: [f64; 3] = [0.5, 1.0, 2.0];

/// The chain the floor optimizes through: tribometer pass, display and
/// sensor twins, high-pass, E_s against the target.
struct Chain {
    display: DisplayTwin,
    load: Vec<f64>,
    velocity: Vec<f64>,
    /// The display's tapes of up to four evaluations side by side (one uses the first).
    tape: Tapes,
    score: Score,
}

/// What the display's force goes through to the objective: the sensor's
/// twin, the high-pass, the constant-speed gate, E_s against the target.
struct Score {
    sensor: SensorTwin,
    filter: OutputFilter,
    keep: Vec<bool>,
    target: SpectralTarget,
}

impl Objective for Chain {
    /// J = E_s² and ∂J/∂u.
    fn value_grad(&mut self, u: &[f64], g: &mut [f64]) -> f64 {
        let (score, velocity) = (&mut self.score, &self.velocity[..]);
        let path = (&self.load[..], velocity);
        self.display.objective_grad(u, path, self.tape.first(), g, |f| score.adjoint(&f, velocity))
    }

    /// The display passes side by side (each result the one it gives alone).
    fn value_grad_each(&mut self, u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        let (score, velocity) = (&mut self.score, &self.velocity[..]);
        let path = (&self.load[..], velocity);
        self.display.objective_grad_each(u, path, &mut self.tape, g, fx, |_, f| score.adjoint(&f, velocity))
    }
}

impl Score {
    /// J for the display force `f` along holder velocity `velocity`, and ∂J/∂f.
    fn adjoint(&mut self, f: &[f64], velocity: &[f64]) -> (f64, Vec<f64>) {
        let mut pass = Vec::new();
        let mut y = self.sensor.forward(f, velocity, &mut pass);
        self.filter.apply_in_place(&mut y);
        let kept: Vec<f64> = y.iter().zip(&self.keep).filter(|(_, k)| **k).map(|(v, _)| *v).collect();
        let mut gk = vec![0.0; kept.len()];
        let j = self.target.value_grad(&kept, &mut gk);
        let mut ybar = vec![0.0; y.len()];
        let mut it = gk.into_iter();
        for (b, k) in ybar.iter_mut().zip(&self.keep) {
            if *k {
                *b = it.next().unwrap_or(0.0);
            }
        }
        self.filter.adjoint_in_place(&mut ybar);
        (j, self.sensor.backward(&pass, &ybar))
    }
}

impl Chain {
    /// The steady friction a unit Nyquist-rate carrier adds on this pass (N):
    /// the display's true carrier gain, from the twin.
    fn carrier_gain(&mut self) -> f64 {
        let n = self.load.len();
        let unit: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let on = self.display.forward(&unit, &self.load, &self.velocity, self.tape.first());
        let off = self.display.forward(&vec![0.0; n], &self.load, &self.velocity, self.tape.first());
        let (mut s, mut c) = (0.0, 0);
        for k in 0..n {
            if self.score.keep[k] {
                s += on[k] - off[k];
                c += 1;
            }
        }
        (s / c.max(1) as f64).abs()
    }
}

/// Computes the achievable floor of a row (after [`super::row::run`] wrote
/// its optimized actuation into the row's folder).
pub fn achievable(i: &RowInputs<'_>) -> Result<Achievable, StudyError> {
    let t0 = Instant::now();
    let c = i.cond;
    let profile = match &i.profile.path {
        Some(p) => LabProfile::load(p).map_err(|e| StudyError::Config(e.issues_text()))?,
        None => LabProfile::default(),
    };
    let rep1 = i.recordings.join(recordings::name(i.sample, &c, 1));
    let (rate, target) = channel(&rep1, "force")?;
    let keep = recordings::gate(&rep1, c.speed)?;
    let bad = |m: String| StudyError::Config(format!("{}: {m}", i.profile.name));
    let mut trib =
        TribometerModel::new(&profile, rate, c.speed * 1e-2, c.mass * 1e-3, 1, Method::Exact, 4).map_err(bad)?;
    let (mut load, mut velocity) = (Vec::with_capacity(target.len()), Vec::with_capacity(target.len()));
    for _ in 0..target.len() {
        let (_, v, l) = trib.step();
        velocity.push(v);
        load.push(l);
    }
    let kept: Vec<f64> = target.iter().zip(&keep).filter(|(_, k)| **k).map(|(v, _)| *v).collect();
    let nfft = rate.round() as usize;
    let cfg = SpectrumConfig { rate, nfft, window: Window::Hann, overlap: 0.5 };
    let band = Band::new(rate, nfft, 2.0, 200.0, false).map_err(|e| StudyError::Config(e.message))?;
    let mut chain = Chain {
        display: DisplayTwin::new(&profile, rate, 4).map_err(bad)?,
        load,
        velocity,
        tape: Default::default(),
        score: Score {
            sensor: SensorTwin::new(&profile, rate, 4).map_err(bad)?,
            filter: OutputFilter::highpass(4, 10.0, rate)?,
            keep: keep.clone(),
            target: SpectralTarget::new(&kept, cfg, band)?,
        },
    };
    let kappa = chain.carrier_gain();
    let mut starts = Vec::new();
    for scale in START_OFFSETS {
        starts.push(carrier_scaled(&target, &keep, kappa.max(1e-9), 1.0, scale)?);
    }
    let opt = i.dir.join(format!("u-{}-{}", i.sample, c.tag()));
    if let Ok((_, u)) = channel(&opt, "u") {
        if u.len() == target.len() {
            starts.push(u);
        }
    }
    let opts = Options { max_iter: ITERATIONS, ..Options::default() };
    let points: Vec<&[f64]> = starts.iter().map(Vec::as_slice).collect();
    let optimized: Vec<(f64, Vec<f64>)> =
        minimize_starts(&mut chain, &points, &opts).into_iter().map(|out| (out.f, out.x)).collect();
    let seconds = t0.elapsed().as_secs_f64();
    // Play each start's optimum like every method; the floor is the best.
    let graph = i.graphs.join("play-actuation.toml");
    let mut best: Option<(Reading, Vec<AtGain>, f64)> = None;
    for (k, (objective, u)) in optimized.iter().enumerate() {
        let file = i.dir.join(format!("floor-u{k}-{}-{}", i.sample, c.tag()));
        write_actuation(&file, rate, u, i.sample, &c)?;
        let mut sweep = Vec::new();
        for &gain in i.gains {
            let sets = Sets::new()
                .path("recordings", i.recordings)
                .text("sample", i.sample)
                .and(c.sets())
                .path("actuation", &file)
                .num("gain", gain)
                .and(i.profile.sets())
                .text("record.path", &format!("floor-played{k}"));
            let r = run_graph(&graph, &sets, &i.dir)?;
            sweep.push(AtGain {
                gain,
                rect: value(&r, &graph, "es", "E_s")?,
                welch: value(&r, &graph, "welch", "E_s")?,
                peak_ratio: value(&r, &graph, "es", "peak_psd_ratio")?,
            });
        }
        let chosen: Chosen =
            super::gains::choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
        let reached = Reading { rect: chosen.best_rect.rect, welch: chosen.best_welch.welch };
        best = Some(match best {
            None => (reached, sweep, *objective),
            Some((b, s, o)) => {
                let keep_old = b.welch <= reached.welch;
                (b.min(reached), if keep_old { s } else { sweep }, if keep_old { o } else { *objective })
            }
        });
    }
    let (reached, sweep, objective) = best.ok_or_else(|| StudyError::Config("no start".into()))?;
    Ok(Achievable { reached, sweep, objective, seconds })
}

/// Writes an actuation as a recording with channel `u`.
fn write_actuation(
    file: &std::path::Path,
    rate: f64,
    u: &[f64],
    sample: &str,
    c: &super::setup::Cond,
) -> Result<(), StudyError> {
    let mut meta = RecordingMeta::new(rate, vec![Channel::new("u", "1")]);
    meta.condition.load_g = Some(c.mass);
    meta.condition.velocity_cm_s = Some(c.speed);
    meta.condition.material = Some(sample.to_string());
    meta.source = "evflow texture study: achievable floor (optimized through the display's twin, noise off)".into();
    let mut w = RecordingWriter::create(file, meta).map_err(|e| StudyError::Recording(e.to_string()))?;
    w.write_interleaved(u).map_err(|e| StudyError::Recording(e.to_string()))?;
    w.finish().map_err(|e| StudyError::Recording(e.to_string()))?;
    Ok(())
}
