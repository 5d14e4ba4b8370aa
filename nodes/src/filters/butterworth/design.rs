//! Digital Butterworth design as second-order sections.
//!
//! The method is the classical one (Oppenheim & Schafer, *Discrete-Time
//! Signal Processing*, §7.1; it is also what `scipy.signal.butter(N, fc,
//! btype, fs=fs, output='sos')` computes):
//!
//! 1. **Analog prototype.** The normalized N-th order Butterworth low-pass
//!    `|H(jΩ)|² = 1 / (1 + Ω^(2N))` has its poles on the unit circle of the
//!    left half plane, `s_k = exp(jπ(2k + N + 1) / (2N))`, `k = 0 … N−1`.
//!    They come in conjugate pairs with damping `ζ_k = −Re s_k =
//!    sin(π(2k + 1) / (2N))`, each pair giving the factor `s² + 2ζ_k s + 1`;
//!    an odd order adds the real pole `s = −1`.
//! 2. **Pre-warping.** The bilinear transform maps the analog frequency `Ω`
//!    to the digital `ω` by `Ω = tan(ω/2)` (with the prototype scaled to
//!    cut off at 1 rad/s), so the cut-off is placed exactly at the digital
//!    `ω_c = 2π f_c / f_s` by scaling with `K = tan(π f_c / f_s)`.
//! 3. **Bilinear transform** `s = (1/K) · (1 − z⁻¹) / (1 + z⁻¹)` applied to
//!    each factor separately. A low-pass pair `1 / (s² + 2ζs + 1)` becomes
//!
//!    ```text
//!    H(z) = K² (1 + 2z⁻¹ + z⁻²) / (a0 + 2(K² − 1) z⁻¹ + (1 − 2ζK + K²) z⁻²),
//!    a0 = 1 + 2ζK + K²,
//!    ```
//!
//!    the high-pass pair `s² / (s² + 2ζs + 1)` (the low-pass with `s → 1/s`)
//!    has the same denominator over the numerator `1 − 2z⁻¹ + z⁻²`, and the
//!    first-order factors `1/(s + 1)` and `s/(s + 1)` become
//!    `K(1 + z⁻¹) / ((1 + K) + (K − 1) z⁻¹)` and
//!    `(1 − z⁻¹) / ((1 + K) + (K − 1) z⁻¹)`.
//!
//! The result has the exact digital Butterworth magnitude
//! `|H(e^{jω})|² = 1 / (1 + (tan(ω/2) / tan(ω_c/2))^(2N))` for the low-pass
//! and `1 / (1 + (tan(ω_c/2) / tan(ω/2))^(2N))` for the high-pass: unity
//! gain at DC (low-pass) or Nyquist (high-pass), −3.01 dB at the cut-off.
//! Every section has unity gain in the pass band, so no section amplifies
//! its input beyond what its own resonance does. Sections are ordered from
//! the most damped (the first-order one, then the largest `ζ`) to the least
//! damped. Everything is computed in `f64`.
//!
//! Numerical range: with coefficients stored as `a1 ≈ −2`, `a2 ≈ 1`, the
//! distance of the poles from `z = 1` is of order `K`, so the relative
//! error of the realized low-frequency behaviour is about `ε / K²`
//! (`ε ≈ 1.1e-16`). [`MIN_RELATIVE_CUTOFF`] keeps that below about 1e-5.

use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// Smallest cut-off, as a fraction of the sample rate, that the design
/// accepts: below it the rounding of the section coefficients changes the
/// low-frequency gain by more than about 1e-5 (see the module notes).
pub const MIN_RELATIVE_CUTOFF: f64 = 1e-6;

/// Highest filter order.
pub const MAX_ORDER: usize = 8;

/// Low-pass or high-pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Passes frequencies below the cut-off.
    Lowpass,
    /// Passes frequencies above the cut-off.
    Highpass,
}

/// Why a design was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DesignError {
    /// The order is outside `1 ..= MAX_ORDER`.
    #[error("order {0} is outside 1 ..= {MAX_ORDER}")]
    Order(usize),
    /// The sample rate is not a positive finite number.
    #[error("sample rate {0} Hz is not a positive finite number")]
    Rate(f64),
    /// The cut-off is at or above the Nyquist frequency.
    #[error("cut-off {cutoff} Hz is not below the Nyquist frequency {nyquist} Hz (half the sample rate {rate} Hz)")]
    AboveNyquist {
        /// The requested cut-off in Hz.
        cutoff: f64,
        /// Half the sample rate in Hz.
        nyquist: f64,
        /// The sample rate in Hz.
        rate: f64,
    },
    /// The cut-off is too low a fraction of the sample rate for `f64` coefficients.
    #[error("cut-off {cutoff} Hz is below {min} Hz ({MIN_RELATIVE_CUTOFF} × the sample rate {rate} Hz), where f64 second-order sections lose their accuracy")]
    TooLow {
        /// The requested cut-off in Hz.
        cutoff: f64,
        /// The lowest accepted cut-off in Hz.
        min: f64,
        /// The sample rate in Hz.
        rate: f64,
    },
}

/// One second-order section, normalized so that `a0 = 1`:
/// `H(z) = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²)`.
/// A first-order section has `b2 = a2 = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Numerator `[b0, b1, b2]`.
    pub b: [f64; 3],
    /// Denominator `[a1, a2]` (`a0 = 1`).
    pub a: [f64; 2],
}

impl Section {
    /// The section's frequency response at `ω` (radians per sample).
    pub fn response(&self, omega: f64) -> Complex64 {
        let z1 = Complex64::from_polar(1.0, -omega);
        let z2 = z1 * z1;
        let num = self.b[0] + z1 * self.b[1] + z2 * self.b[2];
        let den = 1.0 + z1 * self.a[0] + z2 * self.a[1];
        num / den
    }

    /// The largest pole magnitude (the section is stable when it is below 1).
    pub fn pole_radius(&self) -> f64 {
        let [a1, a2] = self.a;
        // Poles are the roots of z² + a1 z + a2.
        let disc = a1 * a1 - 4.0 * a2;
        if disc < 0.0 {
            // A conjugate pair: |p|² = p · p̄ = a2.
            a2.sqrt()
        } else {
            // Real roots; the larger one without cancellation, the other from the product.
            let q = -0.5 * (a1 + a1.signum() * disc.sqrt());
            if q == 0.0 {
                return 0.0;
            }
            (q.abs()).max((a2 / q).abs())
        }
    }
}

/// The frequency response of a cascade of sections at `ω` (radians per sample).
pub fn response(sections: &[Section], omega: f64) -> Complex64 {
    sections.iter().fold(Complex64::new(1.0, 0.0), |h, s| h * s.response(omega))
}

/// The analytic squared magnitude of the digital Butterworth filter of that
/// kind and order with cut-off `fc` at sample rate `fs`, at frequency `f`:
/// `1 / (1 + (tan(πf/fs) / tan(πfc/fs))^(±2N))`.
pub fn ideal_power(kind: Kind, order: usize, fc: f64, fs: f64, f: f64) -> f64 {
    let ratio = (PI * f / fs).tan() / (PI * fc / fs).tan();
    let r = match kind {
        Kind::Lowpass => ratio,
        Kind::Highpass => 1.0 / ratio,
    };
    1.0 / (1.0 + r.powi(2 * order as i32))
}

/// Designs a Butterworth filter of `order` (1 ..= 8) with cut-off `cutoff` Hz
/// (−3.01 dB) at sample rate `rate` Hz, as second-order sections (an odd order
/// gives one first-order section, placed first).
pub fn butterworth(kind: Kind, order: usize, cutoff: f64, rate: f64) -> Result<Vec<Section>, DesignError> {
    if !(1..=MAX_ORDER).contains(&order) {
        return Err(DesignError::Order(order));
    }
    if !(rate.is_finite() && rate > 0.0) {
        return Err(DesignError::Rate(rate));
    }
    let nyquist = rate / 2.0;
    if cutoff.is_nan() || cutoff >= nyquist {
        return Err(DesignError::AboveNyquist { cutoff, nyquist, rate });
    }
    let min = MIN_RELATIVE_CUTOFF * rate;
    if cutoff < min {
        return Err(DesignError::TooLow { cutoff, min, rate });
    }

    let k = (PI * cutoff / rate).tan();
    let k2 = k * k;
    let mut sections = Vec::with_capacity(order.div_ceil(2));
    if order % 2 == 1 {
        let a0 = 1.0 + k;
        let b = match kind {
            Kind::Lowpass => [k / a0, k / a0, 0.0],
            Kind::Highpass => [1.0 / a0, -1.0 / a0, 0.0],
        };
        sections.push(Section { b, a: [(k - 1.0) / a0, 0.0] });
    }
    // Pairs from the most damped (largest ζ, index order/2 − 1) to the least.
    for i in (0..order / 2).rev() {
        let zeta = (PI * (2 * i + 1) as f64 / (2 * order) as f64).sin();
        let a0 = 1.0 + 2.0 * zeta * k + k2;
        let b = match kind {
            Kind::Lowpass => {
                let g = k2 / a0;
                [g, 2.0 * g, g]
            }
            Kind::Highpass => {
                let g = 1.0 / a0;
                [g, -2.0 * g, g]
            }
        };
        let a = [2.0 * (k2 - 1.0) / a0, (1.0 - 2.0 * zeta * k + k2) / a0];
        sections.push(Section { b, a });
    }
    Ok(sections)
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [Kind; 2] = [Kind::Lowpass, Kind::Highpass];

    /// |H|² of the designed sections against the analytic digital
    /// Butterworth response, for every order, at 0.1, 0.5, 1, 2 and 10 × fc
    /// (those below Nyquist) and a few more points.
    #[test]
    fn magnitude_matches_the_analytic_response() {
        let cases = [(1000.0, 10.0), (1000.0, 100.0), (1000.0, 40.0), (10_000.0, 500.0), (48_000.0, 1000.0)];
        for (fs, fc) in cases {
            for kind in KINDS {
                for order in 1..=8 {
                    let s = butterworth(kind, order, fc, fs).unwrap();
                    assert_eq!(s.len(), order.div_ceil(2));
                    for m in [0.1, 0.25, 0.5, 0.9, 1.0, 1.1, 2.0, 5.0, 10.0] {
                        let f = m * fc;
                        if f >= fs / 2.0 {
                            continue;
                        }
                        let got = response(&s, 2.0 * PI * f / fs).norm_sqr();
                        let want = ideal_power(kind, order, fc, fs, f);
                        let rel = (got - want).abs() / want;
                        assert!(rel < 1e-9, "{kind:?} N={order} fc={fc} fs={fs} f={f}: {got:e} vs {want:e} ({rel:e})");
                    }
                    // −3.01 dB at the cut-off.
                    let at_fc = response(&s, 2.0 * PI * fc / fs).norm_sqr();
                    assert!((at_fc - 0.5).abs() < 1e-12, "{kind:?} N={order}: |H(fc)|² = {at_fc}");
                }
            }
        }
    }

    /// Coefficients from scipy 1.17.1, compared as sets of denominators
    /// (scipy pairs and orders sections differently) and as the complex
    /// response of the whole cascade.
    fn compare_with_scipy(ours: &[Section], scipy: &[[f64; 6]], fs: f64, tol: f64) {
        assert_eq!(ours.len(), scipy.len());
        let theirs: Vec<Section> = scipy
            .iter()
            .map(|r| Section { b: [r[0] / r[3], r[1] / r[3], r[2] / r[3]], a: [r[4] / r[3], r[5] / r[3]] })
            .collect();
        let sorted = |v: &[Section]| {
            let mut a: Vec<[f64; 2]> = v.iter().map(|s| s.a).collect();
            a.sort_by(|x, y| x[1].total_cmp(&y[1]).then(x[0].total_cmp(&y[0])));
            a
        };
        for (x, y) in sorted(ours).iter().zip(sorted(&theirs)) {
            assert!((x[0] - y[0]).abs() < 1e-13 && (x[1] - y[1]).abs() < 1e-13, "denominator {x:?} vs scipy {y:?}");
        }
        for i in 1..200 {
            let f = fs / 2.0 * i as f64 / 200.0;
            let w = 2.0 * PI * f / fs;
            let (h, r) = (response(ours, w), response(&theirs, w));
            let rel = (h - r).norm() / r.norm();
            assert!(rel < tol, "f={f}: {h} vs scipy {r} ({rel:e})");
        }
    }

    #[test]
    fn matches_scipy_highpass_10hz_at_1khz() {
        // §5.1.1: the tribometer's force high-pass.
        // scipy.signal.butter(4, 10, 'highpass', fs=1000, output='sos')
        let scipy = [
            [0.9211709934999417, -1.8423419869998834, 0.9211709934999417, 1.0, -1.8866095826215064, 0.8903397362840242],
            [1.0, -2.0, 1.0, 1.0, -1.9492159580258417, 0.9530698953278909],
        ];
        compare_with_scipy(&butterworth(Kind::Highpass, 4, 10.0, 1000.0).unwrap(), &scipy, 1000.0, 1e-10);
    }

    #[test]
    fn matches_scipy_lowpass_500hz_at_10khz() {
        // §3.1.2: the characterization low-pass on 10 kHz force data.
        // scipy.signal.butter(4, 500, 'lowpass', fs=10000, output='sos')
        let scipy = [
            [
                0.00041659920440659937,
                0.0008331984088131987,
                0.00041659920440659937,
                1.0,
                -1.4796742169311934,
                0.5558215432824889,
            ],
            [1.0, 2.0, 1.0, 1.0, -1.7009643319435257, 0.7884997398152979],
        ];
        compare_with_scipy(&butterworth(Kind::Lowpass, 4, 500.0, 10_000.0).unwrap(), &scipy, 10_000.0, 1e-10);
    }

    #[test]
    fn matches_scipy_odd_orders_and_extremes() {
        // scipy.signal.butter(3, 100, 'lowpass', fs=1000, output='sos')
        let lp3 = [
            [0.018098933007514428, 0.036197866015028855, 0.018098933007514428, 1.0, -0.5095254494944288, 0.0],
            [1.0, 1.0, 0.0, 1.0, -1.2505164308487402, 0.5457233155094579],
        ];
        compare_with_scipy(&butterworth(Kind::Lowpass, 3, 100.0, 1000.0).unwrap(), &lp3, 1000.0, 1e-10);

        // scipy.signal.butter(8, 499, 'lowpass', fs=1000, output='sos')
        let lp8 = [
            [0.9840256580072053, 1.9680513160144106, 0.9840256580072053, 1.0, 1.9877114188185523, 0.987750655314701],
            [1.0, 2.0, 1.0, 1.0, 1.989566542080498, 0.9896058151959145],
            [1.0, 2.0, 1.0, 1.0, 1.9930034891129478, 0.9930428300720954],
            [1.0, 2.0, 1.0, 1.0, 1.9975120102827224, 0.9975514402379748],
        ];
        compare_with_scipy(&butterworth(Kind::Lowpass, 8, 499.0, 1000.0).unwrap(), &lp8, 1000.0, 1e-9);

        // scipy.signal.butter(1, 250, 'highpass', fs=1000, output='sos')
        let hp1 = [[0.5, -0.5, 0.0, 1.0, -5.551115123125783e-17, 0.0]];
        compare_with_scipy(&butterworth(Kind::Highpass, 1, 250.0, 1000.0).unwrap(), &hp1, 1000.0, 1e-12);

        // A cut-off of 1e-5 × fs: poles within 1e-4 of z = 1, so a rounding
        // of 1e-16 in a coefficient moves the response near the cut-off by
        // about 1e-16 / K² ≈ 1e-7 relative — the tolerance says so.
        // scipy.signal.butter(5, 0.01, 'highpass', fs=1000, output='sos')
        let hp5 = [
            [0.9998983410937499, -0.9998983410937499, 0.0, 1.0, -0.9999371701207664, 0.0],
            [1.0, -2.0, 1.0, 1.0, -1.9998983371461092, 0.9998983410937503],
            [1.0, -2.0, 1.0, 1.0, -1.9999611645854416, 0.9999611685332067],
        ];
        compare_with_scipy(&butterworth(Kind::Highpass, 5, 0.01, 1000.0).unwrap(), &hp5, 1000.0, 1e-6);
    }

    /// Extreme cut-offs (0.01 Hz and 499 Hz at 1 kHz), every order: finite
    /// coefficients, poles inside the unit circle, unity gain where it must be.
    #[test]
    fn extreme_cutoffs_are_stable_with_unity_passband_gain() {
        let fs = 1000.0;
        for fc in [0.01, 499.0] {
            for kind in KINDS {
                for order in 1..=8 {
                    let s = butterworth(kind, order, fc, fs).unwrap();
                    for sec in &s {
                        assert!(sec.b.iter().chain(&sec.a).all(|c| c.is_finite()), "{sec:?}");
                        let r = sec.pole_radius();
                        assert!(r < 1.0, "{kind:?} N={order} fc={fc}: pole radius {r}");
                    }
                    let pass = match kind {
                        Kind::Lowpass => response(&s, 0.0),
                        Kind::Highpass => response(&s, PI),
                    };
                    assert!((pass.norm() - 1.0).abs() < 1e-6, "{kind:?} N={order} fc={fc}: pass-band gain {pass}");
                    let stop = match kind {
                        Kind::Lowpass => response(&s, PI),
                        Kind::Highpass => response(&s, 0.0),
                    };
                    assert!(stop.norm() < 1e-12, "{kind:?} N={order} fc={fc}: stop-band gain {stop}");
                }
            }
        }
    }

    #[test]
    fn lowest_accepted_cutoff_keeps_unity_gain() {
        // At the floor (1e-6 × fs) the realized DC gain is still within 1e-4.
        for order in 1..=8 {
            let s = butterworth(Kind::Lowpass, order, 1e-3, 1000.0).unwrap();
            let g = response(&s, 0.0).norm();
            assert!((g - 1.0).abs() < 1e-4, "N={order}: DC gain {g}");
            assert!(s.iter().all(|x| x.pole_radius() < 1.0));
        }
    }

    #[test]
    fn refuses_what_it_cannot_design() {
        assert_eq!(butterworth(Kind::Lowpass, 0, 10.0, 1000.0), Err(DesignError::Order(0)));
        assert_eq!(butterworth(Kind::Lowpass, 9, 10.0, 1000.0), Err(DesignError::Order(9)));
        assert!(matches!(butterworth(Kind::Lowpass, 2, 500.0, 1000.0), Err(DesignError::AboveNyquist { .. })));
        assert!(matches!(butterworth(Kind::Highpass, 2, 600.0, 1000.0), Err(DesignError::AboveNyquist { .. })));
        assert!(matches!(butterworth(Kind::Highpass, 2, f64::NAN, 1000.0), Err(DesignError::AboveNyquist { .. })));
        assert!(matches!(butterworth(Kind::Lowpass, 2, 1e-4, 1000.0), Err(DesignError::TooLow { .. })));
        assert!(matches!(butterworth(Kind::Lowpass, 2, 1.0, 0.0), Err(DesignError::Rate(_))));
        let msg = butterworth(Kind::Lowpass, 2, 500.0, 1000.0).unwrap_err().to_string();
        assert!(msg.contains("Nyquist frequency 500 Hz"), "{msg}");
    }

    #[test]
    fn pole_radius_of_known_sections() {
        // z² − 1.5z + 0.56 = (z − 0.8)(z − 0.7); z² + 0.81 has poles ±0.9j.
        assert!((Section { b: [1.0, 0.0, 0.0], a: [-1.5, 0.56] }.pole_radius() - 0.8).abs() < 1e-15);
        assert!((Section { b: [1.0, 0.0, 0.0], a: [0.0, 0.81] }.pole_radius() - 0.9).abs() < 1e-15);
        assert!((Section { b: [1.0, 0.0, 0.0], a: [0.5, 0.0] }.pole_radius() - 0.5).abs() < 1e-15);
        assert_eq!(Section { b: [1.0, 0.0, 0.0], a: [0.0, 0.0] }.pole_radius(), 0.0);
    }
}
