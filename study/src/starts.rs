//! The floors' minimization: an [`Objective`] over a whole stroke's
//! actuation, minimized within |u| ≤ 1 from several starts side by side
//! ([`minimize_starts`]; the twin runs up to [`LANES`] passes at once).
//! The texture study's achievable floor ([`crate::floor`]) and the live
//! study's floors ([`crate::live::floor`], which also lets the starts of
//! several goals share one queue) minimize through it.

use crate::twin::LANES;
use evflow_nodes::synth::lbfgsb::{minimize_each, Options, Outcome};

/// An objective over a whole stroke's actuation that the floors minimize:
/// its value, and its value with the gradient written into `g` — towards
/// one goal, or towards each of several (`goal` its index; an objective
/// of one goal takes only 0).
pub(crate) trait Objective {
    /// The objective at `u` (by default through [`Objective::value_grad`]).
    fn value(&mut self, u: &[f64]) -> f64 {
        self.value_grad(u, &mut vec![0.0; u.len()])
    }
    /// The objective at `u`, its gradient into `g`.
    fn value_grad(&mut self, u: &[f64], g: &mut [f64]) -> f64;
    /// [`Objective::value_grad`] at each of up to four points, values into
    /// `fx` (an objective that can run them at once does; each result
    /// must be the one it gives alone).
    fn value_grad_each(&mut self, u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        for ((u, g), fx) in u.iter().zip(g.iter_mut()).zip(fx.iter_mut()) {
            *fx = self.value_grad(u, g);
        }
    }
    /// The objective of goal `goal` at `u`.
    fn value_of(&mut self, goal: usize, u: &[f64]) -> f64 {
        assert_eq!(goal, 0, "an objective of one goal");
        self.value(u)
    }
    /// [`Objective::value_grad_each`], point `k` towards goal `goals[k]`.
    fn value_grad_each_of(&mut self, goals: &[usize], u: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]) {
        assert!(goals.iter().all(|&k| k == 0), "an objective of one goal");
        self.value_grad_each(u, g, fx)
    }
}

/// Minimizes `objective` within |u| ≤ 1 from each start, four starts at a
/// time side by side ([`minimize_each`], [`Objective::value_grad_each`]): the
/// outcomes in the starts' order, each the one a run of its own reaches.
pub(crate) fn minimize_starts(objective: &mut impl Objective, starts: &[&[f64]], opts: &Options) -> Vec<Outcome> {
    let mut f = |x: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]| objective.value_grad_each(x, g, fx);
    minimize_each(&mut f, starts, LANES, -1.0, 1.0, opts)
}
