//! The regressor of the NARX network: which past outputs and which force
//! samples the network sees for each output sample, and the alignment
//! (look-ahead) between force and actuation.
//!
//! For the output sample n the regressor is
//!
//! ```text
//! [ y[n−1], …, y[n−k_y],  x[n+d], x[n+d−1], …, x[n−k_x] ]
//! ```
//!
//! — `k_y` feedback taps (Eq. 5.1's y[n−1] … y[n−k_y]) and the external
//! input from d samples ahead back to k_x samples behind (k_x + d + 1
//! values). d = −1 gives Eq. 5.1 exactly (x[n−1] … x[n−k_x]). A look-ahead
//! d > 0 is what an *inverse* model needs: the force that u\[n\] causes
//! appears after it (the display's electrical, electroadhesive and
//! mechanical lags), so u\[n\] is best read from force samples up to n + d.
//! Offline this is free; streaming, it delays the estimate by d samples
//! (see the `narx` node).
//!
//! # Choosing d by cross-correlation
//!
//! The display's force is (almost) even in u — the square law F ∝ v_g² —
//! so the plain cross-correlation of u and the force is close to zero and
//! says nothing about timing. What the force does show is *change* in u: a
//! transition of a binary excitation charges the gap and makes a force
//! spike (docs/simulated-lab.md §1.4). [`choose_lookahead`] therefore
//! correlates the squared increment z\[n\] = (u\[n\] − u[n−1])² (centred) with
//! the force x[n + k] for k = 0 … `max_lag`, takes the lag k* of the largest
//! |correlation| and extends it while |correlation| stays above a quarter of
//! that peak: d is the last lag of the response's main part, so the window
//! x[n+d] … x[n−k_x] covers the force response to u\[n\]. (|·| because the
//! response rings: on the nominal simulated lab the correlation alternates
//! in sign, +0.33, −0.38, +0.14, −0.13, +0.06 at lags 0 … 4 — the pen tip's
//! 712 Hz resonance seen at 1 kHz — and d = 3. Networks trained with d = 1,
//! 2, 3 and 5 there reached closed-loop transition agreements of 0.84,
//! 0.80, 0.89 and 0.82 on a held-out random binary sequence, one training
//! seed each — a one-off exploration, `nodes/src/narx/explore.rs` at
//! commit 04f6204.)

use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};

/// Tap counts and alignment of a NARX network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Taps {
    /// Feedback taps k_y: y[n−1] … y[n−k_y] (0 = no feedback: a pure
    /// nonlinear FIR inverse).
    pub feedback: usize,
    /// Input taps k_x behind the output sample: x\[n\] … x[n−k_x].
    pub input: usize,
    /// Look-ahead d: the newest input sample is x[n+d] (−k_x ≤ d).
    pub lookahead: i64,
}

impl Taps {
    /// Checks that the window holds at least one input sample.
    pub fn validate(&self) -> Result<(), String> {
        if self.lookahead < -(self.input as i64) {
            return Err(format!(
                "the look-ahead {} leaves no input tap (the input window x[n+d] … x[n−{}] is empty)",
                self.lookahead, self.input
            ));
        }
        Ok(())
    }

    /// Input samples in the regressor: k_x + d + 1.
    pub fn input_taps(&self) -> usize {
        (self.input as i64 + self.lookahead + 1).max(0) as usize
    }

    /// Network inputs: k_y + k_x + d + 1.
    pub fn n_inputs(&self) -> usize {
        self.feedback + self.input_taps()
    }

    /// How many samples a streaming estimate lags its input: max(d, 0).
    pub fn latency(&self) -> usize {
        self.lookahead.max(0) as usize
    }

    /// The first output sample whose whole regressor lies in the data.
    pub fn first(&self) -> usize {
        self.feedback.max(self.input)
    }

    /// Output samples n (from [`Taps::first`]) with a complete regressor in
    /// data of `len` samples.
    pub fn usable(&self, len: usize) -> usize {
        len.saturating_sub(self.first() + self.latency())
    }

    /// Writes the regressor of sample n into `row`: feedback values from
    /// `y_past(k)` = y[n−k] (k = 1 … k_y), inputs from `x_at(j)` =
    /// x[n+d−j] (j = 0 … k_x + d).
    #[inline]
    pub fn fill(&self, row: &mut [f64], y_past: impl Fn(usize) -> f64, x_at: impl Fn(usize) -> f64) {
        let (fb, inp) = row.split_at_mut(self.feedback);
        for (k, v) in fb.iter_mut().enumerate() {
            *v = y_past(k + 1);
        }
        for (j, v) in inp.iter_mut().enumerate() {
            *v = x_at(j);
        }
    }

    /// Open-loop (series-parallel) regressors and targets from an input
    /// series `x` and the true output series `y` (same length): one row per
    /// usable sample n = first … , feedback taps from the *true* y
    /// (dissertation Fig. 5.3(a)).
    pub fn regressors(&self, x: &[f64], y: &[f64]) -> (Array2<f64>, Array1<f64>) {
        let len = x.len().min(y.len());
        let rows = self.usable(len);
        let first = self.first();
        let d = self.lookahead;
        let mut m = Array2::zeros((rows, self.n_inputs()));
        let mut t = Array1::zeros(rows);
        for (r, mut row) in m.rows_mut().into_iter().enumerate() {
            let n = first + r;
            let newest = (n as i64 + d) as usize;
            let row = row.as_slice_mut().expect("a fresh array is contiguous");
            self.fill(row, |k| y[n - k], |j| x[newest - j]);
            t[r] = y[n];
        }
        (m, t)
    }
}

/// The alignment found by [`choose_lookahead`].
#[derive(Debug, Clone, PartialEq)]
pub struct Alignment {
    /// The chosen look-ahead d.
    pub lookahead: usize,
    /// Lag of the largest |correlation|.
    pub peak: usize,
    /// Normalized correlation of the squared increment of u with x[n + k], k = 0 … max_lag.
    pub correlation: Vec<f64>,
}

/// Chooses the look-ahead d from the data (see the module documentation).
/// `None` when u never changes or x is constant (nothing to correlate).
pub fn choose_lookahead(u: &[f64], x: &[f64], max_lag: usize) -> Option<Alignment> {
    let len = u.len().min(x.len());
    if len < max_lag + 3 {
        return None;
    }
    let z: Vec<f64> = (1..len).map(|n| (u[n] - u[n - 1]).powi(2)).collect();
    let zm = z.iter().sum::<f64>() / z.len() as f64;
    let xm = x[..len].iter().sum::<f64>() / len as f64;
    let zs = z.iter().map(|v| (v - zm).powi(2)).sum::<f64>().sqrt();
    let xs = x[..len].iter().map(|v| (v - xm).powi(2)).sum::<f64>().sqrt();
    if !(zs > 0.0 && xs > 0.0 && zs.is_finite() && xs.is_finite()) {
        return None;
    }
    // z[i] belongs to sample n = i + 1.
    let correlation: Vec<f64> = (0..=max_lag)
        .map(|k| {
            let s: f64 = (0..z.len() - k).map(|i| (z[i] - zm) * (x[i + 1 + k] - xm)).sum();
            s / (zs * xs)
        })
        .collect();
    let peak = (0..=max_lag).max_by(|&a, &b| correlation[a].abs().total_cmp(&correlation[b].abs()))?;
    let floor = 0.25 * correlation[peak].abs();
    let mut d = peak;
    while d < max_lag && correlation[d + 1].abs() > floor {
        d += 1;
    }
    Some(Alignment { lookahead: d, peak, correlation })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regressor_rows_hold_the_right_samples() {
        let x: Vec<f64> = (0..20).map(|i| 100.0 + i as f64).collect();
        let y: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let taps = Taps { feedback: 2, input: 3, lookahead: 2 };
        assert_eq!(taps.n_inputs(), 2 + 6);
        let (m, t) = taps.regressors(&x, &y);
        // First sample n = 3, last n = 17 (x[19] is its newest input).
        assert_eq!(m.nrows(), 15);
        assert_eq!(t[0], 3.0);
        assert_eq!(m.row(0).to_vec(), vec![2.0, 1.0, 105.0, 104.0, 103.0, 102.0, 101.0, 100.0]);
        assert_eq!(t[14], 17.0);
        assert_eq!(m.row(14)[2], 119.0);
        // Eq. 5.1: d = −1 gives x[n−1] … x[n−k_x].
        let eq51 = Taps { feedback: 2, input: 2, lookahead: -1 };
        let (m, t) = eq51.regressors(&x, &y);
        assert_eq!(t[0], 2.0);
        assert_eq!(m.row(0).to_vec(), vec![1.0, 0.0, 101.0, 100.0]);
        assert_eq!(m.nrows(), 18);
        // No feedback at all.
        let fir = Taps { feedback: 0, input: 0, lookahead: 0 };
        let (m, t) = fir.regressors(&x, &y);
        assert_eq!((m.ncols(), m.nrows(), t[0], m[(0, 0)]), (1, 20, 0.0, 100.0));
        assert!(Taps { feedback: 0, input: 1, lookahead: -2 }.validate().is_err());
        assert!(Taps { feedback: 0, input: 1, lookahead: -1 }.validate().is_ok());
    }

    #[test]
    fn the_lookahead_finds_a_known_response_delay() {
        // A plant whose force responds to transitions 3 samples later, with
        // a response lasting 2 samples: x[n] = z[n−3] + 0.8·z[n−4].
        let mut s: u32 = 0x1ff;
        let u: Vec<f64> = (0..3000)
            .map(|_| {
                let bit = ((s >> 8) ^ (s >> 4)) & 1;
                s = ((s << 1) | bit) & 0x1ff;
                if bit == 1 {
                    1.0
                } else {
                    -1.0
                }
            })
            .collect();
        let z = |n: usize| if n == 0 { 0.0 } else { (u[n] - u[n - 1]).powi(2) };
        let x: Vec<f64> = (0..u.len()).map(|n| if n < 4 { 0.0 } else { z(n - 3) + 0.8 * z(n - 4) }).collect();
        let a = choose_lookahead(&u, &x, 10).unwrap();
        assert_eq!(a.peak, 3);
        assert_eq!(a.lookahead, 4);
        assert!(choose_lookahead(&vec![1.0; 100], &x[..100], 10).is_none());
        assert!(choose_lookahead(&u[..100], &[0.5; 100], 10).is_none());
    }
}
