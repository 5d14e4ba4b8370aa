//! Bound-constrained minimization: projected L-BFGS.
//!
//! Minimizes a smooth f(x) over the box lo ≤ x_i ≤ hi. Each iteration:
//!
//! 1. the projected gradient x − P(x − ∇f) measures stationarity (0 at a
//!    point satisfying the KKT conditions of the box) and stops the search
//!    below `pg_tol`;
//! 2. the *active set* — variables at a bound whose gradient pushes them
//!    outward — is held fixed; on the free variables the direction is the
//!    L-BFGS two-loop recursion (Nocedal & Wright, *Numerical
//!    Optimization*, 2nd ed., Alg. 7.4) over the last `memory` pairs
//!    (s, y), restricted to the free variables, scaled by sᵀy/yᵀy;
//! 3. a backtracking line search along the projection arc P(x + α·d)
//!    accepts the first α (1, ½, ¼, …) with the Armijo decrease
//!    f(x_α) ≤ f(x) + c₁·∇fᵀ(x_α − x) — so the objective never rises and x
//!    never leaves the box (Bertsekas, *Nonlinear Programming*, 2nd ed.,
//!    §2.3, projection arc; Kim, Sra & Dhillon 2010, projected
//!    quasi-Newton);
//! 4. a pair (s, y) is kept only if sᵀy > 0 (curvature), so the implied
//!    inverse Hessian stays positive definite.
//!
//! This is the projected form of L-BFGS, not Byrd–Lu–Nocedal–Zhu's
//! L-BFGS-B with its generalized Cauchy point and subspace minimization:
//! simpler, and for boxes whose active set settles early (an actuation
//! bounded to [−1, 1]) it reaches the same points.

/// Settings of [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Pairs (s, y) kept.
    pub memory: usize,
    /// Most iterations.
    pub max_iter: usize,
    /// Most objective evaluations (line-search trials included).
    pub max_evals: usize,
    /// Stop when ‖x − P(x − ∇f)‖∞ falls below this.
    pub pg_tol: f64,
    /// Stop when an iteration lowers f by less than this fraction of |f|.
    pub f_rel_tol: f64,
    /// Armijo constant c₁.
    pub c1: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self { memory: 10, max_iter: 200, max_evals: 1000, pg_tol: 1e-8, f_rel_tol: 1e-10, c1: 1e-4 }
    }
}

/// Why [`minimize`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The projected gradient is below `pg_tol`.
    Stationary,
    /// An iteration lowered f by less than `f_rel_tol`·|f|.
    Converged,
    /// `max_iter` iterations ran.
    MaxIter,
    /// `max_evals` evaluations ran.
    MaxEvals,
    /// No step along the search direction lowered f (at the limit of
    /// floating-point resolution).
    LineSearch,
}

impl Stop {
    /// A few words for people.
    pub fn describe(&self) -> &'static str {
        match self {
            Stop::Stationary => "projected gradient below tolerance",
            Stop::Converged => "objective no longer decreasing",
            Stop::MaxIter => "iteration limit",
            Stop::MaxEvals => "evaluation limit",
            Stop::LineSearch => "no decrease along the search direction",
        }
    }
}

/// The result of [`minimize`].
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The best point found (inside the box).
    pub x: Vec<f64>,
    /// f there.
    pub f: f64,
    /// f at the start and after each iteration (non-increasing).
    pub history: Vec<f64>,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Why it stopped.
    pub stop: Stop,
}

/// Minimizes `f` over lo ≤ x ≤ hi from `x0` (projected into the box).
/// `f(x, g)` returns f(x) and writes ∇f(x) into `g`. A non-finite value
/// counts as +∞ (the line search backs off from it).
pub fn minimize(f: &mut dyn FnMut(&[f64], &mut [f64]) -> f64, x0: &[f64], lo: f64, hi: f64, opts: &Options) -> Outcome {
    let mut m = Minimizer::new(x0, lo, hi, opts);
    while let Some((x, g)) = m.request() {
        let fx = f(x, g);
        m.reply(fx);
    }
    m.finish()
}

/// An objective evaluated at several points at once: `f(x, g, fx)` writes
/// the gradient at `x[k]` into `g[k]` and the value into `fx[k]`.
pub type PointsObjective<'a> = dyn FnMut(&[&[f64]], &mut [&mut [f64]], &mut [f64]) + 'a;

/// Minimizations over one box from each start of `x0`, up to `width`
/// (at least 1) side by side: each takes the steps [`minimize`] would
/// take with the same objective from its start, but their evaluations are
/// asked for together, so that the objective can run them at once; when
/// one finishes, the next start takes its place. `f(x, g, fx)` evaluates
/// the objective at each point of `x` — `width`, or fewer once no start
/// is left — writing each gradient into `g` and each value into `fx`, in
/// the same order. The outcomes come in the starts' order.
pub fn minimize_each(
    f: &mut PointsObjective,
    x0: &[&[f64]],
    width: usize,
    lo: f64,
    hi: f64,
    opts: &Options,
) -> Vec<Outcome> {
    minimize_each_of(&mut |_, x, g, fx| f(x, g, fx), x0, width, lo, hi, opts)
}

/// Objectives evaluated at several points at once, each point of its own
/// start: `f(starts, x, g, fx)` writes the gradient at `x[k]` (a point of
/// the minimization from start `starts[k]`) into `g[k]` and the value
/// into `fx[k]`.
pub type StartsObjective<'a> = dyn FnMut(&[usize], &[&[f64]], &mut [&mut [f64]], &mut [f64]) + 'a;

/// [`minimize_each`] where each start may have an objective of its own:
/// `f` is told which start each point belongs to (its index in `x0`).
pub fn minimize_each_of(
    f: &mut StartsObjective,
    x0: &[&[f64]],
    width: usize,
    lo: f64,
    hi: f64,
    opts: &Options,
) -> Vec<Outcome> {
    let mut out: Vec<Option<Outcome>> = x0.iter().map(|_| None).collect();
    let mut queue = x0.iter().enumerate();
    let mut slots: Vec<Option<(usize, Minimizer)>> = (0..width.max(1)).map(|_| None).collect();
    let mut fx = Vec::with_capacity(slots.len());
    let mut starts = Vec::with_capacity(slots.len());
    loop {
        // Each slot holds a minimization that asks for a point, while starts are left.
        for slot in &mut slots {
            loop {
                match slot {
                    Some((_, m)) if !m.finished() => break,
                    Some(_) => {
                        let (i, m) = slot.take().expect("the slot holds one");
                        out[i] = Some(m.finish());
                    }
                    None => match queue.next() {
                        Some((i, x)) => *slot = Some((i, Minimizer::new(x, lo, hi, opts))),
                        None => break,
                    },
                }
            }
        }
        starts.clear();
        let (x, mut g): (Vec<&[f64]>, Vec<&mut [f64]>) = slots
            .iter_mut()
            .flatten()
            .filter_map(|(i, m)| {
                let point = m.request()?;
                starts.push(*i);
                Some(point)
            })
            .unzip();
        if x.is_empty() {
            break;
        }
        fx.clear();
        fx.resize(x.len(), 0.0);
        f(&starts, &x, &mut g, &mut fx);
        let asked = slots.iter_mut().flatten().filter(|(_, m)| !m.finished());
        asked.zip(&fx).for_each(|((_, m), &v)| m.reply(v));
    }
    out.into_iter().map(|o| o.expect("every start ran")).collect()
}

/// [`minimize`] driven from outside: it asks for the objective at one
/// point at a time ([`Minimizer::request`]) and takes the answer
/// ([`Minimizer::reply`]), so a caller can run several minimizations side
/// by side and evaluate their points together. Each one takes the same
/// steps as [`minimize`] with the same objective.
pub struct Minimizer {
    opts: Options,
    b: Box1,
    /// How near a bound a variable counts as at it.
    eps: f64,
    x: Vec<f64>,
    g: Vec<f64>,
    fx: f64,
    history: Vec<f64>,
    mem: Memory,
    d: Vec<f64>,
    xt: Vec<f64>,
    gt: Vec<f64>,
    free: Vec<bool>,
    evals: usize,
    /// Iterations begun.
    iterations: usize,
    /// The line search's step, trials made, and gᵀ(x_t − x) of the trial asked for.
    step: f64,
    trials: usize,
    decrease: f64,
    state: State,
}

/// Where a [`Minimizer`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// The objective at the start is asked for (into `x`, `g`).
    Start,
    /// A line-search trial is asked for (into `xt`, `gt`).
    Trial,
    /// Finished.
    Done(Stop),
}

impl Minimizer {
    /// A minimization of an objective over lo ≤ x ≤ hi from `x0`
    /// (projected into the box); it first asks for the objective there.
    pub fn new(x0: &[f64], lo: f64, hi: f64, opts: &Options) -> Self {
        let n = x0.len();
        let b = Box1 { lo, hi };
        Minimizer {
            opts: *opts,
            x: x0.iter().map(|&v| b.proj(v)).collect(),
            b,
            eps: 1e-12 * (hi - lo).abs().max(1.0),
            g: vec![0.0; n],
            fx: f64::NAN,
            history: Vec::new(),
            mem: Memory::new(opts.memory.max(1)),
            d: vec![0.0; n],
            xt: vec![0.0; n],
            gt: vec![0.0; n],
            free: vec![true; n],
            evals: 0,
            iterations: 0,
            step: 1.0,
            trials: 0,
            decrease: -0.0,
            state: State::Start,
        }
    }

    /// The point whose objective is wanted next, and where its gradient
    /// goes; `None` once finished.
    pub fn request(&mut self) -> Option<(&[f64], &mut [f64])> {
        match self.state {
            State::Start => Some((&self.x, &mut self.g)),
            State::Trial => Some((&self.xt, &mut self.gt)),
            State::Done(_) => None,
        }
    }

    /// Whether it has stopped (and asks for nothing more).
    pub fn finished(&self) -> bool {
        matches!(self.state, State::Done(_))
    }

    /// The objective at the point [`Minimizer::request`] gave, its
    /// gradient written where it said. Ignored once finished.
    pub fn reply(&mut self, f: f64) {
        match self.state {
            State::Start => {
                self.fx = f;
                self.evals = 1;
                self.history.push(f);
                if !f.is_finite() || self.g.iter().any(|v| !v.is_finite()) {
                    self.state = State::Done(Stop::LineSearch);
                } else {
                    self.begin_iteration();
                }
            }
            State::Trial => {
                self.evals += 1;
                let accepted = f.is_finite()
                    && self.gt.iter().all(|v| v.is_finite())
                    && f <= self.fx + self.opts.c1 * self.decrease
                    && f <= self.fx;
                if accepted {
                    self.accept(f);
                } else {
                    self.step *= 0.5;
                    self.trials += 1;
                    self.next_trial();
                }
            }
            State::Done(_) => {}
        }
    }

    /// The best point found, f there, and why it stopped (a minimization
    /// left unfinished reports its point so far as stopped by `max_evals`).
    pub fn finish(self) -> Outcome {
        let stop = match self.state {
            State::Done(stop) => stop,
            _ => Stop::MaxEvals,
        };
        Outcome { x: self.x, f: self.fx, history: self.history, evaluations: self.evals, stop }
    }

    /// Steps 1 and 2 of an iteration, then the line search's first trial.
    fn begin_iteration(&mut self) {
        if self.iterations >= self.opts.max_iter {
            self.state = State::Done(Stop::MaxIter);
            return;
        }
        self.iterations += 1;
        let (b, x, g) = (&self.b, &self.x, &self.g);
        // 1. Stationarity.
        let pg = x.iter().zip(g).map(|(&xi, &gi)| (xi - b.proj(xi - gi)).abs()).fold(0.0, f64::max);
        if pg < self.opts.pg_tol {
            self.state = State::Done(Stop::Stationary);
            return;
        }
        // 2. Free variables and the two-loop recursion on them.
        let (lo, hi, eps) = (b.lo, b.hi, self.eps);
        for i in 0..x.len() {
            self.free[i] = !((x[i] <= lo + eps && g[i] > 0.0) || (x[i] >= hi - eps && g[i] < 0.0));
        }
        self.mem.direction(g, &self.free, &mut self.d);
        self.step = self.mem.first_step(g, &self.free, &mut self.d, b);
        self.trials = 0;
        self.next_trial();
    }

    /// Step 3, backtracking along the projection arc: the next trial
    /// point, from the step halving up to 60 times, or the search given up.
    fn next_trial(&mut self) {
        if self.trials >= 60 || self.evals >= self.opts.max_evals {
            let stop = if self.evals >= self.opts.max_evals { Stop::MaxEvals } else { Stop::LineSearch };
            self.state = State::Done(stop);
            return;
        }
        // The trial point and gᵀ(x_t − x) in one pass (summed in order from −0).
        let mut decrease = -0.0;
        for i in 0..self.x.len() {
            self.xt[i] = self.b.proj(self.x[i] + self.step * self.d[i]);
            decrease += self.g[i] * (self.xt[i] - self.x[i]);
        }
        self.decrease = decrease;
        self.state = State::Trial;
    }

    /// Step 4, the trial accepted: the curvature pair, the move, the stops.
    fn accept(&mut self, f_new: f64) {
        self.mem.remember(&self.x, &self.xt, &self.g, &self.gt);
        let fprev = self.fx;
        std::mem::swap(&mut self.x, &mut self.xt);
        std::mem::swap(&mut self.g, &mut self.gt);
        self.fx = f_new;
        self.history.push(f_new);
        if fprev - f_new <= self.opts.f_rel_tol * fprev.abs().max(f_new.abs()).max(f64::MIN_POSITIVE) {
            self.state = State::Done(Stop::Converged);
        } else if self.evals >= self.opts.max_evals {
            self.state = State::Done(Stop::MaxEvals);
        } else {
            self.begin_iteration();
        }
    }
}

/// The box lo ≤ x_i ≤ hi.
struct Box1 {
    lo: f64,
    hi: f64,
}

impl Box1 {
    /// The projection onto the box (NaN to its middle).
    fn proj(&self, v: f64) -> f64 {
        if v.is_nan() {
            0.5 * (self.lo + self.hi)
        } else {
            v.clamp(self.lo, self.hi)
        }
    }
}

/// aᵀb over the free variables (summed in order from −0, as `Iterator::sum`).
fn dot(a: &[f64], b: &[f64], free: &[bool]) -> f64 {
    let mut acc = -0.0;
    for ((&a, &b), &f) in a.iter().zip(b).zip(free) {
        if f {
            acc += a * b;
        }
    }
    acc
}

/// `out[j]` = a_jᵀb_j over the free variables for every j, each summed as
/// [`dot`] sums it (the same bits), up to four side by side in one pass:
/// independent sums, so they do not wait on each other's additions.
fn dots(a: &[&[f64]], b: &[&[f64]], free: &[bool], out: &mut [f64]) {
    let mut j = 0;
    while j < a.len() {
        match a.len() - j {
            1 => out[j] = dot(a[j], b[j], free),
            2 => dots_group::<2>(&a[j..], &b[j..], free, &mut out[j..]),
            3 => dots_group::<3>(&a[j..], &b[j..], free, &mut out[j..]),
            _ => dots_group::<4>(&a[j..], &b[j..], free, &mut out[j..]),
        }
        j += 4;
    }
}

fn dots_group<const B: usize>(a: &[&[f64]], b: &[&[f64]], free: &[bool], out: &mut [f64]) {
    let n = free.len();
    let a: [&[f64]; B] = std::array::from_fn(|k| &a[k][..n]);
    let b: [&[f64]; B] = std::array::from_fn(|k| &b[k][..n]);
    let mut acc = [-0.0f64; B];
    for i in 0..n {
        if free[i] {
            for k in 0..B {
                acc[k] += a[k][i] * b[k][i];
            }
        }
    }
    out[..B].copy_from_slice(&acc);
}

/// d += c·v on the free variables and, in the same pass, `next`ᵀd over
/// them afterwards (summed as [`dot`] sums it), if `next` is given. (In the
/// recursion's first loop c = −α: d + (−α)·y is d − α·y, the same bits.)
fn update_and_dot(d: &mut [f64], c: f64, v: &[f64], next: Option<&[f64]>, free: &[bool]) -> Option<f64> {
    let n = free.len();
    let (d, v) = (&mut d[..n], &v[..n]);
    match next {
        Some(w) => {
            let w = &w[..n];
            let mut acc = -0.0;
            for i in 0..n {
                if free[i] {
                    d[i] += c * v[i];
                    acc += w[i] * d[i];
                }
            }
            Some(acc)
        }
        None => {
            for i in 0..n {
                if free[i] {
                    d[i] += c * v[i];
                }
            }
            None
        }
    }
}

/// The last pairs (s, y) of L-BFGS, oldest first.
struct Memory {
    cap: usize,
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    alpha: Vec<f64>,
    /// sᵀy of each pair over this iteration's free variables, and yᵀy of
    /// the last (one slot more).
    sy: Vec<f64>,
    /// The pairs the two loops use (sᵀy not ≤ 0), in the first loop's order.
    used: Vec<usize>,
}

impl Memory {
    fn new(cap: usize) -> Self {
        Self {
            cap,
            s: Vec::with_capacity(cap),
            y: Vec::with_capacity(cap),
            alpha: vec![0.0; cap],
            sy: vec![0.0; cap + 1],
            used: Vec::with_capacity(cap),
        }
    }

    /// d = −H·g on the free variables (0 on the others): the two-loop
    /// recursion over the pairs kept, scaled by sᵀy/yᵀy of the last.
    ///
    /// Every sum is the recursion's as written plainly (each pair's sᵀy
    /// and the update's dot products, in index order), so d has the same
    /// bits; but the pairs' sᵀy (used by both loops) are taken once, side by
    /// side, and each update of d carries the next pair's dot product along
    /// in the same pass.
    fn direction(&mut self, g: &[f64], free: &[bool], d: &mut [f64]) {
        let n = g.len();
        for i in 0..n {
            d[i] = if free[i] { g[i] } else { 0.0 };
        }
        let k = self.s.len();
        if k > 0 {
            let mut a: Vec<&[f64]> = self.s.iter().map(Vec::as_slice).collect();
            let mut b: Vec<&[f64]> = self.y.iter().map(Vec::as_slice).collect();
            a.push(&self.y[k - 1]);
            b.push(&self.y[k - 1]);
            dots(&a, &b, free, &mut self.sy[..k + 1]);
        }
        // First loop, newest pair first.
        self.used.clear();
        for j in (0..k).rev() {
            if self.sy[j] <= 0.0 {
                self.alpha[j] = 0.0;
            } else {
                self.used.push(j);
            }
        }
        let mut pending = None;
        for u in 0..self.used.len() {
            let j = self.used[u];
            let sd = pending.take().unwrap_or_else(|| dot(&self.s[j], d, free));
            let a = sd / self.sy[j];
            self.alpha[j] = a;
            let next = self.used.get(u + 1).map(|&jn| self.s[jn].as_slice());
            pending = update_and_dot(d, -a, &self.y[j], next, free);
        }
        if k > 0 {
            let (sy, yy) = (self.sy[k - 1], self.sy[k]);
            if sy > 0.0 && yy > 0.0 {
                let gamma = sy / yy;
                d.iter_mut().for_each(|v| *v *= gamma);
            }
        }
        // Second loop, oldest pair first.
        self.used.reverse();
        let mut pending = None;
        for u in 0..self.used.len() {
            let j = self.used[u];
            let yd = pending.take().unwrap_or_else(|| dot(&self.y[j], d, free));
            let c = self.alpha[j] - yd / self.sy[j];
            let next = self.used.get(u + 1).map(|&jn| self.y[jn].as_slice());
            pending = update_and_dot(d, c, &self.s[j], next, free);
        }
        d.iter_mut().for_each(|v| *v = -*v);
    }

    /// The first trial step along `d`: 1, or where `d` is no descent
    /// direction (the pairs are forgotten and `d` becomes −g on the free
    /// variables) or no pair is kept, scaled so that the largest move is
    /// at most the box size.
    fn first_step(&mut self, g: &[f64], free: &[bool], d: &mut [f64], b: &Box1) -> f64 {
        // gᵀd, gᵀg and dᵀd side by side in one pass (each summed in order from −0).
        let (mut gd, mut gg, mut dd) = (-0.0f64, -0.0f64, -0.0f64);
        for (&gi, &di) in g.iter().zip(d.iter()) {
            gd += gi * di;
            gg += gi * gi;
            dd += di * di;
        }
        let (gnorm, dnorm) = (gg.sqrt(), dd.sqrt());
        let descent = gd.is_finite() && gd < -1e-14 * gnorm * dnorm;
        if !descent {
            // Not a descent direction: forget the curvature pairs, go down the gradient.
            self.s.clear();
            self.y.clear();
            for i in 0..g.len() {
                d[i] = if free[i] { -g[i] } else { 0.0 };
            }
        }
        // First step, or after a reset: scale so the largest move is at most the box size.
        let mut step = 1.0;
        if self.s.is_empty() {
            let dmax = d.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if dmax > 0.0 {
                step = ((b.hi - b.lo).abs() / dmax).min(1.0);
            }
        }
        step
    }

    /// Keeps the pair (s, y) of the step from `x` (gradient `g`) to `xt`
    /// (gradient `gt`) when sᵀy > 0 (curvature), dropping the oldest when full.
    fn remember(&mut self, x: &[f64], xt: &[f64], g: &[f64], gt: &[f64]) {
        let s: Vec<f64> = xt.iter().zip(x).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = gt.iter().zip(g).map(|(a, b)| a - b).collect();
        let sy: f64 = s.iter().zip(&y).map(|(a, b)| a * b).sum();
        if sy > 1e-16 * y.iter().map(|v| v * v).sum::<f64>() {
            if self.s.len() == self.cap {
                self.s.remove(0);
                self.y.remove(0);
            }
            self.s.push(s);
            self.y.push(y);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `minimize` as it was written before it became [`Minimizer`]: one
    /// loop calling the objective, its line search a function of its own.
    fn minimize_loop(
        f: &mut dyn FnMut(&[f64], &mut [f64]) -> f64,
        x0: &[f64],
        lo: f64,
        hi: f64,
        opts: &Options,
    ) -> Outcome {
        let n = x0.len();
        let b = Box1 { lo, hi };
        let mut x: Vec<f64> = x0.iter().map(|&v| b.proj(v)).collect();
        let mut g = vec![0.0; n];
        let mut fx = f(&x, &mut g);
        let mut evals = 1;
        if !fx.is_finite() || g.iter().any(|v| !v.is_finite()) {
            return Outcome { x, f: fx, history: vec![fx], evaluations: evals, stop: Stop::LineSearch };
        }
        let mut history = vec![fx];
        let mut mem = Memory::new(opts.memory.max(1));
        let (mut d, mut xt, mut gt) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut free = vec![true; n];
        let eps = 1e-12 * (hi - lo).abs().max(1.0);
        let mut stop = Stop::MaxIter;
        for _ in 0..opts.max_iter {
            let pg = x.iter().zip(&g).map(|(&xi, &gi)| (xi - b.proj(xi - gi)).abs()).fold(0.0, f64::max);
            if pg < opts.pg_tol {
                stop = Stop::Stationary;
                break;
            }
            for i in 0..n {
                free[i] = !((x[i] <= lo + eps && g[i] > 0.0) || (x[i] >= hi - eps && g[i] < 0.0));
            }
            mem.direction(&g, &free, &mut d);
            let mut step = mem.first_step(&g, &free, &mut d, &b);
            let mut found = None;
            for _ in 0..60 {
                if evals >= opts.max_evals {
                    break;
                }
                let mut decrease = -0.0;
                for i in 0..n {
                    xt[i] = b.proj(x[i] + step * d[i]);
                    decrease += g[i] * (xt[i] - x[i]);
                }
                let ft = f(&xt, &mut gt);
                evals += 1;
                if ft.is_finite() && gt.iter().all(|v| v.is_finite()) && ft <= fx + opts.c1 * decrease && ft <= fx {
                    found = Some(ft);
                    break;
                }
                step *= 0.5;
            }
            let Some(f_new) = found else {
                stop = if evals >= opts.max_evals { Stop::MaxEvals } else { Stop::LineSearch };
                break;
            };
            mem.remember(&x, &xt, &g, &gt);
            let fprev = fx;
            std::mem::swap(&mut x, &mut xt);
            std::mem::swap(&mut g, &mut gt);
            fx = f_new;
            history.push(fx);
            if fprev - fx <= opts.f_rel_tol * fprev.abs().max(fx.abs()).max(f64::MIN_POSITIVE) {
                stop = Stop::Converged;
                break;
            }
            if evals >= opts.max_evals {
                stop = Stop::MaxEvals;
                break;
            }
        }
        Outcome { x, f: fx, history, evaluations: evals, stop }
    }

    #[test]
    fn the_driven_form_takes_the_loops_steps_bit_for_bit() {
        // Rosenbrock in 6 dimensions on a box that binds, a function that
        // goes non-finite off a region, and limits on iterations and
        // evaluations: every stop reason.
        let rosen = |x: &[f64], g: &mut [f64]| -> f64 {
            let mut f = 0.0;
            g.iter_mut().for_each(|v| *v = 0.0);
            for i in 0..x.len() - 1 {
                let (a, b) = (1.0 - x[i], x[i + 1] - x[i] * x[i]);
                f += a * a + 100.0 * b * b;
                g[i] += -2.0 * a - 400.0 * x[i] * b;
                g[i + 1] += 200.0 * b;
            }
            f
        };
        let wall = |x: &[f64], g: &mut [f64]| -> f64 {
            g[0] = 2.0 * (x[0] - 0.9);
            if x[0] > 0.5 {
                f64::NAN
            } else {
                (x[0] - 0.9).powi(2)
            }
        };
        type Objective<'a> = &'a dyn Fn(&[f64], &mut [f64]) -> f64;
        let cases: [(Objective, Vec<f64>, f64, f64, Options); 6] = [
            (&rosen, vec![-1.2, 1.0, -0.5, 0.3, 0.8, -1.0], -2.0, 0.7, Options::default()),
            (&rosen, vec![0.0; 6], -2.0, 2.0, Options { max_iter: 7, ..Options::default() }),
            (&rosen, vec![0.5; 6], -2.0, 2.0, Options { max_evals: 13, ..Options::default() }),
            (&rosen, vec![0.5; 6], -2.0, 2.0, Options { max_iter: 0, ..Options::default() }),
            (&wall, vec![0.0], -1.0, 1.0, Options::default()),
            (&wall, vec![0.8], -1.0, 1.0, Options::default()),
        ];
        let mut stops = Vec::new();
        for (f, x0, lo, hi, opts) in cases {
            let want = minimize_loop(&mut |x, g| f(x, g), &x0, lo, hi, &opts);
            let got = minimize(&mut |x, g| f(x, g), &x0, lo, hi, &opts);
            let bits = |o: &Outcome| {
                (
                    o.x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    o.history.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                )
            };
            assert_eq!(bits(&got), bits(&want), "{x0:?}");
            assert_eq!((got.evaluations, got.stop), (want.evaluations, want.stop), "{x0:?}");
            stops.push(got.stop);
        }
        for stop in [Stop::Converged, Stop::MaxIter, Stop::MaxEvals, Stop::LineSearch] {
            assert!(stops.contains(&stop), "{stop:?} not reached: {stops:?}");
        }
    }

    /// Σ (w + i)·dᵢ² + q·dᵢ⁴ with dᵢ = xᵢ − c·(i − 1.5), and its gradient:
    /// a smooth bowl whose minimum moves with `c`.
    fn bowl(c: f64, w: f64, q: f64) -> impl Fn(&[f64], &mut [f64]) -> f64 {
        move |x: &[f64], g: &mut [f64]| -> f64 {
            let mut s = 0.0;
            for i in 0..x.len() {
                let d = x[i] - c * (i as f64 - 1.5);
                s += d * d * (w + i as f64) + q * d.powi(4);
                g[i] = 2.0 * d * (w + i as f64) + 4.0 * q * d.powi(3);
            }
            s
        }
    }

    #[test]
    fn minimizations_driven_side_by_side_are_each_their_own() {
        let (fa, fb) = (bowl(0.3, 1.0, 0.1), bowl(-0.7, 1.0, 0.1));
        let opts = Options::default();
        // Five starts: the odd one, and each one that finishes first, leave a place to the next.
        let starts: [&[f64]; 5] = [&[0.9; 4], &[-0.2; 3], &[0.1, 0.5, -0.3, 0.8], &[2.0; 3], &[-1.0; 4]];
        let alone: Vec<Outcome> = starts
            .iter()
            .map(|x0| match x0.len() {
                4 => minimize(&mut |x, g| fa(x, g), x0, -1.0, 1.0, &opts),
                _ => minimize(&mut |x, g| fb(x, g), x0, -1.0, 1.0, &opts),
            })
            .collect();
        let evals: Vec<usize> = alone.iter().map(|o| o.evaluations).collect();
        for width in 1..=4 {
            let mut calls = [0usize; 4];
            let mut both = |x: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]| {
                calls[x.len() - 1] += 1;
                // a has four variables, b three: each point tells whose it is.
                for k in 0..x.len() {
                    fx[k] = if x[k].len() == 4 { fa(x[k], g[k]) } else { fb(x[k], g[k]) };
                }
            };
            let got = minimize_each(&mut both, &starts, width, -1.0, 1.0, &opts);
            assert_eq!(got, alone, "width {width}");
            assert!(calls[width - 1] > 0 && calls[width..].iter().all(|c| *c == 0), "width {width}: {calls:?}");
            let asked: usize = calls.iter().enumerate().map(|(k, c)| (k + 1) * c).sum();
            assert_eq!(asked, evals.iter().sum::<usize>(), "width {width}");
            // Fewer than `width` run only once no start is left: at most
            // the longest run's evaluations.
            let fewer: usize = calls[..width - 1].iter().sum();
            assert!(fewer <= *evals.iter().max().unwrap(), "width {width}: {calls:?} {evals:?}");
        }
        let mut none = |_: &[&[f64]], _: &mut [&mut [f64]], _: &mut [f64]| panic!("no start, no evaluation");
        assert!(minimize_each(&mut none, &[], 2, -1.0, 1.0, &opts).is_empty());
    }

    #[test]
    fn each_start_may_have_an_objective_of_its_own() {
        // Three objectives over the same four variables: only the start's
        // index tells them apart.
        let objectives = [bowl(0.3, 2.0, 0.2), bowl(-0.7, 2.0, 0.2), bowl(0.05, 2.0, 0.2)];
        let whose = [0, 1, 2, 1, 0, 2, 2];
        let starts: Vec<Vec<f64>> =
            (0..whose.len()).map(|k| (0..4).map(|i| ((k * 7 + i * 3) % 5) as f64 * 0.4 - 0.8).collect()).collect();
        let points: Vec<&[f64]> = starts.iter().map(Vec::as_slice).collect();
        let opts = Options::default();
        let alone: Vec<Outcome> = points
            .iter()
            .zip(whose)
            .map(|(x0, w)| minimize(&mut |x, g| objectives[w](x, g), x0, -1.0, 1.0, &opts))
            .collect();
        for width in 1..=4 {
            let mut each = |i: &[usize], x: &[&[f64]], g: &mut [&mut [f64]], fx: &mut [f64]| {
                for k in 0..x.len() {
                    fx[k] = objectives[whose[i[k]]](x[k], g[k]);
                }
            };
            assert_eq!(minimize_each_of(&mut each, &points, width, -1.0, 1.0, &opts), alone, "width {width}");
        }
        // The objectives differ enough that a point given the wrong one goes elsewhere.
        assert_ne!(alone[0].x, minimize(&mut |x, g| objectives[1](x, g), points[0], -1.0, 1.0, &opts).x);
    }

    /// The two-loop recursion as first written: every dot product a pass
    /// of its own, each pair's sᵀy taken again in each loop.
    #[allow(clippy::needless_range_loop)] // kept as it was written
    fn direction_plain(m: &Memory, g: &[f64], free: &[bool], d: &mut [f64]) {
        let dotp = |a: &[f64], b: &[f64]| -> f64 {
            a.iter().zip(b).zip(free).filter(|(_, f)| **f).map(|((a, b), _)| a * b).sum()
        };
        let n = g.len();
        for i in 0..n {
            d[i] = if free[i] { g[i] } else { 0.0 };
        }
        let k = m.s.len();
        let mut alpha = vec![0.0; k];
        for j in (0..k).rev() {
            let sy = dotp(&m.s[j], &m.y[j]);
            if sy <= 0.0 {
                continue;
            }
            let a = dotp(&m.s[j], d) / sy;
            alpha[j] = a;
            for i in 0..n {
                if free[i] {
                    d[i] -= a * m.y[j][i];
                }
            }
        }
        if k > 0 {
            let (sy, yy) = (dotp(&m.s[k - 1], &m.y[k - 1]), dotp(&m.y[k - 1], &m.y[k - 1]));
            if sy > 0.0 && yy > 0.0 {
                let gamma = sy / yy;
                d.iter_mut().for_each(|v| *v *= gamma);
            }
        }
        for j in 0..k {
            let sy = dotp(&m.s[j], &m.y[j]);
            if sy <= 0.0 {
                continue;
            }
            let b = dotp(&m.y[j], d) / sy;
            for i in 0..n {
                if free[i] {
                    d[i] += m.s[j][i] * (alpha[j] - b);
                }
            }
        }
        d.iter_mut().for_each(|v| *v = -*v);
    }

    #[test]
    fn the_direction_has_the_bits_of_the_plain_two_loop_recursion() {
        let mut r = crate::rng::Rng::new(17);
        for n in [1, 2, 3, 7, 64, 301] {
            for pairs in 0..=11 {
                let mut m = Memory::new(10);
                for _ in 0..pairs.min(10) {
                    let s: Vec<f64> =
                        (0..n).map(|_| r.gaussian() * 10f64.powi((r.uniform() * 12.0) as i32 - 6)).collect();
                    // Mostly positive curvature, some pairs not (the loops skip those).
                    let flip = if r.uniform() < 0.2 { -1.0 } else { 1.0 };
                    let y: Vec<f64> = s.iter().map(|v| flip * v * (0.5 + r.uniform()) + 0.1 * r.gaussian()).collect();
                    m.s.push(s);
                    m.y.push(y);
                }
                let g: Vec<f64> = (0..n).map(|_| r.gaussian()).collect();
                for p_free in [1.0, 0.7, 0.0] {
                    let free: Vec<bool> = (0..n).map(|_| r.uniform() < p_free).collect();
                    let (mut got, mut want) = (vec![0.0; n], vec![0.0; n]);
                    m.direction(&g, &free, &mut got);
                    direction_plain(&m, &g, &free, &mut want);
                    for i in 0..n {
                        assert_eq!(got[i].to_bits(), want[i].to_bits(), "n {n}, {pairs} pairs, free {p_free}, i {i}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_diagonal_quadratic_lands_on_the_clamped_minimum() {
        // f = Σ a_i (x_i − c_i)²: the box minimum is clamp(c_i) exactly.
        let a = [1.0, 10.0, 0.1, 3.0, 50.0];
        let c = [0.3, 2.0, -4.0, -0.7, 1.0];
        let mut f = |x: &[f64], g: &mut [f64]| {
            let mut v = 0.0;
            for ((gi, xi), (ai, ci)) in g.iter_mut().zip(x).zip(a.iter().zip(&c)) {
                v += ai * (xi - ci).powi(2);
                *gi = 2.0 * ai * (xi - ci);
            }
            v
        };
        let out = minimize(&mut f, &[0.0; 5], -1.0, 1.0, &Options { f_rel_tol: 0.0, ..Options::default() });
        for (i, (x, c)) in out.x.iter().zip(&c).enumerate() {
            assert!((x - c.clamp(-1.0, 1.0)).abs() < 1e-8, "x[{i}] = {x}");
        }
        assert_eq!(out.stop, Stop::Stationary);
    }

    #[test]
    fn bounded_rosenbrock_stops_on_the_bound_at_its_kkt_point() {
        // Over x ≤ 0.5 the minimum of Rosenbrock is (0.5, 0.25), f = 0.25:
        // there ∂f/∂x₁ = −1 pushes against the bound and ∂f/∂x₂ = 0.
        let mut f = |x: &[f64], g: &mut [f64]| {
            let (a, b) = (x[0], x[1]);
            g[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
            g[1] = 200.0 * (b - a * a);
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
        };
        let opts = Options { max_iter: 500, ..Options::default() };
        let out = minimize(&mut f, &[-1.2, 1.0], -2.0, 0.5, &opts);
        assert!((out.x[0] - 0.5).abs() < 1e-9 && (out.x[1] - 0.25).abs() < 1e-6, "{:?}", out.x);
        assert!((out.f - 0.25).abs() < 1e-9, "{}", out.f);
    }

    #[test]
    fn never_leaves_the_box_and_never_raises_the_objective() {
        // A coupled, badly scaled quartic in 40 variables, from many starts.
        let mut r = crate::rng::Rng::new(3);
        let n = 40;
        let w: Vec<f64> = (0..n).map(|_| 0.1 + 10.0 * r.uniform()).collect();
        let mut f = |x: &[f64], g: &mut [f64]| {
            let mut v = 0.0;
            g.iter_mut().for_each(|g| *g = 0.0);
            for i in 0..n {
                let j = (i + 1) % n;
                let e = x[i] * x[i] - 0.5 * x[j] - 0.3 * w[i];
                v += w[i] * e * e;
                g[i] += 4.0 * w[i] * e * x[i];
                g[j] -= w[i] * e;
            }
            v
        };
        for start in 0..10 {
            let x0: Vec<f64> = (0..n).map(|_| 4.0 * r.uniform() - 2.0).collect();
            let out = minimize(&mut f, &x0, -1.0, 1.0, &Options { max_iter: 60, ..Options::default() });
            assert!(out.x.iter().all(|v| (-1.0..=1.0).contains(v)), "start {start}");
            assert!(out.history.windows(2).all(|p| p[1] <= p[0]), "start {start}: {:?}", out.history);
            assert!(out.f <= out.history[0]);
        }
    }

    #[test]
    fn a_non_finite_objective_is_backed_away_from() {
        // f is infinite beyond x = 0.2: the search must stop short of it.
        let mut f = |x: &[f64], g: &mut [f64]| {
            g[0] = -1.0;
            if x[0] > 0.2 {
                f64::INFINITY
            } else {
                -x[0]
            }
        };
        let out = minimize(&mut f, &[0.0], -1.0, 1.0, &Options::default());
        assert!(out.x[0] <= 0.2 && out.f.is_finite(), "{:?}", out);
    }
}
