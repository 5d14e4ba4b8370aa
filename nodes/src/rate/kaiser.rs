//! Linear-phase low-pass FIR filters by the Kaiser window method, and the
//! measured response of any symmetric FIR filter.
//!
//! The method (Kaiser 1974; Oppenheim & Schafer, *Discrete-Time Signal
//! Processing*, 3rd ed., §7.6.1): for a stopband attenuation of `A` dB
//! (ripple δ = 10^(−A/20) in both bands) and a transition width Δω
//! (radians per sample) between the passband edge ω_p and the stopband
//! edge ω_s,
//!
//! * shape β = 0.1102 (A − 8.7) for A > 50, 0.5842 (A − 21)^0.4 +
//!   0.07886 (A − 21) for 21 ≤ A ≤ 50, and 0 below (Eq. 7.75);
//! * order N = ⌈(A − 8) / (2.285 Δω)⌉ (Eq. 7.76);
//! * taps h\[n\] = (ω_c/π) · sinc(ω_c (n − N/2) / π) · w\[n\], n = 0 … N, with
//!   the ideal cut-off ω_c = (ω_p + ω_s)/2 in the middle of the transition
//!   band and the Kaiser window w\[n\] = I₀(β √(1 − (2n/N − 1)²)) / I₀(β).
//!
//! An even N gives a type I filter (odd length, symmetric): linear phase,
//! a group delay of exactly N/2 samples at every frequency. The taps are
//! scaled to sum to 1, so the DC gain is 1 to rounding.
//!
//! Kaiser's order formula is an estimate (within a few taps); the designer
//! that uses this module ([`super::decimator`]) measures the response with
//! [`measure`] and lengthens the filter until the figures hold.

use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// The modified Bessel function of the first kind, order 0 (power series;
/// converges for every argument a Kaiser window uses).
pub fn bessel_i0(x: f64) -> f64 {
    let q = x * x / 4.0;
    let (mut term, mut sum) = (1.0, 1.0);
    for k in 1..500 {
        term *= q / (k * k) as f64;
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    sum
}

/// Kaiser's window shape β for a stopband attenuation of `atten_db` dB.
pub fn beta(atten_db: f64) -> f64 {
    if atten_db > 50.0 {
        0.1102 * (atten_db - 8.7)
    } else if atten_db >= 21.0 {
        0.5842 * (atten_db - 21.0).powf(0.4) + 0.07886 * (atten_db - 21.0)
    } else {
        0.0
    }
}

/// Kaiser's estimate of the order N (taps − 1) for `atten_db` dB over a
/// transition of `transition` radians per sample.
pub fn order_estimate(atten_db: f64, transition: f64) -> usize {
    ((atten_db - 8.0) / (2.285 * transition)).ceil().max(2.0) as usize
}

/// The N + 1 taps of a Kaiser-windowed sinc low-pass of even order `order`,
/// ideal cut-off `cutoff` (cycles per sample, 0 < cutoff < 0.5) and shape
/// `beta`, scaled to sum to 1.
pub fn lowpass(order: usize, cutoff: f64, beta: f64) -> Vec<f64> {
    let half = order as f64 / 2.0;
    let i0b = bessel_i0(beta);
    let mut taps: Vec<f64> = (0..=order)
        .map(|n| {
            let d = n as f64 - half;
            let ideal = if d == 0.0 { 2.0 * cutoff } else { (2.0 * PI * cutoff * d).sin() / (PI * d) };
            let r = if half > 0.0 { d / half } else { 0.0 };
            ideal * bessel_i0(beta * (1.0 - r * r).max(0.0).sqrt()) / i0b
        })
        .collect();
    let sum: f64 = taps.iter().sum();
    for t in &mut taps {
        *t /= sum;
    }
    taps
}

/// How far a filter's magnitude strays from 1 in its passband and from 0
/// in its stopband.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Response {
    /// Largest | |H(f)| − 1 | over the passband.
    pub pass_deviation: f64,
    /// Largest |H(f)| over the stopband.
    pub stop_gain: f64,
}

impl Response {
    /// Passband ripple in dB: 20·log₁₀(1 + largest deviation).
    pub fn ripple_db(&self) -> f64 {
        20.0 * (1.0 + self.pass_deviation).log10()
    }
    /// Stopband attenuation in dB: −20·log₁₀(largest stopband gain).
    pub fn attenuation_db(&self) -> f64 {
        -20.0 * self.stop_gain.max(f64::MIN_POSITIVE).log10()
    }
}

/// The magnitude of the FIR filter `taps` on a grid at least 32 times
/// finer than its length (zero-padded FFT) and at both band edges (direct
/// sums), over the passband `[0, pass_edge]` and the stopband
/// `[stop_edge, 0.5]` (cycles per sample).
pub fn measure(taps: &[f64], pass_edge: f64, stop_edge: f64) -> Response {
    let n = (32 * taps.len()).next_power_of_two().max(4096);
    let mut buf: Vec<Complex64> = taps.iter().map(|&t| Complex64::new(t, 0.0)).collect();
    buf.resize(n, Complex64::new(0.0, 0.0));
    evflow_dsp::fft::forward(n).process(&mut buf);
    let (mut pass_deviation, mut stop_gain) = (0.0f64, 0.0f64);
    for (k, h) in buf.iter().take(n / 2 + 1).enumerate() {
        let f = k as f64 / n as f64;
        let g = h.norm();
        if f <= pass_edge {
            pass_deviation = pass_deviation.max((g - 1.0).abs());
        }
        if f >= stop_edge {
            stop_gain = stop_gain.max(g);
        }
    }
    pass_deviation = pass_deviation.max((gain(taps, pass_edge) - 1.0).abs());
    stop_gain = stop_gain.max(gain(taps, stop_edge));
    Response { pass_deviation, stop_gain }
}

/// |H(f)| of `taps` at `f` cycles per sample, by the direct sum.
pub fn gain(taps: &[f64], f: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (n, t) in taps.iter().enumerate() {
        let w = 2.0 * PI * f * n as f64;
        re += t * w.cos();
        im -= t * w.sin();
    }
    re.hypot(im)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bessel_i0_known_values() {
        // Abramowitz & Stegun Table 9.8: I₀(1) = 1.266065878, I₀(5) = 27.23987182.
        assert!((bessel_i0(1.0) - 1.266_065_878).abs() < 1e-9);
        assert!((bessel_i0(5.0) - 27.239_871_82).abs() < 1e-7);
        assert_eq!(bessel_i0(0.0), 1.0);
    }

    #[test]
    fn kaiser_formulas_match_the_textbook_example() {
        // Oppenheim & Schafer Example 7.8: ω_p = 0.4π, ω_s = 0.6π, δ = 0.001
        // (A = 60 dB) give β = 5.653 and M = 37.
        assert!((beta(60.0) - 5.65326).abs() < 1e-5);
        assert_eq!(order_estimate(60.0, 0.2 * PI), 37);
        assert_eq!(beta(20.0), 0.0);
        assert!((beta(50.0) - (0.5842 * 29f64.powf(0.4) + 0.07886 * 29.0)).abs() < 1e-12);
    }

    #[test]
    fn a_lowpass_is_symmetric_with_unit_dc_gain_and_meets_its_figures() {
        // Pass to 0.2, stop from 0.25 cycles per sample, 80 dB.
        let (fp, fs, a) = (0.2, 0.25, 80.0);
        let n = order_estimate(a, 2.0 * PI * (fs - fp)).next_multiple_of(2);
        let h = lowpass(n, 0.5 * (fp + fs), beta(a));
        assert_eq!(h.len(), n + 1);
        for k in 0..h.len() {
            assert_eq!(h[k].to_bits(), h[h.len() - 1 - k].to_bits(), "tap {k}");
        }
        assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let r = measure(&h, fp, fs);
        // Kaiser's estimate lands within a fraction of a dB of the target.
        assert!(r.attenuation_db() > a - 1.0 && r.attenuation_db() < a + 3.0, "{r:?}");
        assert!(r.pass_deviation < 2e-4, "{r:?}");
        // The FFT grid agrees with the direct sum at its own points and
        // finds the stopband peak within 0.1 dB of a 10× finer direct search.
        let mut peak = 0.0f64;
        for k in 0..=20_000 {
            peak = peak.max(gain(&h, fs + (0.5 - fs) * k as f64 / 20_000.0));
        }
        assert!((20.0 * (peak / r.stop_gain).log10()).abs() < 0.1, "{peak} vs {}", r.stop_gain);
    }

    #[test]
    fn the_response_of_a_known_filter() {
        // A 2-tap average: |H(f)| = |cos(πf)|; passband [0, 0.1] deviates by
        // 1 − cos(0.1π), the stopband [0.4, 0.5] peaks at cos(0.4π) — both
        // at the band edges, which fall between the grid's points.
        let r = measure(&[0.5, 0.5], 0.1, 0.4);
        assert!((r.pass_deviation - (1.0 - (0.1 * PI).cos())).abs() < 1e-12, "{r:?}");
        assert!((r.stop_gain - (0.4 * PI).cos()).abs() < 1e-12, "{r:?}");
        assert!((r.ripple_db() - 20.0 * (2.0 - (0.1 * PI).cos()).log10()).abs() < 1e-12);
    }
}
