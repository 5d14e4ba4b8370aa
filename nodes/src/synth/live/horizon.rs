//! The receding-horizon synthesis of one tick: the carrier envelope over
//! the next H samples whose force, through the forward model, follows the
//! target force, with the noise an actuation brings counted; the first
//! sample is played, the rest warm-starts the next tick.
//!
//! At tick n, with the envelopes before n fixed (played) and x_k = a[n + k]
//! free for k = 0 … H−1:
//!
//! ```text
//! J(x) = Σ_k ( y[n+k] − c − b − f[n+k] )²  +  β · Σ_k x_k²,     0 ≤ x_k ≤ bound
//! ```
//!
//! y the model's force ([`super::envelope`]: c its constant), f the target
//! (the texture's force where the finger will be), b the offset — the steady
//! friction the carrier keeps so that the target's troughs can be rendered
//! (a square law only adds friction); the 10 Hz high-pass that every
//! recording went through removes b, and b moves slowly. β is the model's
//! learned noise slope: the residual power grows by β per unit of u², so an
//! actuation that buys a little match with much more noise loses (the
//! `time` objective of `synth.optimize`, in newtons² rather than relative).
//!
//! **Starts.** The previous tick's solution shifted by one sample (its last
//! sample from the carrier start), and the square-law envelope on the
//! carrier, x_k = √(max(0, (f[n+k] + b)/κ)); the better of the two is kept.
//!
//! **Iterations.** Projected gradient steps with the Barzilai–Borwein step
//! length (Barzilai & Borwein 1988; projected: Birgin, Martínez & Raydan
//! 2000), each one evaluation of J and its gradient, a step that does not
//! lower J shrinking the step length fourfold and being refused — so J never
//! rises and x never leaves the box. The worst case is fixed:
//! `iterations` + 2 evaluations of H·(M² + 3M) multiply-adds each.
//!
//! **Fallback.** When the budget runs out (the iterations, or the optional
//! deadline) the best point found is played: never worse than the better
//! start. A model without carrier gain (κ ≤ 0: the model explains nothing a
//! carrier could use) plays nothing; a non-finite objective plays the
//! carrier start. Nothing here allocates after [`Horizon::new`].

use super::envelope::EnvelopeModel;
use crate::linalg::dot;
use std::time::Instant;

/// How one tick's synthesis went.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TickOutcome {
    /// The envelope to play now (before any gating), in [0, bound].
    pub envelope: f64,
    /// Optimizer iterations made (evaluations beyond the two starts).
    pub iterations: usize,
    /// J at the better start.
    pub start_objective: f64,
    /// J at the point played.
    pub objective: f64,
    /// The deadline stopped the iterations.
    pub budget_stop: bool,
    /// The carrier start or silence was played instead of an optimized point.
    pub fallback: bool,
    /// The model's expected force change now, y\[n\] − c − b (N): what the
    /// synthesis expects the display to render of the target.
    pub predicted: f64,
}

/// The solver's state and scratch, sized once.
#[derive(Debug, Clone)]
pub struct Horizon {
    m: usize,
    h: usize,
    /// [the last M−1 played envelopes | the H free ones].
    buf: Vec<f64>,
    /// One window, newest first: w_i = a[k − i].
    win: Vec<f64>,
    x: Vec<f64>,
    g: Vec<f64>,
    xt: Vec<f64>,
    gt: Vec<f64>,
    carrier: Vec<f64>,
    warm: Vec<f64>,
    z: Vec<f64>,
    has_warm: bool,
}

/// The carrier's sign at sample n.
#[inline]
fn parity(n: u64) -> f64 {
    if n.is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

impl Horizon {
    /// A solver for a model of memory `m` over a horizon of `h` samples.
    pub fn new(m: usize, h: usize) -> Self {
        let (m, h) = (m.max(1), h.max(1));
        Self {
            m,
            h,
            buf: vec![0.0; m - 1 + h],
            x: vec![0.0; h],
            g: vec![0.0; h],
            xt: vec![0.0; h],
            gt: vec![0.0; h],
            carrier: vec![0.0; h],
            warm: vec![0.0; h],
            z: vec![0.0; m],
            win: vec![0.0; m],
            has_warm: false,
        }
    }

    /// The horizon H, samples.
    pub fn horizon(&self) -> usize {
        self.h
    }

    /// Back to silence: no envelope played, no warm start.
    pub fn reset(&mut self) {
        self.buf.iter_mut().for_each(|v| *v = 0.0);
        self.has_warm = false;
    }

    /// J at `x` (copied into the buffer), its gradient into `g`, and the
    /// model's force change at the first sample.
    #[allow(clippy::too_many_arguments)]
    fn value_grad(
        buf: &mut [f64],
        z: &mut [f64],
        win: &mut [f64],
        m: usize,
        x: &[f64],
        g: &mut [f64],
        n: u64,
        f: &[f64],
        b: f64,
        model: &EnvelopeModel,
    ) -> (f64, f64) {
        let h = x.len();
        buf[m - 1..].copy_from_slice(x);
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut j = 0.0;
        let mut first = 0.0;
        for k in 0..h {
            let p = m - 1 + k;
            let s = parity(n + k as u64);
            // z = Q·w over the window w_i = buf[p − i], copied newest first
            // so that each row's product runs over two contiguous slices.
            for (i, wi) in win.iter_mut().enumerate() {
                *wi = buf[p - i];
            }
            let mut y = 0.0;
            for i in 0..m {
                let zi = dot(&model.q[i * m..(i + 1) * m], win);
                z[i] = zi;
                y += win[i] * (zi + s * model.lt[i]);
            }
            if k == 0 {
                first = y;
            }
            let e = y - b - f[k];
            j += e * e;
            // Only the free samples (p − i ≥ m − 1, i.e. i ≤ k) take a gradient.
            for i in 0..=k.min(m - 1) {
                g[k - i] += 2.0 * e * (2.0 * z[i] + s * model.lt[i]);
            }
        }
        for (gk, xk) in g.iter_mut().zip(x) {
            j += model.beta * xk * xk;
            *gk += 2.0 * model.beta * xk;
        }
        (j, first)
    }

    /// A step length from a bound on J's curvature along one variable.
    fn first_step(model: &EnvelopeModel, bound: f64, h: usize) -> f64 {
        let m = model.memory;
        let mut s = 0.0;
        for i in 0..m {
            let row: f64 = model.q[i * m..(i + 1) * m].iter().map(|q| q.abs()).sum();
            let d = 2.0 * bound * row + model.lt[i].abs();
            s += d * d;
        }
        let l = 2.0 * s * (h.min(m) as f64).sqrt() + 2.0 * model.beta;
        if l.is_finite() && l > 0.0 {
            1.0 / l
        } else {
            1.0
        }
    }

    /// Synthesizes tick `n`: `f` holds the target for samples n … n+H−1
    /// (N), `b` the offset (N), `model` the forward model at the finger's
    /// condition; at most `iterations` iterations, and none once `deadline`
    /// has passed. Call [`Horizon::commit`] with what was played.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        n: u64,
        f: &[f64],
        b: f64,
        model: &EnvelopeModel,
        bound: f64,
        iterations: usize,
        deadline: Option<Instant>,
    ) -> TickOutcome {
        let (m, h) = (self.m, self.h);
        debug_assert_eq!(f.len(), h);
        let kappa = model.kappa;
        if !(kappa.is_finite() && kappa > 0.0 && b.is_finite()) {
            self.has_warm = false;
            return TickOutcome { fallback: true, ..TickOutcome::default() };
        }
        for (c, fk) in self.carrier.iter_mut().zip(f) {
            let a = ((fk + b) / kappa).max(0.0).sqrt();
            *c = if a.is_finite() { a.min(bound) } else { 0.0 };
        }
        // The two starts: the carrier envelope, and last tick's solution shifted.
        self.x.copy_from_slice(&self.carrier);
        let (mut jx, mut first) =
            Self::value_grad(&mut self.buf, &mut self.z, &mut self.win, m, &self.x, &mut self.g, n, f, b, model);
        if self.has_warm {
            self.xt[..h - 1].copy_from_slice(&self.warm[1..]);
            self.xt[h - 1] = self.carrier[h - 1];
            let (jt, ft) =
                Self::value_grad(&mut self.buf, &mut self.z, &mut self.win, m, &self.xt, &mut self.gt, n, f, b, model);
            if jt < jx || !jx.is_finite() {
                std::mem::swap(&mut self.x, &mut self.xt);
                std::mem::swap(&mut self.g, &mut self.gt);
                jx = jt;
                first = ft;
            }
        }
        let start = jx;
        if !jx.is_finite() {
            self.warm.copy_from_slice(&self.carrier);
            self.has_warm = true;
            return TickOutcome {
                envelope: self.carrier[0],
                start_objective: start,
                objective: start,
                fallback: true,
                ..TickOutcome::default()
            };
        }
        let (lo_step, hi_step) = (1e-12, 1e12);
        let mut alpha = Self::first_step(model, bound, h);
        let mut done = 0;
        let mut budget_stop = false;
        while done < iterations {
            if deadline.is_some_and(|d| Instant::now() >= d) {
                budget_stop = true;
                break;
            }
            for k in 0..h {
                self.xt[k] = (self.x[k] - alpha * self.g[k]).clamp(0.0, bound);
            }
            let (jt, ft) =
                Self::value_grad(&mut self.buf, &mut self.z, &mut self.win, m, &self.xt, &mut self.gt, n, f, b, model);
            done += 1;
            if jt < jx {
                // Barzilai–Borwein: α = sᵀs / sᵀy.
                let (mut ss, mut sy) = (0.0, 0.0);
                for k in 0..h {
                    let s = self.xt[k] - self.x[k];
                    ss += s * s;
                    sy += s * (self.gt[k] - self.g[k]);
                }
                alpha = if sy > 0.0 { (ss / sy).clamp(lo_step, hi_step) } else { (alpha * 2.0).min(hi_step) };
                std::mem::swap(&mut self.x, &mut self.xt);
                std::mem::swap(&mut self.g, &mut self.gt);
                jx = jt;
                first = ft;
            } else {
                alpha = (alpha * 0.25).max(lo_step);
            }
        }
        self.warm.copy_from_slice(&self.x);
        self.has_warm = true;
        TickOutcome {
            envelope: self.x[0],
            iterations: done,
            start_objective: start,
            objective: jx,
            budget_stop,
            fallback: false,
            predicted: first,
        }
    }

    /// Records the envelope played at this tick (after gating) as the
    /// newest past sample.
    pub fn commit(&mut self, played: f64) {
        let m = self.m;
        if m > 1 {
            self.buf.copy_within(1..m - 1, 0);
            self.buf[m - 2] = if played.is_finite() { played } else { 0.0 };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::volterra::Volterra;

    /// A square law after a two-tap filter: y = (g0·u[n] + g1·u[n−1])².
    fn square_law() -> EnvelopeModel {
        let (g0, g1) = (0.8, 0.3);
        let v = Volterra::new(vec![g0 * g0, g0 * g1, g0 * g1, g1 * g1], vec![0.0, 0.0], 0.0).unwrap();
        EnvelopeModel::of(&v, 1e-4)
    }

    #[test]
    fn the_objective_gradient_matches_central_differences() {
        let model = square_law();
        let mut hz = Horizon::new(2, 6);
        hz.commit(0.4);
        let f = [0.01, -0.02, 0.03, 0.0, 0.02, -0.01];
        let x = [0.3, 0.5, 0.2, 0.6, 0.4, 0.1];
        let mut g = [0.0; 6];
        let (mut buf, mut z, mut win) = (hz.buf.clone(), hz.z.clone(), hz.win.clone());
        Horizon::value_grad(&mut buf, &mut z, &mut win, 2, &x, &mut g, 7, &f, 0.05, &model);
        for k in 0..6 {
            let mut scratch = [0.0; 6];
            let (mut a, mut b) = (x, x);
            a[k] += 1e-6;
            b[k] -= 1e-6;
            let ja = Horizon::value_grad(&mut buf, &mut z, &mut win, 2, &a, &mut scratch, 7, &f, 0.05, &model).0;
            let jb = Horizon::value_grad(&mut buf, &mut z, &mut win, 2, &b, &mut scratch, 7, &f, 0.05, &model).0;
            let fd = (ja - jb) / 2e-6;
            assert!((fd - g[k]).abs() < 1e-6 * (1.0 + fd.abs()), "x[{k}]: {} vs {fd}", g[k]);
        }
    }

    #[test]
    fn iterations_never_raise_the_objective_nor_leave_the_bound() {
        let model = square_law();
        let mut hz = Horizon::new(2, 8);
        let bound = 0.7;
        for n in 0..200u64 {
            let f: Vec<f64> = (0..8).map(|k| 0.1 * ((n + k) as f64 * 0.2).sin()).collect();
            let out = hz.step(n, &f, 0.12, &model, bound, 6, None);
            assert!(out.objective <= out.start_objective, "tick {n}: {out:?}");
            assert!((0.0..=bound).contains(&out.envelope));
            assert!(hz.x.iter().all(|x| (0.0..=bound).contains(x)));
            assert!(out.iterations == 6 && !out.fallback);
            hz.commit(out.envelope);
        }
    }

    #[test]
    fn the_played_envelope_finds_one_the_model_renders_exactly() {
        // The target is the force the model makes for a known envelope (its
        // dynamics included, so the square-law start is not exact): the
        // optimized envelopes come closer to it than the starts do.
        let (g0, g1) = (0.8, 0.3);
        let v = Volterra::new(vec![g0 * g0, g0 * g1, g0 * g1, g1 * g1], vec![0.0, 0.0], 0.0).unwrap();
        let model = EnvelopeModel::of(&v, 0.0);
        let want: Vec<f64> = (0..400).map(|k| 0.5 + 0.3 * (k as f64 * 0.3).sin()).collect();
        let u: Vec<f64> = want.iter().enumerate().map(|(k, a)| if k % 2 == 0 { *a } else { -a }).collect();
        let mut y = vec![0.0; 400];
        v.eval(&u, &mut y);
        let b = 0.1;
        let f: Vec<f64> = y.iter().map(|y| y - b).collect();
        let h = 8;
        let (mut opt, mut start) = (Horizon::new(2, h), Horizon::new(2, h));
        let (mut err_opt, mut err_start) = (0.0, 0.0);
        for n in 0..390usize {
            let o = opt.step(n as u64, &f[n..n + h], b, &model, 1.0, 10, None);
            opt.commit(o.envelope);
            let s = start.step(n as u64, &f[n..n + h], b, &model, 1.0, 0, None);
            start.commit(s.envelope);
            if n > 20 {
                err_opt += (o.envelope - want[n]).powi(2);
                err_start += (s.envelope - want[n]).powi(2);
            }
        }
        assert!(err_opt < 0.1 * err_start, "optimized {err_opt} against the starts' {err_start}");
    }

    #[test]
    fn a_model_without_carrier_gain_plays_nothing_and_a_deadline_stops_the_iterations() {
        let v = Volterra::new(vec![-1.0], vec![0.0], 0.0).unwrap();
        let model = EnvelopeModel::of(&v, 0.0);
        let mut hz = Horizon::new(1, 4);
        let out = hz.step(0, &[0.1; 4], 0.1, &model, 1.0, 10, None);
        assert!(out.fallback && out.envelope == 0.0);
        let good = square_law();
        let mut hz = Horizon::new(2, 4);
        let out = hz.step(0, &[0.1; 4], 0.1, &good, 1.0, 10, Some(Instant::now()));
        assert!(out.budget_stop && out.iterations == 0 && out.envelope > 0.0);
        // Non-finite inputs: nothing non-finite comes out.
        let out = hz.step(1, &[f64::NAN; 4], 0.1, &good, 1.0, 10, None);
        assert!(out.envelope.is_finite());
        let out = hz.step(2, &[0.1; 4], f64::INFINITY, &good, 1.0, 10, None);
        assert!(out.envelope == 0.0 && out.fallback);
    }
}
