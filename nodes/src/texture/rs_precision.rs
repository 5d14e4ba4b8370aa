//! Error against run time of the re-sampling methods of [`super::rs`]
//! (issue: the resampler options of the texture chain): a band-limited
//! multi-tone test signal, whose re-sampled version is known exactly, is
//! re-sampled by the velocity ratios the grid needs; the error is the RMS
//! difference from the exact result after the best constant sub-sample
//! delay (a constant delay is inaudible and unfelt; rubato's resamplers
//! keep up to one output sample of it), relative to the signal's RMS,
//! away from the ends. The figures of `docs/texture.md` come from here
//! (`evflow report resample`).

use super::rs::{rs, RsError, RsMethod};
use std::f64::consts::TAU;
use std::time::Instant;

/// The test signal: `tones` sines between 5 Hz and `top` × the sample rate,
/// amplitudes 1/√k, phases fixed by a seed; returns (frequency in cycles
/// per sample, amplitude, phase) triples.
pub fn tones(count: usize, top: f64, seed: u64) -> Vec<(f64, f64, f64)> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (1..=count).map(|k| (0.005 + next() * (top - 0.005), 1.0 / (k as f64).sqrt(), TAU * next())).collect()
}

/// The signal of `tones` at (fractional) sample position `t`.
pub fn eval(tones: &[(f64, f64, f64)], t: f64) -> f64 {
    tones.iter().map(|&(f, a, ph)| a * (TAU * f * t + ph).sin()).sum()
}

/// The outcome of one method at one ratio.
#[derive(Debug, Clone, Copy)]
pub struct Precision {
    /// RMS error after the best delay, relative to the exact result's RMS.
    pub error: f64,
    /// That delay, output samples.
    pub delay: f64,
    /// Run time of one call, s (best of the repeats).
    pub seconds: f64,
    /// Output samples produced.
    pub samples: usize,
}

/// Re-samples `len` samples of the test signal by p/q with `method`
/// (best time of `repeats` runs) and scores it against the exact result.
/// Content must stay below the new Nyquist frequency: `top` < p/(2q).
pub fn measure(
    tones: &[(f64, f64, f64)],
    len: usize,
    p: f64,
    q: f64,
    method: RsMethod,
    repeats: usize,
) -> Result<Precision, RsError> {
    let y: Vec<f64> = (0..len).map(|n| eval(tones, n as f64)).collect();
    let mut out = Vec::new();
    let mut seconds = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        out = rs(&y, p, q, method)?;
        seconds = seconds.min(t.elapsed().as_secs_f64());
    }
    let (error, delay) = score(&out, tones, q / p);
    Ok(Precision { error, delay, seconds, samples: out.len() })
}

/// The RMS error of `out` against the test signal read every `step` input
/// samples, relative to its RMS, after the best constant delay (output
/// samples, within ±1.5), away from the ends: (error, delay).
pub fn score(out: &[f64], tones: &[(f64, f64, f64)], step: f64) -> (f64, f64) {
    let margin = (out.len() / 10).max(64).min(out.len() / 3);
    let body = margin..out.len().saturating_sub(margin);
    let rms_of = |delay: f64| {
        let (mut e, mut r, mut n) = (0.0, 0.0, 0usize);
        for k in body.clone() {
            let want = eval(tones, (k as f64 - delay) * step);
            e += (out[k] - want).powi(2);
            r += want * want;
            n += 1;
        }
        (e.sqrt() / r.sqrt().max(f64::MIN_POSITIVE), n)
    };
    // Coarse scan of the delay over ±1.5 output samples, then golden-section
    // refinement. Each error is a sum of sines over the whole body, the
    // same whichever thread takes it: the scan's two halves, and the two
    // points of each golden step, are computed side by side.
    let mut best = (0.0, rms_of(0.0).0);
    let scan = |range: std::ops::RangeInclusive<i32>| -> Vec<(f64, f64)> {
        range.map(|i| i as f64 * 0.05).map(|d| (d, rms_of(d).0)).collect()
    };
    let (low, high) = side_by_side(|| scan(-30..=0), || scan(1..=30));
    for (d, e) in low.into_iter().chain(high) {
        if e < best.1 {
            best = (d, e);
        }
    }
    let (mut a, mut b) = (best.0 - 0.05, best.0 + 0.05);
    let g = 0.618_033_988_749_894_9;
    for _ in 0..40 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        let (at_c, at_d) = side_by_side(|| rms_of(c).0, || rms_of(d).0);
        if at_c < at_d {
            b = d;
        } else {
            a = c;
        }
    }
    let delay = 0.5 * (a + b);
    let error = rms_of(delay).0.min(best.1);
    (error, delay)
}

/// `a()` on a second thread while `b()` runs on this one (a panic in
/// `a` goes on in the caller, as it would have without the thread).
fn side_by_side<A: Send, B>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B) -> (A, B) {
    std::thread::scope(|s| {
        let other = s.spawn(a);
        let rb = b();
        (other.join().unwrap_or_else(|e| std::panic::resume_unwind(e)), rb)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rate::resampler::Quality;
    use rubato::PolynomialDegree;

    #[test]
    fn side_by_side_returns_both_in_order_and_passes_a_panic_on() {
        let t = tones(5, 0.2, 3);
        let (a, b) = side_by_side(|| eval(&t, 0.25), || eval(&t, 7.5));
        assert_eq!((a.to_bits(), b.to_bits()), (eval(&t, 0.25).to_bits(), eval(&t, 7.5).to_bits()));
        let caught = std::panic::catch_unwind(|| side_by_side(|| -> f64 { panic!("in the other thread") }, || 1.0));
        assert!(caught.is_err());
    }

    #[test]
    fn the_exact_kernel_and_long_sincs_are_accurate_and_errors_fall_with_length() {
        let t = tones(8, 0.22, 7);
        let k8 = measure(&t, 4000, 3.0, 4.0, RsMethod::Kernel(8), 1).unwrap();
        let k32 = measure(&t, 4000, 3.0, 4.0, RsMethod::Kernel(32), 1).unwrap();
        assert!(k32.error < k8.error, "{k8:?} {k32:?}");
        assert!(k32.error < 1e-3, "{k32:?}");
        assert!(k32.delay.abs() < 0.01, "the kernel is aligned exactly: {k32:?}");
        let s32 = measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoSinc(32), 1).unwrap();
        let s256 = measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoSinc(256), 1).unwrap();
        assert!(s256.error < s32.error, "{s32:?} {s256:?}");
        let lin = measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoPoly(PolynomialDegree::Linear), 1).unwrap();
        assert!(lin.error > s256.error, "{lin:?} {s256:?}");
    }

    #[test]
    fn the_resample_node_s_sincs_are_accurate_and_its_cubic_is_not() {
        // Content to 0.22 f_s at 3/4 (new Nyquist 0.375 f_s): inside both
        // sincs' passbands (measured 5e-11, 8e-11); the cubic leaves 3e-2.
        let t = tones(8, 0.22, 7);
        let m = |q| measure(&t, 4000, 3.0, 4.0, RsMethod::Node(q), 1).unwrap();
        let (fast, balanced, best) = (m(Quality::Fast), m(Quality::Balanced), m(Quality::Best));
        assert!(balanced.error < 1e-9 && best.error < 1e-9, "{balanced:?} {best:?}");
        assert!(fast.error > 1e-3 && fast.error < 0.1, "{fast:?}");
        // Its latency is removed to the nearest output sample.
        for p in [fast, balanced, best] {
            assert!(p.delay.abs() <= 0.5 + 1e-3, "{p:?}");
        }
    }

    #[test]
    fn the_scorer_recovers_a_pure_delay_and_sees_an_error() {
        let t = tones(4, 0.2, 1);
        let shifted: Vec<f64> = (0..2000).map(|n| eval(&t, n as f64 - 0.3)).collect();
        let (e, d) = score(&shifted, &t, 1.0);
        assert!(e < 1e-6 && (d - 0.3).abs() < 1e-4, "{e} {d}");
        let noisy: Vec<f64> = shifted.iter().enumerate().map(|(n, y)| y + 0.01 * (n as f64 * 0.37).sin()).collect();
        let (e, _) = score(&noisy, &t, 1.0);
        assert!(e > 1e-3 && e < 0.02, "{e}");
    }
}
