//! The anti-aliased decimator behind `decimate`: its filter design and the
//! streaming filter-and-keep-every-M-th-sample loop.
//!
//! **Design.** A linear-phase FIR low-pass by the Kaiser window method
//! ([`super::kaiser`]) at the input rate, with its passband up to
//! `passband` × the new Nyquist frequency f_N = f_in / (2M) and its
//! stopband from f_N itself, `attenuation` dB down: whatever would fold
//! back onto the output's band is attenuated by at least that much, and
//! the band below `passband`·f_N comes through with the ripple the Kaiser
//! design gives for that attenuation (δ = 10^(−A/20) in both bands). The
//! order is Kaiser's estimate rounded up to a multiple of 2M, so the group
//! delay N/2 input samples is a whole number N/(2M) of output samples
//! (another path can be delayed to match it exactly with a `delay` node);
//! the measured response is checked on a grid 32× finer than the filter
//! and the order raised by 2M until both figures hold there.
//!
//! **Streaming.** The last N + 1 inputs live in a mirrored history (each
//! sample written twice, N + 1 apart) so that the window is one contiguous
//! slice; output l is the filter at input Ml, computed when that input
//! arrives (the output sample and input Ml fall at the same time, so the
//! engine delivers them in the same call whatever the block size). Only
//! every M-th filter output is computed (a polyphase decimator's cost,
//! N + 1 multiply-adds per output). Inputs are scaled by 2⁻¹⁰ on entry
//! and outputs by 2¹⁰ on exit — exact for every normal number — so no
//! sum of finite inputs overflows; an output beyond the f64 range is
//! clamped to ±f64::MAX.

use super::kaiser::{self, Response};
use std::f64::consts::PI;

/// Largest filter the designer builds (taps): beyond it a two-stage
/// decimation is cheaper and the design check slow.
pub const MAX_TAPS: usize = 1 << 16;

/// The design aims this many dB beyond the attenuation asked for.
pub const MARGIN_DB: f64 = 1.0;

/// Inputs are multiplied by this on entry (and outputs divided by it).
const SCALE: f64 = 1.0 / 1024.0;

/// Why a decimator could not be designed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecimateError {
    /// The factor is zero.
    #[error("the decimation factor must be at least 1, not {0}")]
    Factor(usize),
    /// `passband` outside (0, 1).
    #[error("passband {0} must lie strictly between 0 and 1 (a fraction of the new Nyquist frequency)")]
    Passband(f64),
    /// `attenuation` outside the range the Kaiser formulas cover.
    #[error("attenuation {0} dB must lie between 20 and 200 dB")]
    Attenuation(f64),
    /// The filter would be longer than [`MAX_TAPS`].
    #[error(
        "factor {factor} with passband {passband} and {attenuation} dB needs a filter of about {taps} taps, \
         more than {MAX_TAPS}; decimate in two stages (two `decimate` nodes whose factors multiply to {factor}), \
         or lower `passband` or `attenuation`"
    )]
    TooLong {
        /// The factor asked for.
        factor: usize,
        /// The passband asked for.
        passband: f64,
        /// The attenuation asked for, dB.
        attenuation: f64,
        /// Taps the design would need.
        taps: usize,
    },
}

/// A designed anti-aliasing filter for decimation by `factor`.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// The decimation factor M.
    pub factor: usize,
    /// The taps (odd length N + 1, symmetric, summing to 1).
    pub taps: Vec<f64>,
    /// The response measured over the passband `[0, passband·f_N]` and the
    /// stopband `[f_N, f_in/2]`.
    pub response: Response,
}

impl Design {
    /// Group delay in input samples (N/2, the same at every frequency).
    pub fn delay_in(&self) -> usize {
        (self.taps.len() - 1) / 2
    }
    /// Group delay in output samples (N/(2M), a whole number).
    pub fn delay_out(&self) -> usize {
        self.delay_in() / self.factor
    }
}

/// Designs the filter for decimation by `factor` with the passband edge at
/// `passband` × the new Nyquist frequency and `attenuation` dB from the new
/// Nyquist frequency up. Factor 1 is the identity (one tap, no delay).
pub fn design(factor: usize, passband: f64, attenuation: f64) -> Result<Design, DecimateError> {
    if factor == 0 {
        return Err(DecimateError::Factor(factor));
    }
    if !(passband > 0.0 && passband < 1.0) {
        return Err(DecimateError::Passband(passband));
    }
    if !(20.0..=200.0).contains(&attenuation) {
        return Err(DecimateError::Attenuation(attenuation));
    }
    if factor == 1 {
        return Ok(Design { factor, taps: vec![1.0], response: Response { pass_deviation: 0.0, stop_gain: 0.0 } });
    }
    let stop = 0.5 / factor as f64;
    let pass = passband * stop;
    let delta = 10f64.powf(-attenuation / 20.0);
    let step = 2 * factor;
    // Designed for 1 dB more than asked: the Kaiser window's ripple is set
    // by β alone and scatters by ±10 % around δ from one length to the next.
    let target = attenuation + MARGIN_DB;
    let estimate = kaiser::order_estimate(target, 2.0 * PI * (stop - pass));
    let mut order = estimate.div_ceil(step) * step;
    let too_long = |order: usize| DecimateError::TooLong { factor, passband, attenuation, taps: order + 1 };
    if order >= MAX_TAPS {
        return Err(too_long(order));
    }
    let beta = kaiser::beta(target);
    loop {
        let taps = kaiser::lowpass(order, 0.5 * (pass + stop), beta);
        let response = kaiser::measure(&taps, pass, stop);
        if response.stop_gain <= delta && response.pass_deviation <= delta {
            return Ok(Design { factor, taps, response });
        }
        order += step;
        if order >= MAX_TAPS {
            return Err(too_long(order));
        }
    }
}

/// The streaming decimator: push input samples, get every M-th filtered one.
#[derive(Debug, Clone)]
pub struct Decimator {
    taps: Vec<f64>,
    history: Vec<f64>,
    pos: usize,
    phase: usize,
    factor: usize,
}

impl Decimator {
    /// A decimator running `design`, at t = 0 (zeros before the first input).
    pub fn new(design: &Design) -> Self {
        let n = design.taps.len();
        Self { taps: design.taps.clone(), history: vec![0.0; 2 * n], pos: 0, phase: 0, factor: design.factor }
    }

    /// Takes input sample n (the next one); returns output sample n/M when
    /// n is a multiple of M.
    #[inline]
    pub fn push(&mut self, x: f64) -> Option<f64> {
        let n = self.taps.len();
        let v = x * SCALE;
        self.history[self.pos] = v;
        self.history[self.pos + n] = v;
        self.pos = if self.pos + 1 == n { 0 } else { self.pos + 1 };
        let due = self.phase == 0;
        self.phase = if self.phase + 1 == self.factor { 0 } else { self.phase + 1 };
        if !due {
            return None;
        }
        // Oldest to newest: history[pos .. pos + n]; the taps are symmetric,
        // so the convolution is their dot product with that window.
        let y = dot(&self.taps, &self.history[self.pos..self.pos + n]) / SCALE;
        Some(if y.is_finite() { y } else { y.clamp(-f64::MAX, f64::MAX) })
    }

    /// Back to t = 0.
    pub fn reset(&mut self) {
        self.history.fill(0.0);
        self.pos = 0;
        self.phase = 0;
    }
}

/// Σ a[i]·b[i] over four interleaved partial sums (the same order of
/// operations every call, so the result does not depend on the block size).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0f64; 4];
    let (ca, ra) = a.as_chunks::<4>();
    let (cb, rb) = b.as_chunks::<4>();
    for (x, y) in ca.iter().zip(cb) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rate::testing::noise;

    /// The textbook definition: y[l] = Σ_k h[k]·x[Ml − k], x[n < 0] = 0.
    fn reference(h: &[f64], x: &[f64], m: usize) -> Vec<f64> {
        (0..x.len().div_ceil(m))
            .map(|l| {
                let n = l * m;
                (0..h.len()).filter(|&k| k <= n).map(|k| h[k] * x[n - k]).sum()
            })
            .collect()
    }

    #[test]
    fn streaming_equals_the_convolution_definition() {
        for m in [1, 2, 3, 10, 25] {
            let d = design(m, 0.8, 80.0).unwrap();
            let x = noise(3000, m as u64);
            let mut dec = Decimator::new(&d);
            let got: Vec<f64> = x.iter().filter_map(|&v| dec.push(v)).collect();
            let want = reference(&d.taps, &x, m);
            assert_eq!(got.len(), want.len());
            for (l, (a, b)) in got.iter().zip(&want).enumerate() {
                assert!((a - b).abs() < 1e-14, "M={m} l={l}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn designs_meet_their_figures_with_a_whole_output_delay() {
        for (m, pass, a) in [(2, 0.8, 100.0), (10, 0.8, 100.0), (10, 0.5, 60.0), (25, 0.9, 120.0), (4, 0.8, 20.0)] {
            let d = design(m, pass, a).unwrap();
            assert!(d.taps.len() % 2 == 1 && (d.taps.len() - 1).is_multiple_of(2 * m), "M={m}: {} taps", d.taps.len());
            assert_eq!(d.delay_out() * m, d.delay_in());
            assert!(d.response.attenuation_db() >= a, "M={m}: {:?}", d.response);
            assert!(d.response.pass_deviation <= 10f64.powf(-a / 20.0), "M={m}: {:?}", d.response);
            // No longer than Kaiser's estimate (with the margin, rounded up to 2M) and two more steps.
            let est = kaiser::order_estimate(a + MARGIN_DB, 2.0 * PI * (1.0 - pass) * 0.5 / m as f64);
            assert!(d.taps.len() - 1 <= est.div_ceil(2 * m) * 2 * m + 4 * m, "M={m}: {} vs {est}", d.taps.len());
        }
        assert_eq!(design(1, 0.8, 100.0).unwrap().taps, vec![1.0]);
    }

    #[test]
    fn bad_designs_are_errors() {
        assert_eq!(design(0, 0.8, 100.0), Err(DecimateError::Factor(0)));
        assert!(matches!(design(4, 1.0, 100.0), Err(DecimateError::Passband(_))));
        assert!(matches!(design(4, f64::NAN, 100.0), Err(DecimateError::Passband(_))));
        assert!(matches!(design(4, 0.8, 10.0), Err(DecimateError::Attenuation(_))));
        let e = design(5000, 0.9, 150.0).unwrap_err();
        assert!(matches!(e, DecimateError::TooLong { .. }), "{e}");
        assert!(e.to_string().contains("two stages"), "{e}");
    }

    #[test]
    fn extreme_inputs_stay_finite_and_bounded() {
        let d = design(4, 0.8, 100.0).unwrap();
        let bound = d.taps.iter().map(|t| t.abs()).sum::<f64>();
        for big in [1e300, f64::MAX] {
            let mut dec = Decimator::new(&d);
            for n in 0..2000 {
                // Alternating signs: the worst case for the partial sums.
                let x = if (n / 3) % 2 == 0 { big } else { -big };
                if let Some(y) = dec.push(x) {
                    assert!(y.is_finite() && y.abs() <= bound * big, "{big}: {y}");
                }
            }
        }
    }
}
