//! The stroke's achievable floor: the actuation over a user's whole stroke
//! optimized through the lab's twin of the display ([`crate::twin`]:
//! its equations with the noise off) knowing the finger's true path, load
//! and the real force, within the range every method is played at
//! (|u| ≤ 1, the `limit` of every chain). Each optimum is then played like
//! every method — noise on, the gain sweep, the same metric — by
//! [`super::play`]. The evaluation knows the display and the future; a
//! live chain, which knows neither, can approach this figure, not pass it.
//! Where a method does pass it, the optimization was not optimal there and
//! the floor takes the method's value ([`super::row::LiveRow::floor`]).
//!
//! Objective: E_s² in the Welch reading (Hann, half-overlapping one-second
//! segments, 2–200 Hz) of the twin's force, high-passed at 10 Hz, against
//! the real force high-passed alike, over the whole stroke — reversals
//! included, as every live method is scored.
//!
//! Starts: the square-law envelope on a Nyquist-rate carrier for the real
//! force (its sign taken off with the direction of motion) at half and
//! once the least offset, with the display's true carrier gain on this
//! stroke; and every method's own actuation (the chains' output after
//! `limit`, at gain 1), so the floor is never above a method it was
//! seeded with, before the noise.

use super::stroke::Stroke;
use crate::starts::Objective;
use crate::twin::{DisplayTwin, Tapes, LANES};
use crate::StudyError;
use evflow_nodes::lab::profile::LabProfile;
use evflow_nodes::metric::spectral_error::Band;
use evflow_nodes::metric::spectrum::{SpectrumConfig, Window};
use evflow_nodes::synth::lbfgsb::{minimize_each_of, Options};
use evflow_nodes::synth::output_filter::OutputFilter;
use evflow_nodes::synth::spectral::SpectralTarget;
use evflow_nodes::synth::start::carrier_scaled;

/// Named starts: `(name, actuation)`.
pub type Seeds = [(String, Vec<f64>)];

/// The carrier starts' offsets, relative to the least that keeps the
/// envelope real.
pub const START_OFFSETS: [f64; 2] = [0.5, 1.0];

/// Half-width of the window around a reversal that [`sliding_only`] clears, ms.
pub const REVERSAL_MS: f64 = 150.0;

/// `u` with every sample within [`REVERSAL_MS`] of a reversal of the
/// finger (a change of the sign of its velocity, rests included) set to 0.
pub fn sliding_only(u: &[f64], stroke: &Stroke) -> Vec<f64> {
    let w = (REVERSAL_MS * 1e-3 * stroke.rate).round() as usize;
    let v = &stroke.velocity;
    let n = u.len().min(v.len());
    let mut clear = vec![false; n];
    let mut last: Option<usize> = None;
    for k in 0..n {
        if v[k] != 0.0 {
            if let Some(j) = last {
                if v[j].signum() != v[k].signum() || k > j + 1 {
                    let (lo, hi) = (j.saturating_sub(w), (k + w).min(n - 1));
                    clear[lo..=hi].iter_mut().for_each(|c| *c = true);
                }
            }
            last = Some(k);
        }
    }
    u.iter().take(n).zip(&clear).map(|(x, c)| if *c { 0.0 } else { *x }).collect()
}

/// One start's optimum.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Where it started: `carrier ×0.5`, `carrier ×1`, or a method's name.
    pub start: String,
    /// E_s² against the real force through the twin at the start (noise off).
    pub start_objective: f64,
    /// The same at the optimum.
    pub objective: f64,
    /// The actuation, |u| ≤ 1.
    pub u: Vec<f64>,
}

/// The display's twin and the high-pass of one stroke, and the target of
/// each goal optimized towards.
struct Chain<'a> {
    twin: DisplayTwin,
    filter: OutputFilter,
    stroke: &'a Stroke,
    targets: Vec<SpectralTarget>,
    /// The twin's tapes of up to four evaluations side by side (one uses the first).
    tape: Tapes,
}

impl Chain<'_> {
    fn force(&mut self, u: &[f64]) -> Vec<f64> {
        self.twin.forward(u, &self.stroke.load, &self.stroke.velocity, self.tape.first())
    }

    /// The steady friction a unit Nyquist-rate carrier adds on this stroke
    /// in the direction of motion (N): the display's true carrier gain.
    fn carrier_gain(&mut self) -> f64 {
        let n = self.stroke.len();
        let unit: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let on = self.force(&unit);
        let off = self.force(&vec![0.0; n]);
        let v = &self.stroke.velocity;
        let moving: Vec<usize> = (0..n).filter(|&k| v[k] != 0.0).collect();
        let s: f64 = moving.iter().map(|&k| (on[k] - off[k]) * v[k].signum()).sum();
        s / moving.len().max(1) as f64
    }
}

/// J = E_s² of the twin's force `y` high-passed, and ∂J/∂y.
fn force_adjoint(filter: &OutputFilter, target: &mut SpectralTarget, mut y: Vec<f64>) -> (f64, Vec<f64>) {
    filter.apply_in_place(&mut y);
    let mut ybar = vec![0.0; y.len()];
    let j = target.value_grad(&y, &mut ybar);
    filter.adjoint_in_place(&mut ybar);
    (j, ybar)
}

/// What a floor optimizes towards: the force the display should give
/// along the stroke (high-passed like every force the study scores), and
/// its magnitude variation, whose square-law envelope is the carrier start.
#[derive(Debug, Clone, PartialEq)]
pub struct Goal {
    /// The force to match, high-passed at 10 Hz, N.
    pub highpassed: Vec<f64>,
    /// The force's variation in the direction of motion, N (for the carrier starts).
    pub magnitude: Vec<f64>,
}

impl Goal {
    /// The stroke's floor: the real force under the finger.
    pub fn real(stroke: &Stroke) -> Result<Self, StudyError> {
        let real = stroke.real_highpassed()?;
        // The real force's magnitude variation: its sign taken off with the motion's.
        let magnitude = real.iter().zip(&stroke.velocity).map(|(f, v)| if *v < 0.0 { -f } else { *f }).collect();
        Ok(Self { highpassed: real, magnitude })
    }

    /// The target's floor: the live synthesis' own target `target` (N,
    /// tick by tick, a friction magnitude: what the chain computed from
    /// the IR frame and the load cell) in the direction the finger truly
    /// moves (friction opposes the motion), high-passed — the stroke's
    /// floor with the real force replaced by the force the chain aims at.
    pub fn chain_target(stroke: &Stroke, target: &[f64]) -> Result<Self, StudyError> {
        let n = stroke.len();
        let mut t: Vec<f64> = target.iter().take(n).map(|v| if v.is_finite() { *v } else { 0.0 }).collect();
        t.resize(n, 0.0);
        let mut want: Vec<f64> = t.iter().zip(&stroke.velocity).map(|(f, v)| f * sign_of_motion(*v)).collect();
        OutputFilter::highpass(4, 10.0, stroke.rate)?.apply_in_place(&mut want);
        Ok(Self { highpassed: want, magnitude: t })
    }
}

/// The direction friction opposes: +1 moving forward or at rest, −1 backwards.
fn sign_of_motion(v: f64) -> f64 {
    if v < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Optimizes the stroke's actuation through the display of `profile` from
/// the carrier starts and every seed (`(name, actuation)`, each clipped to
/// |u| ≤ 1 and cut or padded with 0 to the stroke), `iterations` each,
/// towards the real force (the stroke's floor).
pub fn optimize(
    stroke: &Stroke,
    profile: &LabProfile,
    seeds: &[(String, Vec<f64>)],
    iterations: usize,
) -> Result<Vec<Candidate>, StudyError> {
    optimize_towards(stroke, profile, &Goal::real(stroke)?, seeds, iterations)
}

/// [`optimize`] towards any [`Goal`].
pub fn optimize_towards(
    stroke: &Stroke,
    profile: &LabProfile,
    goal: &Goal,
    seeds: &[(String, Vec<f64>)],
    iterations: usize,
) -> Result<Vec<Candidate>, StudyError> {
    let mut each = optimize_goals(stroke, profile, &[(goal, seeds)], iterations)?;
    Ok(each.pop().map(|(c, _)| c).unwrap_or_default())
}

/// [`optimize_towards`] for each `(goal, seeds)` on one stroke, every
/// goal's starts in one queue (`from_starts_goals`): each goal's
/// candidates are the ones [`optimize_towards`] gives it alone, and a goal
/// whose starts end early leaves its lanes to another's. With each goal's
/// candidates, the share of the L-BFGS-B evaluations that were its own.
pub fn optimize_goals(
    stroke: &Stroke,
    profile: &LabProfile,
    goals: &[(&Goal, &Seeds)],
    iterations: usize,
) -> Result<Vec<(Vec<Candidate>, f64)>, StudyError> {
    let rate = stroke.rate;
    let nfft = rate.round() as usize;
    let cfg = SpectrumConfig { rate, nfft, window: Window::Hann, overlap: 0.5 };
    let band = Band::new(rate, nfft, 2.0, 200.0, false).map_err(|e| StudyError::Config(e.message))?;
    let mut targets = Vec::with_capacity(goals.len());
    for (goal, _) in goals {
        targets.push(SpectralTarget::new(&goal.highpassed, cfg, band)?);
    }
    let mut chain = Chain {
        twin: DisplayTwin::new(profile, rate, 4).map_err(StudyError::Config)?,
        filter: OutputFilter::highpass(4, 10.0, rate)?,
        stroke,
        targets,
        tape: Default::default(),
    };
    let kappa = chain.carrier_gain();
    let each: Vec<(&[f64], &Seeds)> = goals.iter().map(|(g, s)| (g.magnitude.as_slice(), *s)).collect();
    from_starts_goals(&mut chain, &each, kappa, stroke.len(), iterations)
}

impl Objective for Chain<'_> {
    /// J = E_s² of the twin's force, high-passed, towards the first goal.
    fn value(&mut self, u: &[f64]) -> f64 {
        self.value_of(0, u)
    }

    /// J and ∂J/∂u towards the first goal.
    fn value_grad(&mut self, u: &[f64], g: &mut [f64]) -> f64 {
        let (filter, target) = (&self.filter, &mut self.targets[0]);
        let path = (&self.stroke.load[..], &self.stroke.velocity[..]);
        self.twin.objective_grad(u, path, self.tape.first(), g, |y| force_adjoint(filter, target, y))
    }

    /// The twin passes side by side (each result the one it gives alone).
    fn value_grad_each(&mut self, u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        self.value_grad_each_of(&vec![0; u.len()], u, g, fx)
    }

    fn value_of(&mut self, goal: usize, u: &[f64]) -> f64 {
        let mut y = self.force(u);
        self.filter.apply_in_place(&mut y);
        self.targets[goal].es(&y).powi(2)
    }

    /// The twin passes side by side, each force scored against its own goal.
    fn value_grad_each_of(&mut self, goals: &[usize], u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        let (filter, targets) = (&self.filter, &mut self.targets);
        let path = (&self.stroke.load[..], &self.stroke.velocity[..]);
        let adjoint = |k: usize, y| force_adjoint(filter, &mut targets[goals[k]], y);
        self.twin.objective_grad_each(u, path, &mut self.tape, g, fx, adjoint)
    }
}

/// The floors' optimization of `objective` over `n` samples towards each
/// goal `(magnitude, seeds)`: the carrier starts at [`START_OFFSETS`] for
/// the goal's `magnitude` (when the carrier gain `kappa` is positive) and
/// every seed (cut or padded with 0 to `n`, within |u| ≤ 1), each followed
/// by `iterations` of L-BFGS-B within |u| ≤ 1. Every goal's starts run in
/// one queue, four at a time side by side ([`minimize_each_of`],
/// [`Objective::value_grad_each_of`]): each start's optimum is the one it
/// reaches alone. Each goal's candidates, in its starts' order, with the
/// share of the evaluations that were its own.
pub(crate) fn from_starts_goals(
    objective: &mut impl Objective,
    goals: &[(&[f64], &Seeds)],
    kappa: f64,
    n: usize,
    iterations: usize,
) -> Result<Vec<(Vec<Candidate>, f64)>, StudyError> {
    let keep = vec![true; n];
    // (goal, name, start)
    let mut starts: Vec<(usize, String, Vec<f64>)> = Vec::new();
    for (goal, (magnitude, seeds)) in goals.iter().enumerate() {
        if kappa.is_finite() && kappa > 0.0 {
            for scale in START_OFFSETS {
                starts.push((goal, format!("carrier ×{scale}"), carrier_scaled(magnitude, &keep, kappa, 1.0, scale)?));
            }
        }
        for (name, u) in *seeds {
            let mut u: Vec<f64> =
                u.iter().take(n).map(|v| if v.is_finite() { v.clamp(-1.0, 1.0) } else { 0.0 }).collect();
            u.resize(n, 0.0);
            starts.push((goal, name.clone(), u));
        }
    }
    let opts = Options { max_iter: iterations, ..Options::default() };
    let start_objective: Vec<f64> = starts.iter().map(|(goal, _, u0)| objective.value_of(*goal, u0)).collect();
    let points: Vec<&[f64]> = starts.iter().map(|(_, _, u0)| u0.as_slice()).collect();
    let whose: Vec<usize> = starts.iter().map(|(goal, _, _)| *goal).collect();
    let mut goals_of = Vec::with_capacity(LANES);
    let mut f = |i: &[usize], x: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]| {
        goals_of.clear();
        goals_of.extend(i.iter().map(|&s| whose[s]));
        objective.value_grad_each_of(&goals_of, x, g, fx)
    };
    let results = minimize_each_of(&mut f, &points, LANES, -1.0, 1.0, &opts);
    let all: usize = results.iter().map(|r| r.evaluations).sum();
    let mut out: Vec<(Vec<Candidate>, f64)> = goals.iter().map(|_| (Vec::new(), 0.0)).collect();
    for (((goal, start, _), start_objective), r) in starts.into_iter().zip(start_objective).zip(results) {
        out[goal].1 += r.evaluations as f64 / all.max(1) as f64;
        out[goal].0.push(Candidate { start, start_objective, objective: r.f, u: r.x });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::live::scope::User;

    #[test]
    fn sliding_only_clears_the_reversals_and_keeps_the_strokes() {
        let user = User { name: "t".into(), seed: 5, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 3.0 };
        let stroke = Stroke::of(&user, "plastic-sheet", 4.0, 1000.0).unwrap();
        let u = vec![1.0; stroke.len()];
        let s = sliding_only(&u, &stroke);
        let reversals =
            stroke.velocity.windows(2).filter(|w| w[0] != 0.0 && w[1] != 0.0 && w[0].signum() != w[1].signum()).count()
                + stroke.velocity.windows(2).filter(|w| w[0] != 0.0 && w[1] == 0.0).count();
        assert!(reversals >= 2, "{reversals}");
        let cleared = s.iter().filter(|x| **x == 0.0).count();
        assert!(cleared >= 300 && cleared < stroke.len() / 2, "{cleared} of {}", stroke.len());
        // Around every sign change the actuation is cleared; at full speed it is kept.
        for (k, sk) in s.iter().enumerate().skip(1) {
            let (a, b) = (stroke.velocity[k - 1], stroke.velocity[k]);
            if a != 0.0 && b != 0.0 && a.signum() != b.signum() {
                assert_eq!(*sk, 0.0);
            }
            if stroke.velocity[k].abs() > 0.06 && *sk == 0.0 {
                // Full speed is reached within 50 ms of a reversal at most: only those samples are cleared.
                let near =
                    (k.saturating_sub(200)..(k + 200).min(stroke.len())).any(|j| stroke.velocity[j].abs() < 0.005);
                assert!(near, "sample {k} cleared at full speed far from a reversal");
            }
        }
    }

    #[test]
    fn the_target_goal_is_the_target_along_the_motion_high_passed() {
        let user = User { name: "t".into(), seed: 5, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 3.0 };
        let stroke = Stroke::of(&user, "plastic-sheet", 3.0, 1000.0).unwrap();
        let zero = Goal::chain_target(&stroke, &[]).unwrap();
        assert_eq!(zero.magnitude.len(), stroke.len());
        assert!(zero.magnitude.iter().chain(&zero.highpassed).all(|m| *m == 0.0));
        // A constant target: a step the high-pass removes, except where the motion reverses.
        let c = Goal::chain_target(&stroke, &vec![0.05; stroke.len()]).unwrap();
        let mut want: Vec<f64> = stroke.velocity.iter().map(|v| 0.05 * sign_of_motion(*v)).collect();
        OutputFilter::highpass(4, 10.0, 1000.0).unwrap().apply_in_place(&mut want);
        assert_eq!(c.highpassed, want);
        assert!(want.iter().any(|w| w.abs() > 0.03), "the reversals show");
        // Non-finite target samples count as 0.
        let mut bad = vec![0.05; stroke.len()];
        bad[10] = f64::NAN;
        assert!(Goal::chain_target(&stroke, &bad).unwrap().highpassed.iter().all(|x| x.is_finite()));
        // The real goal is the high-passed real force.
        let real = Goal::real(&stroke).unwrap();
        assert_eq!(real.highpassed, stroke.real_highpassed().unwrap());
    }

    #[test]
    fn goals_in_one_queue_reach_what_each_reaches_alone() {
        let user = User { name: "t".into(), seed: 9, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 8.0 };
        let stroke = Stroke::of(&user, "felt-fabric", 3.0, 1000.0).unwrap();
        let n = stroke.len();
        let real = Goal::real(&stroke).unwrap();
        let wanted: Vec<f64> = (0..n).map(|k| 0.05 + 0.02 * (k as f64 * 0.09).sin()).collect();
        let target = Goal::chain_target(&stroke, &wanted).unwrap();
        let carrier: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 0.6 } else { -0.6 }).collect();
        let stroke_seeds = vec![("held carrier".to_string(), carrier.clone()), ("quiet".to_string(), vec![0.1; n])];
        let target_seeds = vec![("half carrier".to_string(), carrier.iter().map(|u| u / 2.0).collect())];
        let profile = LabProfile::default();
        let alone = [
            optimize_towards(&stroke, &profile, &target, &target_seeds, 6).unwrap(),
            optimize_towards(&stroke, &profile, &real, &stroke_seeds, 6).unwrap(),
        ];
        let goals: Vec<(&Goal, &Seeds)> = vec![(&target, &target_seeds), (&real, &stroke_seeds)];
        let together = optimize_goals(&stroke, &profile, &goals, 6).unwrap();
        assert_eq!(together.len(), 2);
        for (k, ((c, share), a)) in together.iter().zip(&alone).enumerate() {
            assert_eq!(c, a, "goal {k}");
            assert!(*share > 0.0 && *share < 1.0, "goal {k}: {share}");
        }
        assert!((together[0].1 + together[1].1 - 1.0).abs() < 1e-12);
        // The two goals lead the same start to different optima, so a
        // point scored against the other goal's target would show.
        let crossed = optimize_towards(&stroke, &profile, &real, &target_seeds, 6).unwrap();
        assert_ne!(crossed.last().unwrap().u, alone[0].last().unwrap().u);
    }

    #[test]
    fn the_floor_never_rises_above_its_starts_and_stays_in_range() {
        let user = User { name: "t".into(), seed: 5, speed: [3.0, 7.0], mass: [60.0, 110.0], travel_cm: 8.0 };
        let stroke = Stroke::of(&user, "plastic-sheet", 3.0, 1000.0).unwrap();
        let seed: Vec<f64> = (0..stroke.len()).map(|k| if k % 2 == 0 { 0.6 } else { -0.6 }).collect();
        let c = optimize(&stroke, &LabProfile::default(), &[("held carrier".into(), seed)], 8).unwrap();
        assert_eq!(c.len(), 3);
        for cand in &c {
            assert!(
                cand.objective <= cand.start_objective,
                "{}: {} > {}",
                cand.start,
                cand.objective,
                cand.start_objective
            );
            assert!(cand.u.iter().all(|u| u.abs() <= 1.0));
            assert_eq!(cand.u.len(), stroke.len());
        }
        // Optimizing does something on a stroke where the display can render texture.
        assert!(c.iter().any(|cand| cand.objective < 0.95 * cand.start_objective));
    }
}
