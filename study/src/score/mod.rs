//! A recorded stroke's score (`evflow score`, docs/score.md): the live
//! chain's actuation for a stroke recorded on a rig (the output of
//! graphs/texture-live-recorded.toml), played on a display under the
//! finger's true path and scored by E_s (Welch, 2–200 Hz, both forces
//! high-passed at 10 Hz) against the real force along the same path —
//! beside nothing, the display floor, the target's floor and the stroke's
//! floor, each played and scored as `evflow report live` plays and scores
//! its rows ([`crate::live`]), in a [`LiveRow`].
//!
//! * [`inputs`] — the three files, read and checked;
//! * [`lab`] — a lab profile's virtual display under the recorded finger (a graph);
//! * [`models`] — the display made of a library's forward models (the twin itself);
//! * [`metric`] — E_s and amplitude spectra of forces in memory;
//! * [`report`] — the table and the figure.
//!
//! The floors are those of the live study: the whole stroke's actuation
//! optimized through the display's twin from the carrier starts and from
//! the chain's own actuation, each optimum played over the gain sweep, the
//! best kept — and where the chain does better at its best gain, the
//! chain's value ([`LiveRow::floor`], [`LiveRow::target_floor`]).

pub mod inputs;
pub mod lab;
pub mod metric;
pub mod models;
pub mod report;

use crate::gains::{choose, AtGain};
use crate::live::floor::{self, Candidate, Goal, Seeds};
use crate::live::row::{Chain, ChainResult, LiveRow, StrokeFloor, TargetFloor};
use crate::live::stroke::Stroke;
use crate::row::Reading;
use crate::setup::Profile;
use crate::StudyError;
use evflow_nodes::synth::output_filter::OutputFilter;
use inputs::Inputs;
use models::ForwardDisplay;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::time::Instant;

/// The display a stroke is played on.
#[derive(Debug, Clone)]
pub enum Display {
    /// A lab profile's virtual display (`nominal`, graphs/lab/NAME.toml, a family member, a file).
    Lab(Profile),
    /// The display made of a library's forward models.
    Models(ForwardDisplay),
}

impl Display {
    /// The display's name for the report.
    pub fn name(&self) -> String {
        match self {
            Display::Lab(p) => p.name.clone(),
            Display::Models(d) => {
                let (l, s) = d.axes();
                format!("forward models ({} × {} conditions: {:?} g × {:?} cm/s)", l.len(), s.len(), l, s)
            }
        }
    }
}

/// How a stroke is scored.
#[derive(Debug, Clone)]
pub struct ScoreConfig {
    /// The display.
    pub display: Display,
    /// Where the played files go.
    pub work: PathBuf,
    /// The gain sweep every actuation is played over (× gain, then |u| ≤ 1).
    pub gains: Vec<f64>,
    /// Whether the target's and the stroke's floors are computed.
    pub floors: bool,
    /// Optimizer iterations per start of each floor.
    pub floor_iterations: usize,
}

impl ScoreConfig {
    /// `report live`'s sweep and floor iterations on `display`.
    pub fn defaults(display: Display, work: PathBuf) -> Self {
        let s = crate::live::scope::LiveScope::defaults();
        Self { display, work, gains: s.gains, floors: s.floor, floor_iterations: s.floor_iterations }
    }
}

/// What a score is doing (for progress lines).
#[derive(Debug, Clone, Copy)]
pub enum Step<'a> {
    /// Playing an actuation (its name) over `n` gains.
    Playing(&'a str, usize),
    /// Optimizing a floor through the twin from `n` starts.
    Optimizing(&'a str, usize),
    /// A floor's optimization is done, in `seconds`.
    Optimized(&'a str, f64),
}

/// One actuation played at gain 1 with the forces it gave.
#[derive(Debug, Clone)]
pub struct Played {
    /// Its readings.
    pub at: AtGain,
    /// The display's force, high-passed, N.
    pub rendered: Vec<f64>,
    /// The real force, high-passed, N.
    pub real: Vec<f64>,
}

/// A display an actuation is played on and a floor optimized through.
pub trait Player {
    /// Plays `u` (|u| ≤ 1 after × gain) with `add` (N) added to the display's
    /// force, at each of `gains`.
    fn sweep(&mut self, name: &str, u: &[f64], add: &[f64], gains: &[f64]) -> Result<Vec<AtGain>, StudyError>;
    /// Plays `u` with `add` at gain 1, keeping the forces.
    fn play(&mut self, name: &str, u: &[f64], add: &[f64]) -> Result<Played, StudyError>;
    /// The stroke's actuation optimized through the display's twin towards
    /// each `(goal, seeds)`, every goal's starts in one queue: each goal's
    /// candidates (the ones it reaches alone) and its share of the
    /// evaluations.
    fn optimize_goals(
        &mut self,
        stroke: &Stroke,
        goals: &[(&Goal, &Seeds)],
        iterations: usize,
    ) -> Result<Vec<(Vec<Candidate>, f64)>, StudyError>;
}

/// The forward-model display as a player: played in memory, no noise.
struct ModelPlayer<'a> {
    display: &'a ForwardDisplay,
    along: Vec<Vec<f64>>,
    real_hp: Vec<f64>,
    rate: f64,
}

impl ModelPlayer<'_> {
    fn force(&self, u: &[f64], add: &[f64], gain: f64) -> Result<Vec<f64>, StudyError> {
        let u: Vec<f64> = u.iter().map(|x| (gain * x).clamp(-1.0, 1.0)).collect();
        let mut f = self.display.force(&u, &self.along);
        f.iter_mut().zip(add).for_each(|(f, a)| *f += a);
        OutputFilter::highpass(4, 10.0, self.rate)?.apply_in_place(&mut f);
        Ok(f)
    }
}

impl Player for ModelPlayer<'_> {
    fn sweep(&mut self, _: &str, u: &[f64], add: &[f64], gains: &[f64]) -> Result<Vec<AtGain>, StudyError> {
        gains.iter().map(|&g| metric::reading(&self.force(u, add, g)?, &self.real_hp, self.rate, g)).collect()
    }

    fn play(&mut self, _: &str, u: &[f64], add: &[f64]) -> Result<Played, StudyError> {
        let rendered = self.force(u, add, 1.0)?;
        let at = metric::reading(&rendered, &self.real_hp, self.rate, 1.0)?;
        Ok(Played { at, rendered, real: self.real_hp.clone() })
    }

    fn optimize_goals(
        &mut self,
        stroke: &Stroke,
        goals: &[(&Goal, &Seeds)],
        iterations: usize,
    ) -> Result<Vec<(Vec<Candidate>, f64)>, StudyError> {
        self.display.optimize_goals(stroke, goals, iterations)
    }
}

/// The amplitude spectra of the figure (Welch, N per 1 Hz bin, 2–200 Hz).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Spectra {
    /// The real force.
    pub real: Vec<(f64, f64)>,
    /// The chain's actuation as recorded (gain 1).
    pub rendered: Vec<(f64, f64)>,
    /// No actuation.
    pub nothing: Vec<(f64, f64)>,
    /// The stroke's floor's best actuation at gain 1 (None: not computed).
    pub floor: Option<Vec<(f64, f64)>>,
}

/// A stroke's score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// The display's name.
    pub display: String,
    /// The recorded stroke, the actuation and the real recording.
    pub files: [PathBuf; 3],
    /// The material.
    pub material: String,
    /// How the texture's own modulation was taken out of the real force.
    pub base: inputs::Base,
    /// Seconds scored.
    pub seconds: f64,
    /// The row, as `report live` holds one: nothing, the display floor, the
    /// chain (as `live`: its actuation as recorded, over the sweep), the
    /// stroke's floor and the target's floor.
    pub row: LiveRow,
    /// The figure's spectra.
    pub spectra: Spectra,
}

impl Score {
    /// The chain's result.
    pub fn chain(&self) -> &ChainResult {
        &self.row.chains[0]
    }

    /// The chain's readings at gain 1 (as recorded).
    pub fn at_gain_1(&self) -> Option<AtGain> {
        self.chain().sweep.iter().copied().find(|s| s.gain == 1.0)
    }
}

/// The best of `candidates` as played over the gain sweep, as the live
/// study picks it: its sweep, the best of each reading over every
/// candidate, and its index.
fn play_best(
    player: &mut dyn Player,
    candidates: &[Candidate],
    name: &str,
    gains: &[f64],
) -> Result<(Vec<AtGain>, Reading, usize), StudyError> {
    let zeros = vec![0.0; candidates.first().map_or(0, |c| c.u.len())];
    let mut best: Option<(Vec<AtGain>, Reading, usize)> = None;
    for (k, c) in candidates.iter().enumerate() {
        let sweep = player.sweep(&format!("{name}-u{k}"), &c.u, &zeros, gains)?;
        let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
        let reached = Reading { rect: chosen.best_rect.rect, welch: chosen.best_welch.welch };
        match best.as_mut() {
            Some(b) if reached.welch >= b.1.welch => b.1 = b.1.min(reached),
            Some(b) => *b = (sweep, b.1.min(reached), k),
            None => best = Some((sweep, reached, k)),
        }
    }
    best.ok_or_else(|| StudyError::Config(format!("{name}: no start")))
}

/// Scores the stroke of `inputs` on `cfg`'s display; `progress` hears each step.
pub fn score(inputs: &Inputs, cfg: &ScoreConfig, progress: &mut dyn FnMut(Step<'_>)) -> Result<Score, StudyError> {
    if cfg.gains.is_empty() || cfg.gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(StudyError::Config("the gains must be positive numbers, at least one".into()));
    }
    let path = &inputs.path;
    let (rate, seconds, n) = (path.rate, inputs.seconds(), path.len());
    let work = std::path::absolute(&cfg.work)
        .map_err(|e| StudyError::Io { path: cfg.work.clone(), message: e.to_string() })?;
    let mut lab_player;
    let mut model_player;
    let player: &mut dyn Player = match &cfg.display {
        Display::Lab(p) => {
            lab_player = lab::LabPlayer::new(p.clone(), &inputs.real_file, &work, rate, seconds)?;
            &mut lab_player
        }
        Display::Models(d) => {
            if (d.rate - rate).abs() > 1e-9 * rate {
                return Err(StudyError::Config(format!(
                    "{}: the forward models were identified at {} Hz, the actuation {} is at {rate} Hz",
                    d.files[0].display(),
                    d.rate,
                    inputs.actuation_file.display()
                )));
            }
            let mut real_hp = path.real.clone();
            OutputFilter::highpass(4, 10.0, rate)?.apply_in_place(&mut real_hp);
            model_player = ModelPlayer { display: d, along: d.along(path), real_hp, rate };
            &mut model_player
        }
    };
    let zeros = vec![0.0; n];
    progress(Step::Playing("nothing", 1));
    let nothing = player.play("nothing", &zeros, &zeros)?;
    progress(Step::Playing("the display floor", 1));
    let df = player.sweep("display-floor", &zeros, &path.modulation, &[1.0])?[0];
    progress(Step::Playing("the chain's actuation", cfg.gains.len()));
    let rendered = player.play("chain", &inputs.u, &zeros)?;
    let mut sweep = Vec::with_capacity(cfg.gains.len());
    for &g in &cfg.gains {
        sweep.push(if g == 1.0 { rendered.at } else { player.sweep("chain", &inputs.u, &zeros, &[g])?[0] });
    }
    let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
    let chain = ChainResult { chain: Chain::Live, sweep, chosen, iterations_per_tick: 0.0 };
    let (achievable, target_floor, floor_spectrum) =
        if cfg.floors { floors(player, inputs, cfg, &zeros, progress)? } else { (None, None, None) };
    let spectra = Spectra {
        real: metric::amplitude(&rendered.real, rate)?,
        rendered: metric::amplitude(&rendered.rendered, rate)?,
        nothing: metric::amplitude(&nothing.rendered, rate)?,
        floor: floor_spectrum,
    };
    let row = LiveRow {
        profile: cfg.display.name(),
        sample: inputs.material.clone(),
        user: inputs.name(),
        nothing: Reading { rect: nothing.at.rect, welch: nothing.at.welch },
        display_floor: Reading { rect: df.rect, welch: df.welch },
        chains: vec![chain],
        achievable,
        target_floor,
        dir: work,
    };
    Ok(Score {
        display: cfg.display.name(),
        files: [inputs.stroke_file.clone(), inputs.actuation_file.clone(), inputs.real_file.clone()],
        material: inputs.material.clone(),
        base: inputs.base.clone(),
        seconds,
        row,
        spectra,
    })
}

/// The stroke's floor, the target's floor and the amplitude spectrum of
/// the stroke floor's best actuation.
type Floors = (Option<StrokeFloor>, Option<TargetFloor>, Option<Vec<(f64, f64)>>);

/// The target's floor, the stroke's floor and the spectrum of the
/// latter's best actuation, each optimized from the chain's actuation on
/// `player` and swept over `cfg`'s gains.
fn floors(
    player: &mut dyn Player,
    inputs: &Inputs,
    cfg: &ScoreConfig,
    zeros: &[f64],
    progress: &mut dyn FnMut(Step<'_>),
) -> Result<Floors, StudyError> {
    let path = &inputs.path;
    let rate = path.rate;
    let seeds = vec![(Chain::Live.label().to_string(), inputs.u.clone())];
    let starts = 2 * (seeds.len() + floor::START_OFFSETS.len());
    // Both floors' starts in one queue: the target's floor (towards the
    // chain's own target) first, then the stroke's (towards the real force).
    progress(Step::Optimizing("both floors", starts));
    let t = Instant::now();
    let (target, real) = (Goal::chain_target(path, &inputs.target)?, Goal::real(path)?);
    let mut each = player.optimize_goals(path, &[(&target, &seeds), (&real, &seeds)], cfg.floor_iterations)?;
    let secs = t.elapsed().as_secs_f64();
    progress(Step::Optimized("both floors", secs));
    let (Some((candidates, stroke_share)), Some((target_candidates, target_share))) = (each.pop(), each.pop()) else {
        return Err(StudyError::Config("the floors did not run".into()));
    };
    progress(Step::Playing("the target's floor", target_candidates.len() * cfg.gains.len()));
    let (sweep, reached, best) = play_best(player, &target_candidates, "target-floor", &cfg.gains)?;
    let c = &target_candidates[best];
    let target_floor = Some(TargetFloor {
        sweep,
        reached,
        start: c.start.clone(),
        objective: c.objective,
        seconds: secs * target_share,
    });
    progress(Step::Playing("the stroke's floor", (candidates.len() + 1) * cfg.gains.len() + 1));
    let (sweep, reached, best) = play_best(player, &candidates, "floor", &cfg.gains)?;
    let c = &candidates[best];
    let sliding = player.sweep("floor-sliding", &floor::sliding_only(&c.u, path), zeros, &cfg.gains)?;
    let s = choose(&sliding).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
    let floor_spectrum = Some(metric::amplitude(&player.play("floor-best", &c.u, zeros)?.rendered, rate)?);
    let achievable = Some(StrokeFloor {
        sweep,
        reached,
        start: c.start.clone(),
        objective: c.objective,
        sliding_only: Reading { rect: s.best_rect.rect, welch: s.best_welch.welch },
        seconds: secs * stroke_share,
    });
    Ok((achievable, target_floor, floor_spectrum))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::live::scope::User;
    use evflow_nodes::metric::spectral_error::Band;
    use evflow_nodes::metric::spectrum::{SpectrumConfig, Window};
    use evflow_nodes::synth::spectral::SpectralTarget;
    use std::path::Path;

    #[test]
    fn on_the_forward_model_display_the_floors_are_never_above_the_chain_they_start_from() {
        let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/data");
        let display = ForwardDisplay::load(&[lib]).unwrap();
        let user = User { name: "t".into(), seed: 1, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 8.0 };
        let path = Stroke::of(&user, "plastic-sheet", 2.0, 1000.0).unwrap();
        let n = path.len();
        // A chain's actuation: a carrier under an envelope that follows the texture loosely.
        let u: Vec<f64> =
            (0..n).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 } * (0.4 + 0.2 * (k as f64 * 0.05).sin())).collect();
        let target: Vec<f64> = path.real.iter().map(|f| f.abs()).collect();
        let inputs = Inputs {
            stroke_file: "s".into(),
            actuation_file: "a".into(),
            real_file: "r".into(),
            frame_rate: 40.0,
            frames: 80,
            path: path.clone(),
            u: u.clone(),
            target: target.clone(),
            material: "plastic-sheet".into(),
            base: inputs::Base::Sample("plastic-sheet".into()),
        };
        let dir = tempfile::tempdir().unwrap();
        let cfg = ScoreConfig {
            display: Display::Models(display.clone()),
            work: dir.path().into(),
            gains: vec![0.8, 1.0],
            floors: true,
            floor_iterations: 6,
        };
        let s = score(&inputs, &cfg, &mut |_| {}).unwrap();
        let r = &s.row;
        assert!((r.nothing.welch - 1.0).abs() < 1e-12, "no force at all: {}", r.nothing.welch);
        let chain = s.at_gain_1().unwrap();
        // The stroke's floor starts from the chain's actuation and the twin is the display: at gain 1 its best
        // is never above the chain, and its objective is the played E_s².
        let a = r.achievable.as_ref().unwrap();
        assert!(a.reached.welch <= chain.welch, "{} > {}", a.reached.welch, chain.welch);
        let at1 = a.sweep.iter().find(|x| x.gain == 1.0).unwrap();
        assert!((at1.welch.powi(2) - a.objective).abs() < 1e-9 * a.objective, "{} vs {}", at1.welch, a.objective);
        // The target's floor: its objective towards the target is never above the chain's.
        let t = r.target_floor.as_ref().unwrap();
        let goal = Goal::chain_target(&path, &target).unwrap();
        let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window: Window::Hann, overlap: 0.5 };
        let band = Band::new(1000.0, 1000, 2.0, 200.0, false).unwrap();
        let mut f = display.force(&u, &display.along(&path));
        OutputFilter::highpass(4, 10.0, 1000.0).unwrap().apply_in_place(&mut f);
        let from = SpectralTarget::new(&goal.highpassed, cfg, band).unwrap().es(&f).powi(2);
        assert!(t.objective <= from, "{} > {from}", t.objective);
        // The chain at gain 1 is the chain played.
        assert_eq!(s.chain().sweep.len(), 2);
        assert!(s.spectra.rendered.iter().all(|p| p.1.is_finite()));
        // The report says what each line is.
        let md = report::markdown(&s);
        assert!(
            md.contains("as recorded") && md.contains("target's floor") && md.contains("through the forward models")
        );
        assert_eq!(report::figure(&s).series.len(), 4);
    }
}
