//! A second-order Butterworth high-pass whose cut-off may change at every
//! sample: the trapezoidal (zero-delay-feedback) state-variable filter.
//!
//! The state-variable form integrates with the trapezoidal rule, so at a
//! fixed cut-off its response is the bilinear transform of the analog
//! Butterworth prototype with the cut-off pre-warped — the same filter as
//! `filters::butterworth` designs (held to it in the tests below, sample for
//! sample). Unlike a direct-form biquad, its two states are the analog
//! integrators' own, so moving the cut-off from one sample to the next
//! changes no stored energy and stays stable under any modulation (the
//! topology and update are A. Simper's, "Linear trapezoidal integrated SVF",
//! Cytomic technical paper, 2013).
//!
//! Per sample: one `tan` when the cut-off moved, ten multiply-adds, nothing
//! allocated.

use std::f64::consts::{PI, SQRT_2};

/// The filter's state and its current coefficients.
#[derive(Debug, Clone)]
pub struct TrackingHighpass {
    rate: f64,
    /// Lowest and highest cut-off it may take (Hz).
    lo: f64,
    hi: f64,
    /// The cut-off of the coefficients below (NaN before the first).
    cutoff: f64,
    a1: f64,
    a2: f64,
    a3: f64,
    ic1: f64,
    ic2: f64,
}

/// 1/Q of a Butterworth second-order section.
const K: f64 = SQRT_2;

impl TrackingHighpass {
    /// A filter at `rate` samples a second whose cut-off is kept within
    /// [`lo`, `hi`] Hz (`hi` is held below 0.45 · rate).
    pub fn new(rate: f64, lo: f64, hi: f64) -> Self {
        let hi = hi.min(0.45 * rate).max(f64::MIN_POSITIVE);
        let lo = lo.clamp(f64::MIN_POSITIVE, hi);
        Self { rate, lo, hi, cutoff: f64::NAN, a1: 1.0, a2: 0.0, a3: 0.0, ic1: 0.0, ic2: 0.0 }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.ic1 = 0.0;
        self.ic2 = 0.0;
    }

    /// The cut-off in force (Hz), after clamping.
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// Moves the cut-off to `fc` Hz (clamped; a non-finite value keeps the
    /// last one, or the lowest before any).
    pub fn set_cutoff(&mut self, fc: f64) {
        let fc = if fc.is_finite() {
            fc.clamp(self.lo, self.hi)
        } else if self.cutoff.is_nan() {
            self.lo
        } else {
            return;
        };
        if fc == self.cutoff {
            return;
        }
        self.cutoff = fc;
        let g = (PI * fc / self.rate).tan();
        self.a1 = 1.0 / (1.0 + g * (g + K));
        self.a2 = g * self.a1;
        self.a3 = g * self.a2;
    }

    /// Filters one sample at the current cut-off.
    pub fn tick(&mut self, x: f64) -> f64 {
        let v3 = x - self.ic2;
        let v1 = self.a1 * self.ic1 + self.a2 * v3;
        let v2 = self.ic2 + self.a2 * self.ic1 + self.a3 * v3;
        self.ic1 = 2.0 * v1 - self.ic1;
        self.ic2 = 2.0 * v2 - self.ic2;
        x - K * v1 - v2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filters::butterworth::design::{butterworth, Kind};
    use crate::filters::butterworth::sos::Cascade;

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            })
            .collect()
    }

    #[test]
    fn at_a_fixed_cutoff_it_is_the_bilinear_butterworth() {
        for fc in [1.0, 8.0, 20.0, 150.0] {
            let sections = butterworth(Kind::Highpass, 2, fc, 1000.0).unwrap();
            let mut reference = Cascade::new(&sections);
            let mut svf = TrackingHighpass::new(1000.0, 0.5, 400.0);
            svf.set_cutoff(fc);
            let mut worst: f64 = 0.0;
            for x in noise(5000, 7) {
                worst = worst.max((svf.tick(x) - reference.tick(x)).abs());
            }
            assert!(worst < 1e-12, "fc {fc} Hz: largest difference {worst:e}");
        }
    }

    #[test]
    fn removes_a_constant_and_passes_a_tone_above_the_cutoff() {
        let mut f = TrackingHighpass::new(1000.0, 1.0, 400.0);
        f.set_cutoff(10.0);
        let mut last = 0.0;
        for _ in 0..5000 {
            last = f.tick(0.3);
        }
        assert!(last.abs() < 1e-9, "DC left: {last}");
        // 100 Hz, a decade above: the bilinear Butterworth's gain,
        // 1/√(1 + (tan(π·fc/fs)/tan(π·f/fs))⁴), read as an RMS ratio over
        // whole periods once the start has died away.
        f.reset();
        let (mut sum_in, mut sum_out) = (0.0, 0.0);
        for n in 0..4000 {
            let x = (2.0 * PI * 100.0 * n as f64 / 1000.0).sin();
            let y = f.tick(x);
            if n >= 2000 {
                sum_in += x * x;
                sum_out += y * y;
            }
        }
        let want = 1.0 / (1.0 + ((PI * 10.0 / 1000.0).tan() / (PI * 100.0 / 1000.0).tan()).powi(4)).sqrt();
        let got = (sum_out / sum_in).sqrt();
        assert!((got - want).abs() < 1e-6, "100 Hz gain {got}, the analytic {want}");
    }

    #[test]
    fn stays_bounded_when_the_cutoff_jumps_every_sample() {
        let mut f = TrackingHighpass::new(1000.0, 0.5, 400.0);
        let cut = noise(200_000, 3);
        let mut largest: f64 = 0.0;
        for (n, x) in noise(200_000, 11).into_iter().enumerate() {
            // Cut-offs from 0.5 Hz to 400 Hz, a new one every sample.
            f.set_cutoff(0.5 * 800f64.powf(0.5 * (cut[n] + 1.0)));
            largest = largest.max(f.tick(x).abs());
        }
        assert!(largest.is_finite() && largest < 10.0, "largest output {largest}");
    }

    #[test]
    fn cutoffs_are_clamped_and_a_non_finite_one_is_ignored() {
        let mut f = TrackingHighpass::new(1000.0, 2.0, 900.0);
        f.set_cutoff(f64::NAN);
        assert_eq!(f.cutoff(), 2.0);
        f.set_cutoff(0.0);
        assert_eq!(f.cutoff(), 2.0);
        f.set_cutoff(1e9);
        assert_eq!(f.cutoff(), 450.0);
        f.set_cutoff(f64::INFINITY);
        assert_eq!(f.cutoff(), 450.0);
    }
}
