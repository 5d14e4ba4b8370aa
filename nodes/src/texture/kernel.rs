//! A band-limited evaluator of a sampled signal at any real position: a
//! Kaiser-windowed sinc read from a precomputed table.
//!
//! This is the re-sampling step 𝓡𝓢 of Eq. 6.4 as the `interp` node runs it
//! live: each output sample k of 𝓡𝓢(y, v_j, v_u) is y evaluated at the input
//! position p₀ + k·t with t = v_u / v_j input samples per output sample, so
//! any sample of the re-sampled signal can be computed on its own, in any
//! order and at any tick, with exact sub-sample alignment. The anti-alias
//! cutoff follows the ratio of every update: c = γ·min(1, 1/t) of the input
//! Nyquist frequency, and the kernel widens to W/c taps on each side.
//! (rubato's asynchronous resampler fixes its anti-alias filter when it is
//! built, and its docs warn that lowering the ratio afterwards by more than a
//! few percent aliases; the ratio here changes at every update.)
//!
//! y(p) = Σₙ y\[n\]·h(p − n) / Σₙ h(p − n), h(d) = sinc(c·d)·kaiser(c·d / W),
//! summed over |p − n| < W/c. Dividing by the sum of the taps makes a
//! constant come out exact whatever the position and the cutoff.

use crate::rate::kaiser::bessel_i0;
use std::f64::consts::PI;

/// Table points per unit of the scaled argument c·d.
pub(super) const OVERSAMPLING: usize = 512;

/// The anti-alias cutoff γ of `interp`'s kernel, as a fraction of the
/// Nyquist frequency (at ratios ≤ 1; lower for faster reading). Content
/// above it is removed even at a ratio of 1.
pub const INTERP_CUTOFF: f64 = 0.9;

/// The Kaiser shape β of `interp`'s kernel.
pub const INTERP_BETA: f64 = 8.6;

/// The windowed-sinc table and its settings.
#[derive(Debug, Clone)]
pub struct SincKernel {
    /// Half-width W in zero crossings of the sinc (taps at cutoff 1).
    half_width: usize,
    /// Cutoff as a fraction γ of the Nyquist frequency (at ratio ≥ 1).
    cutoff: f64,
    /// g(u) = sinc(u)·kaiser(u/W) at u = i / OVERSAMPLING, i = 0 ..= W·OVERSAMPLING + 1.
    table: Vec<f64>,
}

impl SincKernel {
    /// A kernel of half-width `half_width` (≥ 2) zero crossings, cutoff
    /// `cutoff` (0 < γ ≤ 1) of the Nyquist frequency, and Kaiser shape `beta`.
    pub fn new(half_width: usize, cutoff: f64, beta: f64) -> Self {
        let half_width = half_width.max(2);
        let n = half_width * OVERSAMPLING + 2;
        let i0b = bessel_i0(beta);
        let table = (0..n)
            .map(|i| {
                let u = i as f64 / OVERSAMPLING as f64;
                let r = u / half_width as f64;
                if r >= 1.0 {
                    return 0.0;
                }
                let sinc = if u == 0.0 { 1.0 } else { (PI * u).sin() / (PI * u) };
                sinc * bessel_i0(beta * (1.0 - r * r).sqrt()) / i0b
            })
            .collect();
        Self { half_width, cutoff: cutoff.clamp(1e-3, 1.0), table }
    }

    /// The kernel `interp` runs: [`INTERP_CUTOFF`], [`INTERP_BETA`], half-width `half_width`.
    pub fn for_interp(half_width: usize) -> Self {
        Self::new(half_width, INTERP_CUTOFF, INTERP_BETA)
    }

    /// The half-width W.
    pub fn half_width(&self) -> usize {
        self.half_width
    }

    /// The cutoff c (fraction of the input Nyquist frequency) used for a step
    /// of `step` input samples per output sample: γ·min(1, 1/step).
    pub fn cutoff_for(&self, step: f64) -> f64 {
        if step > 1.0 {
            self.cutoff / step
        } else {
            self.cutoff
        }
    }

    /// Input samples each side of a position that the kernel reads at cutoff `c`.
    pub fn reach(&self, c: f64) -> f64 {
        self.half_width as f64 / c
    }

    /// The table of g: g(i / [`OVERSAMPLING`]) at index i.
    pub(super) fn table(&self) -> &[f64] {
        &self.table
    }

    /// g(u), linearly interpolated in the table; 0 beyond it.
    #[inline(always)]
    fn g(&self, u: f64) -> f64 {
        let x = u.abs() * OVERSAMPLING as f64;
        // x ≥ 0, so through u32 it is the index `x as usize` is (a table
        // is far shorter than 2³² points, and past its end both give 0),
        // converted in fewer instructions.
        let i = x as u32 as usize;
        match self.table.get(i..i + 2) {
            Some(&[a, b]) => a + (x - i as f64) * (b - a),
            _ => 0.0,
        }
    }

    /// The signal `at(n)` (defined for n in `0 .. len`) evaluated at the real
    /// position `p` with cutoff `c`. Samples outside `0 .. len` are left out
    /// and the remaining taps renormalized (0 when none is left).
    #[inline]
    pub fn eval(&self, p: f64, c: f64, len: usize, at: impl Fn(usize) -> f64) -> f64 {
        let Some((first, last)) = self.span(p, c, len) else { return 0.0 };
        let (mut acc, mut norm) = (0.0, 0.0);
        self.taps(p, c, first, last + 1, &mut acc, &mut norm, at);
        ratio(acc, norm)
    }

    /// The taps under position `p` at cutoff `c` that lie in `0 .. len`:
    /// `first ..= last`, or `None` when there are none.
    #[inline(always)]
    pub(super) fn span(&self, p: f64, c: f64, len: usize) -> Option<(usize, usize)> {
        let reach = self.reach(c);
        let first = (p - reach).ceil().max(0.0);
        let last = (p + reach).floor().min(len as f64 - 1.0);
        if first.is_nan() || last.is_nan() || first > last {
            return None;
        }
        Some((first as usize, last as usize))
    }

    /// Adds taps `from .. to` to the weighted sum `acc` and the sum of
    /// weights `norm`, in order.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn taps(
        &self,
        p: f64,
        c: f64,
        from: usize,
        to: usize,
        acc: &mut f64,
        norm: &mut f64,
        at: impl Fn(usize) -> f64,
    ) {
        // n as f64, counted in f64 (exact: n < 2⁵³) rather than converted
        // from usize tap by tap, which takes several instructions.
        let mut at_n = from as f64;
        for n in from..to {
            let h = self.g(c * (p - at_n));
            *acc += h * at(n);
            *norm += h;
            at_n += 1.0;
        }
    }

    /// 𝓡𝓢 of a whole signal: `len_out` samples of `y` at positions
    /// `start + k·step` (step = input samples per output sample).
    pub fn resample(&self, y: &[f64], start: f64, step: f64, len_out: usize) -> Vec<f64> {
        let c = self.cutoff_for(step);
        (0..len_out).map(|k| self.eval(start + k as f64 * step, c, y.len(), |n| y[n])).collect()
    }
}

/// The weighted sum over the sum of weights (0 when the weights vanish).
#[inline(always)]
pub(super) fn ratio(acc: f64, norm: f64) -> f64 {
    if norm.abs() < 1e-12 {
        0.0
    } else {
        acc / norm
    }
}

impl Default for SincKernel {
    /// W = 16, γ = 0.9, β = 8.6 (side lobes ≈ −90 dB).
    fn default() -> Self {
        Self::new(16, 0.9, 8.6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn reproduces_samples_constants_and_in_band_sines() {
        let k = SincKernel::default();
        let y: Vec<f64> = (0..400).map(|n| (TAU * 30.0 * n as f64 / 1000.0 + 0.3).sin()).collect();
        // At integer positions far from the edges it returns the samples.
        for n in [100usize, 200, 250] {
            assert!((k.eval(n as f64, 0.9, y.len(), |i| y[i]) - y[n]).abs() < 1e-4);
        }
        // Between samples: the band-limited sine itself.
        for p in [100.25, 171.5, 250.9] {
            let want = (TAU * 30.0 * p / 1000.0 + 0.3).sin();
            assert!((k.eval(p, 0.9, y.len(), |i| y[i]) - want).abs() < 1e-3, "{p}");
        }
        // A constant is exact at any position and cutoff, even at the edges.
        for (p, c) in [(0.0, 0.9), (3.3, 0.2), (399.0, 0.05)] {
            assert!((k.eval(p, c, 400, |_| 2.5) - 2.5).abs() < 1e-12);
        }
    }

    /// The evaluation as it was before the index conversions were trimmed:
    /// the reference the kernel must match bit for bit.
    fn eval_reference(k: &SincKernel, p: f64, c: f64, len: usize, at: impl Fn(usize) -> f64) -> f64 {
        let g = |u: f64| {
            let x = u.abs() * OVERSAMPLING as f64;
            let i = x as usize;
            if i + 1 >= k.table.len() {
                return 0.0;
            }
            k.table[i] + (x - i as f64) * (k.table[i + 1] - k.table[i])
        };
        let reach = k.reach(c);
        let first = (p - reach).ceil().max(0.0);
        let last = (p + reach).floor().min(len as f64 - 1.0);
        if first.is_nan() || last.is_nan() || first > last {
            return 0.0;
        }
        let (mut acc, mut norm) = (0.0, 0.0);
        for n in first as usize..=last as usize {
            let h = g(c * (p - n as f64));
            acc += h * at(n);
            norm += h;
        }
        if norm.abs() < 1e-12 {
            0.0
        } else {
            acc / norm
        }
    }

    #[test]
    fn evaluation_is_the_reference_bit_for_bit() {
        let y: Vec<f64> = (0..3000).map(|n| (n as f64 * 0.37).sin() + 1e-3 * n as f64).collect();
        for k in [SincKernel::for_interp(16), SincKernel::new(2, 1.0, 5.0), SincKernel::default()] {
            for p in [-50.0, -0.3, 0.0, 0.5, 17.25, 1234.567, 2999.0, 2999.9, 3020.0, 1e9, f64::NAN] {
                for c in [1.0, 0.9, 0.45, 0.05, 1e-3] {
                    let (got, want) = (k.eval(p, c, y.len(), |i| y[i]), eval_reference(&k, p, c, y.len(), |i| y[i]));
                    assert_eq!(got.to_bits(), want.to_bits(), "p {p}, c {c}");
                }
            }
        }
    }

    #[test]
    fn resampling_a_sine_moves_its_frequency() {
        // 10 Hz read at 1.5 samples per output sample is 15 Hz (§6.2).
        let k = SincKernel::default();
        let y: Vec<f64> = (0..3000).map(|n| (TAU * 10.0 * n as f64 / 1000.0).sin()).collect();
        let r = k.resample(&y, 0.0, 1.5, 1900);
        for (i, v) in r.iter().enumerate().skip(20).take(1800) {
            assert!((v - (TAU * 15.0 * i as f64 / 1000.0).sin()).abs() < 1e-3, "{i}");
        }
    }

    #[test]
    fn downsampling_removes_what_would_alias() {
        // 400 Hz at fs 1 kHz read at step 2 would alias to 200 Hz; the cutoff
        // γ/2 of Nyquist (225 Hz) removes it.
        let k = SincKernel::default();
        let y: Vec<f64> = (0..4000).map(|n| (TAU * 400.0 * n as f64 / 1000.0).sin()).collect();
        let r = k.resample(&y, 0.0, 2.0, 1900);
        let rms = (r[100..1800].iter().map(|v| v * v).sum::<f64>() / 1700.0).sqrt();
        assert!(rms < 1e-3, "alias rms {rms}");
    }
}
