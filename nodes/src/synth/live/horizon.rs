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
//! rises and x never leaves the box.
//!
//! **Cost.** The played envelopes before n are the same in every evaluation
//! of one tick, so their part of each window is summed once per tick
//! ([`Horizon::step`]'s preparation, Σ_k M·(M − 1 − k) multiply-adds over
//! the k < M − 1 whose window reaches into the past): per sample k a
//! constant (past × past, and the linear term over the past) and, for every
//! free i, the row sum Σ_{j past} Q_ij·a_j. An evaluation then multiplies
//! only the free part, Σ_k min(k + 1, M)² multiply-adds (M = 20, H = 16:
//! 1 496, against H·M² = 6 400 for the whole windows). The worst case is
//! fixed: one preparation and `iterations` + 2 evaluations. Each tick lays
//! the model's Q out transposed, so that a window's row products run four
//! rows at a time ([`dot_columns`]: each row summed as the row dot
//! product, the same bits), and on CPUs with AVX2 the evaluations run
//! compiled for it (Rust never fuses a multiply and an add on its own, so
//! the portable and AVX2 builds give the same bits; a test checks both
//! against the row-by-row evaluation).
//!
//! **Fallback.** When the budget runs out (the iterations, or the optional
//! deadline) the best point found is played: never worse than the better
//! start. A model without carrier gain (κ ≤ 0: the model explains nothing a
//! carrier could use) plays nothing; a non-finite objective plays the
//! carrier start. Nothing here allocates after [`Horizon::new`].

use super::envelope::EnvelopeModel;
use crate::linalg::dot_columns::{dot_columns, ROWS};
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
    /// The last M−1 played envelopes, oldest first.
    buf: Vec<f64>,
    /// The free part of one window, newest first: w_i = x[k − i].
    win: Vec<f64>,
    /// Per sample k of the horizon, the part of y[n+k] that the played
    /// envelopes alone make (past × past and the linear term over them).
    fixed: Vec<f64>,
    /// Per sample k, row-major H × M: Σ_{j past} Q_ij·a_j for each free i.
    cross: Vec<f64>,
    /// The played envelopes, newest first (scratch of the preparation).
    past: Vec<f64>,
    /// Qᵀ of this tick's model, column t from `qt[t·mp]`, each column
    /// padded with zeros to mp rows, so that the dot products of every row
    /// of Q run four rows at a time ([`dot_columns`]).
    qt: Vec<f64>,
    /// M rounded up to a multiple of [`ROWS`].
    mp: usize,
    /// The dot products of Q's rows (mp of them; scratch).
    rows: Vec<f64>,
    /// The CPU has AVX2: the evaluations run compiled for it.
    avx2: bool,
    x: Vec<f64>,
    g: Vec<f64>,
    xt: Vec<f64>,
    gt: Vec<f64>,
    carrier: Vec<f64>,
    warm: Vec<f64>,
    z: Vec<f64>,
    has_warm: bool,
}

/// Which of the solver's two points an evaluation reads (and whose
/// gradient it writes).
#[derive(Debug, Clone, Copy)]
enum Point {
    /// `x`, its gradient `g`.
    Current,
    /// `xt`, its gradient `gt`.
    Trial,
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
        let mp = m.div_ceil(ROWS) * ROWS;
        Self {
            qt: vec![0.0; m * mp],
            mp,
            rows: vec![0.0; mp],
            avx2: crate::cpu::has_avx2_fma(),
            m,
            h,
            buf: vec![0.0; m - 1],
            fixed: vec![0.0; h],
            cross: vec![0.0; h * m],
            past: vec![0.0; m - 1],
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

    /// Sums, for tick `n`, the part of every window that the played
    /// envelopes fill: [`Horizon::fixed`] and [`Horizon::cross`]; first
    /// lays out the model's Qᵀ for [`dot_columns`].
    fn prepare(&mut self, n: u64, model: &EnvelopeModel) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `new` found AVX2 on this CPU.
            return unsafe { self.prepare_avx2(n, model) };
        }
        self.prepare_impl(n, model)
    }

    /// [`Horizon::prepare`] compiled for AVX2 (the same operations: Rust
    /// never fuses a multiply and an add on its own, so the same bits).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn prepare_avx2(&mut self, n: u64, model: &EnvelopeModel) {
        self.prepare_impl(n, model)
    }

    #[inline(always)]
    fn prepare_impl(&mut self, n: u64, model: &EnvelopeModel) {
        let (m, h, mp) = (self.m, self.h, self.mp);
        for i in 0..m {
            for (t, q) in model.q[i * m..(i + 1) * m].iter().enumerate() {
                self.qt[t * mp + i] = *q;
            }
        }
        // The played envelopes newest first: past[t] = a[n − 1 − t].
        for (t, p) in self.past.iter_mut().enumerate() {
            *p = self.buf[m - 2 - t];
        }
        self.fixed.iter_mut().for_each(|v| *v = 0.0);
        // Window k holds x[k − i] for i ≤ k and, for i > k, the played
        // a[n + k − i] = past[i − k − 1]; only k < M − 1 reaches back. Every
        // row i's product over the past, Σ_t Q_i,k+1+t·past[t], is summed
        // as the row dot product would be, all rows at once.
        for k in 0..h.min(m - 1) {
            let s = parity(n + k as u64);
            let past = &self.past[..m - k - 1];
            dot_columns(&self.qt[(k + 1) * mp..], mp, past, &mut self.rows);
            let mut fixed = 0.0;
            for i in k + 1..m {
                fixed += past[i - k - 1] * (self.rows[i] + s * model.lt[i]);
            }
            self.fixed[k] = fixed;
            self.cross[k * m..k * m + k + 1].copy_from_slice(&self.rows[..=k]);
        }
    }

    /// J at `x`, its gradient into `g`, and the model's force change at
    /// the first sample; [`Horizon::prepare`] has summed the past.
    fn value_grad(&mut self, which: Point, n: u64, f: &[f64], b: f64, model: &EnvelopeModel) -> (f64, f64) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `new` found AVX2 on this CPU.
            return unsafe { self.value_grad_avx2(which, n, f, b, model) };
        }
        self.value_grad_impl(which, n, f, b, model)
    }

    /// [`Horizon::value_grad`] compiled for AVX2 (the same bits).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn value_grad_avx2(&mut self, which: Point, n: u64, f: &[f64], b: f64, model: &EnvelopeModel) -> (f64, f64) {
        self.value_grad_impl(which, n, f, b, model)
    }

    #[inline(always)]
    fn value_grad_impl(&mut self, which: Point, n: u64, f: &[f64], b: f64, model: &EnvelopeModel) -> (f64, f64) {
        let m = self.m;
        let (x, g) = match which {
            Point::Current => (&self.x, &mut self.g),
            Point::Trial => (&self.xt, &mut self.gt),
        };
        let (win, z, rows) = (&mut self.win, &mut self.z, &mut self.rows);
        let h = x.len();
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut j = 0.0;
        let mut first = 0.0;
        let lt = &model.lt[..m];
        for k in 0..h {
            let s = parity(n + k as u64);
            // The free part of the window, newest first, so that each row's
            // product runs over two contiguous slices: i ≤ kf.
            let kf = k.min(m - 1);
            let len = kf + 1;
            let win = &mut win[..len];
            for (wi, xi) in win.iter_mut().zip(x[k - kf..=k].iter().rev()) {
                *wi = *xi;
            }
            // Σ_j Q_ij w_j for the rows i ≤ kf (and a few beyond, unread).
            let rows = &mut rows[..len.div_ceil(ROWS) * ROWS];
            dot_columns(&self.qt, self.mp, win, rows);
            let cross = &self.cross[k * m..k * m + len];
            let z = &mut z[..len];
            let mut y = self.fixed[k];
            for (((zi, r), c), (w, l)) in z.iter_mut().zip(&rows[..len]).zip(cross).zip(win.iter().zip(lt)) {
                // z_i = Σ_j Q_ij w_j over the whole window (Q symmetric).
                *zi = r + c;
                y += w * (*zi + c + s * l);
            }
            if k == 0 {
                first = y;
            }
            let e = y - b - f[k];
            j += e * e;
            // Row i of the window is sample k − i.
            for ((gi, zi), l) in g[k - kf..=k].iter_mut().rev().zip(&*z).zip(lt) {
                *gi += 2.0 * e * (2.0 * zi + s * l);
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
        let h = self.h;
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
        self.prepare(n, model);
        let (mut jx, mut first) = self.value_grad(Point::Current, n, f, b, model);
        if self.has_warm {
            self.xt[..h - 1].copy_from_slice(&self.warm[1..]);
            self.xt[h - 1] = self.carrier[h - 1];
            let (jt, ft) = self.value_grad(Point::Trial, n, f, b, model);
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
            let (jt, ft) = self.value_grad(Point::Trial, n, f, b, model);
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
        for (m, h, played) in [(2, 6, vec![0.4]), (5, 4, vec![0.4, 0.1, 0.7, 0.2]), (3, 7, vec![0.3, 0.6])] {
            let model = pseudo_random_model(m);
            let mut hz = Horizon::new(m, h);
            played.iter().for_each(|a| hz.commit(*a));
            let f: Vec<f64> = (0..h).map(|k| 0.02 * ((k * 7 % 5) as f64 - 2.0)).collect();
            let x: Vec<f64> = (0..h).map(|k| 0.1 + 0.08 * ((k * 3 % 7) as f64)).collect();
            hz.prepare(7, &model);
            let value = |hz: &mut Horizon, x: &[f64]| {
                hz.xt.copy_from_slice(x);
                hz.value_grad(Point::Trial, 7, &f, 0.05, &model)
            };
            value(&mut hz, &x);
            let g = hz.gt.clone();
            for k in 0..h {
                let (mut a, mut b) = (x.clone(), x.clone());
                a[k] += 1e-6;
                b[k] -= 1e-6;
                let fd = (value(&mut hz, &a).0 - value(&mut hz, &b).0) / 2e-6;
                assert!((fd - g[k]).abs() < 1e-6 * (1.0 + fd.abs()), "M {m}, x[{k}]: {} vs {fd}", g[k]);
            }
        }
    }

    /// A model of memory `m` with every coefficient set (Q symmetric).
    fn pseudo_random_model(m: usize) -> EnvelopeModel {
        let mut q = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                q[i * m + j] = 0.3 / (1.0 + (i + j) as f64) * if (i * j) % 3 == 1 { -1.0 } else { 1.0 };
            }
        }
        let lt = (0..m).map(|i| 0.01 * (i as f64 - 1.5)).collect();
        let kappa = q.iter().sum();
        EnvelopeModel { memory: m, q, lt, kappa, beta: 1e-3 }
    }

    /// The evaluation as it was before the rows' dot products were taken
    /// four at a time: each row's window by [`crate::linalg::dot`].
    /// Returns (J, y at the first sample, the gradient).
    fn row_by_row(hz: &Horizon, n: u64, x: &[f64], f: &[f64], b: f64, model: &EnvelopeModel) -> (f64, f64, Vec<f64>) {
        use crate::linalg::dot;
        let (m, h) = (hz.m, x.len());
        let past: Vec<f64> = (0..m - 1).map(|t| hz.buf[m - 2 - t]).collect();
        let (mut fixed, mut cross) = (vec![0.0; h], vec![0.0; h * m]);
        for k in 0..h.min(m - 1) {
            let s = parity(n + k as u64);
            let past = &past[..m - k - 1];
            for i in k + 1..m {
                let zi = dot(&model.q[i * m + k + 1..(i + 1) * m], past);
                fixed[k] += past[i - k - 1] * (zi + s * model.lt[i]);
            }
            for i in 0..=k {
                cross[k * m + i] = dot(&model.q[i * m + k + 1..(i + 1) * m], past);
            }
        }
        let (mut j, mut first, mut g) = (0.0, 0.0, vec![0.0; h]);
        for k in 0..h {
            let s = parity(n + k as u64);
            let kf = k.min(m - 1);
            let win: Vec<f64> = (0..=kf).map(|i| x[k - i]).collect();
            let mut y = fixed[k];
            let mut z = vec![0.0; kf + 1];
            for i in 0..=kf {
                z[i] = dot(&model.q[i * m..i * m + kf + 1], &win) + cross[k * m + i];
                y += win[i] * (z[i] + cross[k * m + i] + s * model.lt[i]);
            }
            if k == 0 {
                first = y;
            }
            let e = y - b - f[k];
            j += e * e;
            for i in 0..=kf {
                g[k - i] += 2.0 * e * (2.0 * z[i] + s * model.lt[i]);
            }
        }
        for (gk, xk) in g.iter_mut().zip(x) {
            j += model.beta * xk * xk;
            *gk += 2.0 * model.beta * xk;
        }
        (j, first, g)
    }

    #[test]
    fn the_evaluation_has_the_bits_of_the_row_by_row_one() {
        let mut r = crate::rng::Rng::new(17);
        // Memories and horizons around the blocks of four, the shipped
        // M = 20, H = 16 among them; Q not symmetric (nothing relies on it).
        for (m, h) in [(1, 3), (2, 8), (3, 5), (4, 4), (5, 9), (7, 16), (20, 16), (21, 16), (20, 25)] {
            let mut model = pseudo_random_model(m);
            model.q.iter_mut().for_each(|q| *q *= 1.0 + 0.3 * r.uniform());
            let mut hz = Horizon::new(m, h);
            for _ in 0..m + 3 {
                hz.commit(r.uniform());
            }
            // Both builds: the portable one and, where the CPU has it, AVX2's.
            for (n, avx2) in [(4u64, false), (7, false), (4, hz.avx2), (7, hz.avx2)] {
                hz.avx2 = avx2;
                let f: Vec<f64> = (0..h).map(|_| 0.1 * (2.0 * r.uniform() - 1.0)).collect();
                let x: Vec<f64> = (0..h).map(|_| r.uniform()).collect();
                hz.prepare(n, &model);
                hz.x.copy_from_slice(&x);
                let (j, first) = hz.value_grad(Point::Current, n, &f, 0.05, &model);
                let (wj, wfirst, wg) = row_by_row(&hz, n, &x, &f, 0.05, &model);
                assert_eq!(
                    (j.to_bits(), first.to_bits()),
                    (wj.to_bits(), wfirst.to_bits()),
                    "M {m}, H {h}, AVX2 {avx2}"
                );
                for (a, b) in hz.g.iter().zip(&wg) {
                    assert_eq!(a.to_bits(), b.to_bits(), "M {m}, H {h}: gradient");
                }
            }
        }
    }

    #[test]
    fn the_split_windows_give_the_whole_windows_objective() {
        // y[n+k] summed over the whole window a[n+k−i], i < M, written out.
        let (m, h, n) = (5, 7, 3u64);
        let model = pseudo_random_model(m);
        let played = [0.4, 0.1, 0.7, 0.2];
        let mut hz = Horizon::new(m, h);
        played.iter().for_each(|a| hz.commit(*a));
        let f: Vec<f64> = (0..h).map(|k| 0.01 * k as f64).collect();
        let x: Vec<f64> = (0..h).map(|k| 0.2 + 0.05 * k as f64).collect();
        let (b, all): (f64, Vec<f64>) = (0.05, played.iter().chain(&x).copied().collect());
        let mut want = 0.0;
        let mut first = 0.0;
        for k in 0..h {
            let p = m - 1 + k;
            let s = parity(n + k as u64);
            let mut y = 0.0;
            for i in 0..m {
                y += s * model.lt[i] * all[p - i];
                for j in 0..m {
                    y += model.q[i * m + j] * all[p - i] * all[p - j];
                }
            }
            if k == 0 {
                first = y;
            }
            want += (y - b - f[k]).powi(2) + model.beta * x[k] * x[k];
        }
        hz.prepare(n, &model);
        hz.x.copy_from_slice(&x);
        let (j, y0) = hz.value_grad(Point::Current, n, &f, b, &model);
        assert!((j - want).abs() < 1e-12 * want.max(1.0), "{j} vs {want}");
        assert!((y0 - first).abs() < 1e-12, "{y0} vs {first}");
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
