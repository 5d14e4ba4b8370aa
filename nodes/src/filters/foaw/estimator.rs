//! The first-order adaptive windowing (FOAW) velocity estimator of
//! Janabi-Sharifi, Hayward & Chen, "Discrete-time adaptive windowing for
//! velocity estimation", IEEE Trans. Control Systems Technology 8(6),
//! 1003–1009, 2000.
//!
//! At sample k the window grows, n = 1, 2, …, N, while a straight line
//! through the newest position y_k with slope b_n passes within the noise
//! bound d of every position inside the window,
//! |y_{k−j} − (y_k − b_n·j·T)| ≤ d for j = 1 … n−1; the estimate is the
//! slope of the largest window that passed (n = 1, the finite difference,
//! always passes). The slope is
//!
//! * **end-fit**: b_n = (y_k − y_{k−n}) / (n·T), the line through the
//!   window's two ends;
//! * **best-fit**: b_n = (n·Σᵢ y_{k−i} − 2·Σᵢ i·y_{k−i}) / (T·n(n+1)(n+2)/6),
//!   i = 0 … n, the least-squares slope over the window's n + 1 samples
//!   (the paper's Eq. for the best-fit variant; for n = 1 it is the finite
//!   difference).
//!
//! Slow, steady motion gets a long window (little noise); a change of
//! velocity breaks the fit and shrinks the window (little lag).

/// Which slope a window gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fit {
    /// Through the window's two ends.
    End,
    /// Least squares over the window.
    Best,
}

/// A FOAW estimator with its window of past positions. Allocates only in
/// [`Foaw::new`].
#[derive(Debug, Clone)]
pub struct Foaw {
    fit: Fit,
    /// Noise bound d, position units.
    noise: f64,
    /// Sample period T, s.
    period: f64,
    /// The last N + 1 positions, newest first (`win[j]` = y_{k−j}): each
    /// push shifts them by one, so the window's tests read a slice.
    win: Vec<f64>,
    len: usize,
    velocity: f64,
}

impl Foaw {
    /// An estimator with noise bound `noise` (position units), sample
    /// period `period` (s) and windows of at most `max_window` ≥ 1 samples.
    pub fn new(fit: Fit, noise: f64, period: f64, max_window: usize) -> Self {
        let cap = max_window.max(1) + 1;
        Foaw { fit, noise, period, win: vec![0.0; cap], len: 0, velocity: 0.0 }
    }

    /// Forgets every position (velocity 0).
    pub fn reset(&mut self) {
        self.len = 0;
        self.velocity = 0.0;
    }

    /// Takes the next position and returns the velocity estimate (position
    /// units per second). A non-finite position is skipped and the last
    /// estimate held.
    pub fn push(&mut self, y: f64) -> f64 {
        if !y.is_finite() {
            return self.velocity;
        }
        let cap = self.win.len();
        self.win.copy_within(..cap - 1, 1);
        self.win[0] = y;
        self.len = (self.len + 1).min(cap);
        if self.len < 2 {
            self.velocity = 0.0;
            return 0.0;
        }
        let w = &self.win[..self.len];
        let t = self.period;
        let mut accepted = (y - w[1]) / t;
        // Running sums over i = 0 … n for the best fit, of positions
        // relative to y_k (the slope is shift-invariant; this way a resting
        // finger gives exactly 0 and large coordinates lose no precision).
        let (mut s0, mut s1) = (w[1] - y, w[1] - y);
        for n in 2..w.len() {
            let yn = w[n];
            s0 += yn - y;
            s1 += n as f64 * (yn - y);
            let nf = n as f64;
            let b = match self.fit {
                Fit::End => (y - yn) / (nf * t),
                Fit::Best => (nf * s0 - 2.0 * s1) / (t * nf * (nf + 1.0) * (nf + 2.0) / 6.0),
            };
            if !line_fits(&w[1..n], y, b, t, self.noise) {
                break;
            }
            accepted = b;
        }
        self.velocity = if accepted.is_finite() { accepted } else { 0.0 };
        self.velocity
    }
}

/// Whether every position `rest[j − 1]` = y_{k−j} (j = 1 … n−1) lies
/// within `noise` of the line through y_k with slope b:
/// |y_{k−j} − (y_k − b·j·T)| ≤ d. Eight positions are tested at a time, all
/// of them before the verdict (a comparison has no side effect, so the
/// answer is the one position by position would give; the compiler turns
/// the eight into vector instructions).
#[inline]
fn line_fits(rest: &[f64], y: f64, b: f64, t: f64, noise: f64) -> bool {
    const LANES: usize = 8;
    let test = |j: f64, wj: f64| (wj - (y - b * j * t)).abs() <= noise;
    let mut chunks = rest.chunks_exact(LANES);
    // j as f64, counted in f64 (exact: j < 2⁵³).
    let mut j0 = 1.0;
    for c in &mut chunks {
        let mut all = true;
        for (l, &wj) in c.iter().enumerate() {
            all &= test(j0 + l as f64, wj);
        }
        if !all {
            return false;
        }
        j0 += LANES as f64;
    }
    chunks.remainder().iter().enumerate().all(|(l, &wj)| test(j0 + l as f64, wj))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_on_a_noiseless_ramp_and_zero_at_rest() {
        for fit in [Fit::End, Fit::Best] {
            let mut f = Foaw::new(fit, 1e-9, 0.025, 16);
            let mut v = 0.0;
            for k in 0..40 {
                v = f.push(0.1 + 0.05 * 0.025 * k as f64);
            }
            assert!((v - 0.05).abs() < 1e-9, "{fit:?}: {v}");
            let mut rest = Foaw::new(fit, 1e-4, 0.025, 16);
            for _ in 0..40 {
                assert_eq!(rest.push(0.3), 0.0);
            }
        }
    }

    /// The estimate as first written, reading the ring through a modular
    /// index per position: the shifted window must give its bits.
    fn by_modular_index(fit: Fit, noise: f64, t: f64, max_window: usize, ys: &[f64]) -> Vec<f64> {
        let cap = max_window + 1;
        let (mut ring, mut head, mut len, mut out) = (vec![0.0; cap], 0usize, 0usize, Vec::new());
        for &y in ys {
            head = (head + 1) % cap;
            ring[head] = y;
            len = (len + 1).min(cap);
            if len < 2 {
                out.push(0.0);
                continue;
            }
            let back = |j: usize| ring[(head + cap - j) % cap];
            let mut accepted = (y - back(1)) / t;
            let (mut s0, mut s1) = (back(1) - y, back(1) - y);
            for n in 2..len {
                let yn = back(n);
                s0 += yn - y;
                s1 += n as f64 * (yn - y);
                let nf = n as f64;
                let b = match fit {
                    Fit::End => (y - yn) / (nf * t),
                    Fit::Best => (nf * s0 - 2.0 * s1) / (t * nf * (nf + 1.0) * (nf + 2.0) / 6.0),
                };
                if !(1..n).all(|j| (back(j) - (y - b * j as f64 * t)).abs() <= noise) {
                    break;
                }
                accepted = b;
            }
            out.push(if accepted.is_finite() { accepted } else { 0.0 });
        }
        out
    }

    #[test]
    fn the_shifted_window_gives_the_modular_rings_bits() {
        let mut r = crate::rng::Rng::new(17);
        // A stroke with noise: steady stretches (long windows) and turns.
        let ys: Vec<f64> = (0..3000).map(|k| 0.05 * (k as f64 * 0.004).sin() + 2e-5 * r.gaussian() + 0.3).collect();
        for fit in [Fit::End, Fit::Best] {
            for max_window in [1, 2, 7, 16, 40] {
                let mut f = Foaw::new(fit, 5e-5, 1e-3, max_window);
                let got: Vec<u64> = ys.iter().map(|&y| f.push(y).to_bits()).collect();
                let want: Vec<u64> =
                    by_modular_index(fit, 5e-5, 1e-3, max_window, &ys).iter().map(|v| v.to_bits()).collect();
                assert_eq!(got, want, "{fit:?}, window {max_window}");
            }
        }
    }

    #[test]
    fn best_fit_slope_is_least_squares() {
        // Against a direct least-squares fit over the whole window when
        // every point fits (noise bound large).
        let ys = [0.0, 0.9, 2.2, 2.8, 4.1, 5.0];
        let mut f = Foaw::new(Fit::Best, 10.0, 1.0, 5);
        let mut v = 0.0;
        for &y in &ys {
            v = f.push(y);
        }
        let n = ys.len() as f64;
        let mt = (n - 1.0) / 2.0;
        let my = ys.iter().sum::<f64>() / n;
        let sxy: f64 = ys.iter().enumerate().map(|(i, y)| (i as f64 - mt) * (y - my)).sum();
        let sxx: f64 = (0..ys.len()).map(|i| (i as f64 - mt).powi(2)).sum();
        assert!((v - sxy / sxx).abs() < 1e-12, "{v} vs {}", sxy / sxx);
    }

    #[test]
    fn a_velocity_step_shrinks_the_window() {
        // 1 unit/s, then −1 unit/s: within two samples of the reversal the
        // window holds only post-reversal samples and the estimate is exact.
        let mut f = Foaw::new(Fit::End, 1e-6, 1.0, 16);
        let mut y = 0.0;
        for _ in 0..20 {
            f.push(y);
            y += 1.0;
        }
        y -= 2.0;
        f.push(y);
        y -= 1.0;
        assert_eq!(f.push(y), -1.0);
    }

    #[test]
    fn non_finite_positions_hold_the_estimate() {
        let mut f = Foaw::new(Fit::Best, 1e-3, 0.025, 8);
        for k in 0..10 {
            f.push(0.01 * k as f64);
        }
        let v = f.push(0.1);
        assert_eq!(f.push(f64::NAN), v);
        assert_eq!(f.push(f64::INFINITY), v);
        assert!(f.push(0.11).is_finite());
    }
}
