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
        // 1. Stationarity.
        let pg = x.iter().zip(&g).map(|(&xi, &gi)| (xi - b.proj(xi - gi)).abs()).fold(0.0, f64::max);
        if pg < opts.pg_tol {
            stop = Stop::Stationary;
            break;
        }
        // 2. Free variables and the two-loop recursion on them.
        for i in 0..n {
            free[i] = !((x[i] <= lo + eps && g[i] > 0.0) || (x[i] >= hi - eps && g[i] < 0.0));
        }
        mem.direction(&g, &free, &mut d);
        let step = mem.first_step(&g, &free, &mut d, &b);
        // 3. Backtracking along the projection arc.
        let Some(f_new) = line_search(f, &b, (&x, &g, fx), &d, step, (&mut xt, &mut gt), &mut evals, opts) else {
            stop = if evals >= opts.max_evals { Stop::MaxEvals } else { Stop::LineSearch };
            break;
        };
        // 4. Curvature pair.
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

/// aᵀb over the free variables.
fn dot(a: &[f64], b: &[f64], free: &[bool]) -> f64 {
    a.iter().zip(b).zip(free).filter(|(_, f)| **f).map(|((a, b), _)| a * b).sum()
}

/// The last pairs (s, y) of L-BFGS, oldest first.
struct Memory {
    cap: usize,
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    alpha: Vec<f64>,
}

impl Memory {
    fn new(cap: usize) -> Self {
        Self { cap, s: Vec::with_capacity(cap), y: Vec::with_capacity(cap), alpha: vec![0.0; cap] }
    }

    /// d = −H·g on the free variables (0 on the others): the two-loop
    /// recursion over the pairs kept, scaled by sᵀy/yᵀy of the last.
    fn direction(&mut self, g: &[f64], free: &[bool], d: &mut [f64]) {
        let n = g.len();
        for i in 0..n {
            d[i] = if free[i] { g[i] } else { 0.0 };
        }
        let k = self.s.len();
        for j in (0..k).rev() {
            let sy = dot(&self.s[j], &self.y[j], free);
            if sy <= 0.0 {
                self.alpha[j] = 0.0;
                continue;
            }
            let a = dot(&self.s[j], d, free) / sy;
            self.alpha[j] = a;
            for i in 0..n {
                if free[i] {
                    d[i] -= a * self.y[j][i];
                }
            }
        }
        if k > 0 {
            let (sy, yy) = (dot(&self.s[k - 1], &self.y[k - 1], free), dot(&self.y[k - 1], &self.y[k - 1], free));
            if sy > 0.0 && yy > 0.0 {
                let gamma = sy / yy;
                d.iter_mut().for_each(|v| *v *= gamma);
            }
        }
        for j in 0..k {
            let sy = dot(&self.s[j], &self.y[j], free);
            if sy <= 0.0 {
                continue;
            }
            let b = dot(&self.y[j], d, free) / sy;
            for i in 0..n {
                if free[i] {
                    d[i] += self.s[j][i] * (self.alpha[j] - b);
                }
            }
        }
        d.iter_mut().for_each(|v| *v = -*v);
    }

    /// The first trial step along `d`: 1, or where `d` is no descent
    /// direction (the pairs are forgotten and `d` becomes −g on the free
    /// variables) or no pair is kept, scaled so that the largest move is
    /// at most the box size.
    fn first_step(&mut self, g: &[f64], free: &[bool], d: &mut [f64], b: &Box1) -> f64 {
        let gd: f64 = g.iter().zip(d.iter()).map(|(a, b)| a * b).sum();
        let gnorm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
        let dnorm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
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

/// Backtracking along the projection arc from `x` (gradient `g`, value
/// `fx`) in direction `d`, from `step` halving up to 60 times: the first
/// trial point with the Armijo decrease, left in `xt` (gradient in `gt`),
/// and its value; `None` when none was found (or `max_evals` was reached).
#[allow(clippy::too_many_arguments)]
fn line_search(
    f: &mut dyn FnMut(&[f64], &mut [f64]) -> f64,
    b: &Box1,
    (x, g, fx): (&[f64], &[f64], f64),
    d: &[f64],
    mut step: f64,
    (xt, gt): (&mut [f64], &mut [f64]),
    evals: &mut usize,
    opts: &Options,
) -> Option<f64> {
    for _ in 0..60 {
        if *evals >= opts.max_evals {
            break;
        }
        for i in 0..x.len() {
            xt[i] = b.proj(x[i] + step * d[i]);
        }
        let decrease: f64 = g.iter().zip(xt.iter().zip(x)).map(|(gi, (a, b))| gi * (a - b)).sum();
        let ft = f(xt, gt);
        *evals += 1;
        if ft.is_finite() && gt.iter().all(|v| v.is_finite()) && ft <= fx + opts.c1 * decrease && ft <= fx {
            return Some(ft);
        }
        step *= 0.5;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

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
