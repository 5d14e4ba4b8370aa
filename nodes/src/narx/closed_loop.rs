//! Closed-loop (parallel) inference, dissertation Fig. 5.3(b): the
//! network's own estimates are fed back in place of the reference, one
//! sample per call, without allocating.
//!
//! Each call takes the newest force sample x\[t\] and returns the estimate
//! of u[t − L], L = max(d, 0) the look-ahead latency ([`super::taps`]).
//! Before the histories have filled, missing force samples count as 0 N and
//! missing past estimates as u = 0.
//!
//! Bounds: the network output (normalized units) is clamped to [−1, 1], the
//! range the training targets were mapped to, before it is fed back and
//! mapped back to actuation units — so the estimate always stays within the
//! training range of u, whatever the force does. A non-finite force sample
//! is read as 0 N and counted; an output more than 1 beyond the range
//! (|y| > 2 before clamping, or non-finite, which a tanh network cannot
//! produce from finite inputs) is counted as a divergence and replaced by
//! the clamped value (0 for non-finite).
//!
//! Speed: the network runs in the blocked layout of [`super::packed`], with
//! the exact or the fast tanh ([`Tanh`]; exact unless asked). The histories
//! are mirrored rings — each sample is written twice, at p and p + n, with p
//! moving backwards — so the window of the last n samples, newest first, is
//! always the contiguous slice `[p, p + n)`: the network reads the feedback
//! and force taps in place, with no shifting, no copy and no modulo.

use super::mapminmax::MapMinMax;
use super::net::Mlp;
use super::packed::{PackedMlp, Tanh};
use super::taps::Taps;

/// A running closed-loop NARX network.
#[derive(Debug, Clone)]
pub struct ClosedLoop {
    net: PackedMlp,
    taps: Taps,
    xmap: MapMinMax,
    ymap: MapMinMax,
    /// Normalized force history, a mirrored ring of nx = k_x + L + 1 values
    /// (2·nx entries; newest first from `xpos`).
    xh: Vec<f64>,
    /// Normalized estimate history, a mirrored ring of ny = max(k_y, 1) values.
    yh: Vec<f64>,
    nx: usize,
    ny: usize,
    xpos: usize,
    ypos: usize,
    /// Samples between the newest force sample and the newest input tap
    /// (L − d: −d for d < 0, else 0).
    skip: usize,
    x0: f64,
    y0: f64,
    /// Samples whose output was clamped into [−1, 1] (normalized).
    pub clamped: u64,
    /// Samples whose output was non-finite or beyond ±2 (normalized) before clamping.
    pub diverged: u64,
    /// Non-finite force samples read as 0.
    pub bad_inputs: u64,
}

impl ClosedLoop {
    /// A closed loop over a trained network, its taps and the maps of force
    /// (`xmap`) and actuation (`ymap`). The network must have
    /// `taps.n_inputs()` inputs.
    /// Runs the exact tanh ([`ClosedLoop::with_tanh`] chooses).
    pub fn new(net: Mlp, taps: Taps, xmap: MapMinMax, ymap: MapMinMax) -> Self {
        Self::with_tanh(net, taps, xmap, ymap, Tanh::Exact)
    }

    /// Like [`ClosedLoop::new`], with the given tanh in the hidden layers.
    pub fn with_tanh(net: Mlp, taps: Taps, xmap: MapMinMax, ymap: MapMinMax, tanh: Tanh) -> Self {
        debug_assert_eq!(net.inputs(), taps.n_inputs());
        let nx = taps.input + taps.latency() + 1;
        let ny = taps.feedback.max(1);
        let x0 = xmap.apply(0.0);
        let y0 = ymap.apply(0.0).clamp(-1.0, 1.0);
        Self {
            net: PackedMlp::new(&net, tanh),
            taps,
            xmap,
            ymap,
            xh: vec![x0; 2 * nx],
            yh: vec![y0; 2 * ny],
            nx,
            ny,
            xpos: 0,
            ypos: 0,
            skip: (taps.latency() as i64 - taps.lookahead) as usize,
            x0,
            y0,
            clamped: 0,
            diverged: 0,
            bad_inputs: 0,
        }
    }

    /// The taps.
    pub fn taps(&self) -> &Taps {
        &self.taps
    }

    /// The tanh of the hidden layers.
    pub fn tanh(&self) -> Tanh {
        self.net.tanh()
    }

    /// Back to the start: empty histories, counters at zero.
    pub fn reset(&mut self) {
        self.xh.fill(self.x0);
        self.yh.fill(self.y0);
        self.xpos = 0;
        self.ypos = 0;
        self.clamped = 0;
        self.diverged = 0;
        self.bad_inputs = 0;
    }

    /// Takes the force sample x\[t\] (N) and returns the estimate of u[t − L].
    #[inline]
    pub fn step(&mut self, x: f64) -> f64 {
        let y = self.estimate(x);
        self.feed_back(y);
        self.ymap.reverse(y)
    }

    /// Like [`ClosedLoop::step`], but feeds back the known actuation
    /// `u_known` = u[t − L] instead of the estimate (teacher forcing): how a
    /// closed loop is started from known initial states, as MATLAB's
    /// `preparets` does with the first k_y targets. Returns the estimate.
    pub fn step_known(&mut self, x: f64, u_known: f64) -> f64 {
        let y = self.estimate(x);
        let known = self.ymap.apply(if u_known.is_finite() { u_known } else { 0.0 }).clamp(-1.0, 1.0);
        self.feed_back(known);
        self.ymap.reverse(y)
    }

    /// The clamped, normalized network output for the newest force sample.
    #[inline]
    fn estimate(&mut self, x: f64) -> f64 {
        let x = if x.is_finite() {
            x
        } else {
            self.bad_inputs += 1;
            0.0
        };
        let nx = self.nx;
        self.xpos = if self.xpos == 0 { nx - 1 } else { self.xpos - 1 };
        let v = self.xmap.apply(x);
        self.xh[self.xpos] = v;
        self.xh[self.xpos + nx] = v;
        // The newest sample in the window is x[n + d]: for d < 0 it lies
        // −d samples behind the newest one received (x[t], n = t).
        let start = self.xpos + self.skip;
        let xs = &self.xh[start..self.xpos + nx];
        let fb = &self.yh[self.ypos..self.ypos + self.taps.feedback];
        let raw = self.net.forward(fb, xs);
        if raw.is_finite() {
            if raw.abs() > 2.0 {
                self.diverged += 1;
            }
            if raw.abs() > 1.0 {
                self.clamped += 1;
            }
            raw.clamp(-1.0, 1.0)
        } else {
            self.diverged += 1;
            self.y0
        }
    }

    #[inline]
    fn feed_back(&mut self, y: f64) {
        if self.taps.feedback > 0 {
            let ny = self.ny;
            self.ypos = if self.ypos == 0 { ny - 1 } else { self.ypos - 1 };
            self.yh[self.ypos] = y;
            self.yh[self.ypos + ny] = y;
        }
    }

    /// Runs a whole force series and returns the estimates aligned with it:
    /// element n is the estimate of u\[n\] (the last L samples, whose
    /// look-ahead lies past the end of `x`, are estimated with 0 N there).
    pub fn run(&mut self, x: &[f64]) -> Vec<f64> {
        let lat = self.taps.latency();
        let mut out = Vec::with_capacity(x.len());
        for (t, &v) in x.iter().chain(std::iter::repeat_n(&0.0, lat)).enumerate() {
            let u = self.step(v);
            if t >= lat {
                out.push(u);
            }
        }
        out
    }

    /// Runs a whole force series like [`ClosedLoop::run`], with the first
    /// `known` estimates replaced by the true actuation `u` in the feedback
    /// (started from known states, see [`ClosedLoop::step_known`]).
    pub fn run_known(&mut self, x: &[f64], u: &[f64], known: usize) -> Vec<f64> {
        let lat = self.taps.latency();
        let mut out = Vec::with_capacity(x.len());
        for (t, &v) in x.iter().chain(std::iter::repeat_n(&0.0, lat)).enumerate() {
            let e = match t.checked_sub(lat) {
                Some(n) if n < known && n < u.len() => self.step_known(v, u[n]),
                _ => self.step(v),
            };
            if t >= lat {
                out.push(e);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn map(min: f64, max: f64) -> MapMinMax {
        MapMinMax { min, max }
    }

    /// A network that copies one chosen input to its output (a linear
    /// network with a one-hot weight row), to see which sample each tap reads.
    fn picker(taps: Taps, which: usize) -> ClosedLoop {
        let n = taps.n_inputs();
        let mut w = vec![0.0; n + 1];
        w[which] = 1.0;
        let net = Mlp::with_weights(n, &[], w).unwrap();
        ClosedLoop::new(net, taps, map(-1.0, 1.0), map(-1.0, 1.0))
    }

    #[test]
    fn taps_read_the_same_samples_as_the_open_loop_regressor() {
        // x ramps through [−1, 1]; each input tap picked alone must give the
        // sample the open-loop regressor has there.
        let x: Vec<f64> = (0..40).map(|i| -0.95 + 0.045 * i as f64).collect();
        for taps in [
            Taps { feedback: 0, input: 3, lookahead: 2 },
            Taps { feedback: 0, input: 2, lookahead: -1 },
            Taps { feedback: 0, input: 0, lookahead: 0 },
            Taps { feedback: 0, input: 4, lookahead: 5 },
        ] {
            let (m, _) = taps.regressors(&x, &x);
            for j in 0..taps.input_taps() {
                let est = picker(taps, j).run(&x);
                for r in 0..m.nrows() {
                    let n = taps.first() + r;
                    assert!((est[n] - m[(r, j)]).abs() < 1e-12, "{taps:?} tap {j} sample {n}");
                }
            }
        }
    }

    #[test]
    fn feedback_taps_read_past_estimates() {
        // y[n] = 0.5·y[n−2] + x[n]: an impulse must echo every second sample.
        let taps = Taps { feedback: 2, input: 0, lookahead: 0 };
        let net = Mlp::with_weights(3, &[], vec![0.0, 0.5, 1.0, 0.0]).unwrap();
        let mut cl = ClosedLoop::new(net, taps, map(-1.0, 1.0), map(-1.0, 1.0));
        let y = cl.run(&[0.8, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let want = [0.8, 0.0, 0.4, 0.0, 0.2, 0.0];
        for (a, b) in y.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{y:?}");
        }
    }

    #[test]
    fn known_states_are_fed_back_before_the_loop_closes() {
        // y[n] = y[n−1]: the loop holds whatever was fed back last.
        let taps = Taps { feedback: 1, input: 0, lookahead: 0 };
        let net = Mlp::with_weights(2, &[], vec![1.0, 0.0, 0.0]).unwrap();
        let mut cl = ClosedLoop::new(net, taps, map(-1.0, 1.0), map(-1.0, 1.0));
        let u = [0.5, -0.3, 0.7, 0.1, 0.1];
        let est = cl.run_known(&[0.0; 5], &u, 3);
        let want = [0.0, 0.5, -0.3, 0.7, 0.7];
        for (a, b) in est.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{est:?}");
        }
    }

    #[test]
    fn fast_tanh_follows_the_exact_loop_over_a_long_run() {
        // A shipped model, run closed loop on 60 s of lab force (a random
        // binary actuation through the simulated display and sensor) with
        // the exact and the fast tanh. One forward pass differs by at most
        // e ≈ 1e-14 (the propagated tanh error of packed.rs plus rounding);
        // through the feedback tap a difference δ of the last estimate
        // moves the next by L·δ, L = |∂y/∂y[n−1]|, and the clamp to [−1, 1]
        // never widens it. Where L > 1 for a while the difference grows,
        // where L < 1 it decays: measured, the largest difference over the
        // 60 000 samples is 2.5e-11 of a range of 2 (about 2000·e) when this
        // was written. The bound checked, 1e-9 of the range, leaves a factor
        // of 80 for other CPUs (without FMA the sums round differently).
        use crate::narx::labdata::{rbs, Lab};
        use crate::narx::model::Model;
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/data/models");
        let model = Model::load(&dir.join("narx-85g-5cms.json")).unwrap();
        let x = Lab::default().force(&rbs(60_000, 5));
        let exact = model.closed_loop_with(Tanh::Exact).unwrap().run(&x);
        let mut fast_loop = model.closed_loop_with(Tanh::Fast).unwrap();
        assert_eq!(fast_loop.tanh(), Tanh::Fast);
        let fast = fast_loop.run(&x);
        let range = model.normalization.y.max - model.normalization.y.min;
        let worst = exact.iter().zip(&fast).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("largest |fast − exact| over {} samples: {worst:e} (range {range})", x.len());
        assert!(worst <= 1e-9 * range, "{worst:e}");
        // Not trivially equal: the two loops do run different tanh.
        assert!(exact.iter().zip(&fast).any(|(a, b)| a != b));
    }

    #[test]
    fn outputs_stay_in_the_training_range_and_bad_input_is_counted() {
        // An unstable loop: y[n] = 3·y[n−1] + x[n] would grow without bound.
        let taps = Taps { feedback: 1, input: 0, lookahead: 0 };
        let net = Mlp::with_weights(2, &[], vec![3.0, 1.0, 0.0]).unwrap();
        let mut cl = ClosedLoop::new(net, taps, map(-2.0, 2.0), map(-0.5, 1.5));
        let mut r = Rng::new(1);
        for i in 0..1000 {
            let x = if i == 500 { f64::NAN } else { 10.0 * r.gaussian() };
            let u = cl.step(x);
            assert!((-0.5..=1.5).contains(&u), "{u}");
        }
        assert_eq!(cl.bad_inputs, 1);
        assert!(cl.clamped > 0 && cl.diverged > 0);
        cl.reset();
        assert_eq!((cl.clamped, cl.diverged, cl.bad_inputs), (0, 0, 0));
    }
}
