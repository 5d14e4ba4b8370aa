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

/// The RMS error of `out` against the test signal read every `step` input
/// samples, relative to its RMS, after the best constant delay (output
/// samples, within ±1.5), away from the ends: (error, delay).
pub fn score(out: &[f64], tones: &[(f64, f64, f64)], step: f64) -> (f64, f64) {
    Scorer::default().score(out, tones, step)
}

/// The delays of the scorer's coarse scan, in steps of 0.05 output samples.
const SCAN: std::ops::RangeInclusive<i32> = -30..=30;

/// Scores re-sampled signals, keeping the exact signal at the delays of the
/// coarse scan between calls: every method scored at one ratio (and one
/// output length) is compared with the same values there, so they are
/// computed once (the scan is 62 of a score's 143 passes over the signal).
/// The results are the same bits as a fresh scorer's: each kept value is
/// computed as the pass would have computed it, and added in the same order.
#[derive(Debug, Default)]
pub struct Scorer {
    scans: Vec<Scan>,
}

/// The exact signal at every delay of [`SCAN`] for one signal, step and body.
#[derive(Debug)]
struct Scan {
    tones: Vec<[u64; 3]>,
    step: u64,
    body: std::ops::Range<usize>,
    /// `want[i][k − body.start]`: the signal at output sample k, delay `SCAN`'s i-th.
    want: Vec<Vec<f64>>,
}

impl Scorer {
    /// Re-samples `len` samples of the test signal by p/q with `method`
    /// (best time of `repeats` runs) and scores it against the exact result.
    /// Content must stay below the new Nyquist frequency: `top` < p/(2q).
    pub fn measure(
        &mut self,
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
        let (error, delay) = self.score(&out, tones, q / p);
        Ok(Precision { error, delay, seconds, samples: out.len() })
    }

    /// [`score`], keeping this scorer's scans.
    pub fn score(&mut self, out: &[f64], tones: &[(f64, f64, f64)], step: f64) -> (f64, f64) {
        let margin = (out.len() / 10).max(64).min(out.len() / 3);
        let body = margin..out.len().saturating_sub(margin);
        let want_at =
            |delay: f64| -> Vec<f64> { body.clone().map(|k| eval(tones, (k as f64 - delay) * step)).collect() };
        let rms_against = |want: &[f64]| {
            let (mut e, mut r) = (0.0, 0.0);
            for (&o, &w) in out[body.clone()].iter().zip(want) {
                e += (o - w).powi(2);
                r += w * w;
            }
            e.sqrt() / r.sqrt().max(f64::MIN_POSITIVE)
        };
        let rms_of = |delay: f64| rms_against(&want_at(delay));
        // Coarse scan of the delay over ±1.5 output samples, then golden-section
        // refinement. The scan's signal is kept; each of its halves, and the two
        // points of each golden step, are computed side by side.
        let key: Vec<[u64; 3]> = tones.iter().map(|&(f, a, ph)| [f.to_bits(), a.to_bits(), ph.to_bits()]).collect();
        let found = self.scans.iter().position(|s| s.tones == key && s.step == step.to_bits() && s.body == body);
        let k = match found {
            Some(k) => k,
            None => {
                let half = |range: std::ops::RangeInclusive<i32>| -> Vec<Vec<f64>> {
                    range.map(|i| want_at(i as f64 * 0.05)).collect()
                };
                let (mut want, high) = side_by_side(|| half(*SCAN.start()..=0), || half(1..=*SCAN.end()));
                want.extend(high);
                self.scans.push(Scan { tones: key, step: step.to_bits(), body: body.clone(), want });
                self.scans.len() - 1
            }
        };
        let scan = &self.scans[k].want;
        // Delay 0 is the scan's own.
        let mut best = (0.0, rms_against(&scan[(-SCAN.start()) as usize]));
        for (i, want) in SCAN.zip(scan) {
            let e = rms_against(want);
            if e < best.1 {
                best = (i as f64 * 0.05, e);
            }
        }
        let (mut a, mut b) = (best.0 - 0.05, best.0 + 0.05);
        let g = 0.618_033_988_749_894_9;
        for _ in 0..40 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            let (at_c, at_d) = side_by_side(|| rms_of(c), || rms_of(d));
            if at_c < at_d {
                b = d;
            } else {
                a = c;
            }
        }
        let delay = 0.5 * (a + b);
        let error = rms_of(delay).min(best.1);
        (error, delay)
    }
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
        let k8 = Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::Kernel(8), 1).unwrap();
        let k32 = Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::Kernel(32), 1).unwrap();
        assert!(k32.error < k8.error, "{k8:?} {k32:?}");
        assert!(k32.error < 1e-3, "{k32:?}");
        assert!(k32.delay.abs() < 0.01, "the kernel is aligned exactly: {k32:?}");
        let s32 = Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoSinc(32), 1).unwrap();
        let s256 = Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoSinc(256), 1).unwrap();
        assert!(s256.error < s32.error, "{s32:?} {s256:?}");
        let lin =
            Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::RubatoPoly(PolynomialDegree::Linear), 1).unwrap();
        assert!(lin.error > s256.error, "{lin:?} {s256:?}");
    }

    #[test]
    fn the_resample_node_s_sincs_are_accurate_and_its_cubic_is_not() {
        // Content to 0.22 f_s at 3/4 (new Nyquist 0.375 f_s): inside both
        // sincs' passbands (measured 5e-11, 8e-11); the cubic leaves 3e-2.
        let t = tones(8, 0.22, 7);
        let m = |q| Scorer::default().measure(&t, 4000, 3.0, 4.0, RsMethod::Node(q), 1).unwrap();
        let (fast, balanced, best) = (m(Quality::Fast), m(Quality::Balanced), m(Quality::Best));
        assert!(balanced.error < 1e-9 && best.error < 1e-9, "{balanced:?} {best:?}");
        assert!(fast.error > 1e-3 && fast.error < 0.1, "{fast:?}");
        // Its latency is removed to the nearest output sample.
        for p in [fast, balanced, best] {
            assert!(p.delay.abs() <= 0.5 + 1e-3, "{p:?}");
        }
    }

    /// The scorer as it was before it kept its scans: every pass computes
    /// the signal it compares with.
    fn score_recomputing(out: &[f64], tones: &[(f64, f64, f64)], step: f64) -> (f64, f64) {
        let margin = (out.len() / 10).max(64).min(out.len() / 3);
        let body = margin..out.len().saturating_sub(margin);
        let rms_of = |delay: f64| {
            let (mut e, mut r) = (0.0, 0.0);
            for k in body.clone() {
                let want = eval(tones, (k as f64 - delay) * step);
                e += (out[k] - want).powi(2);
                r += want * want;
            }
            e.sqrt() / r.sqrt().max(f64::MIN_POSITIVE)
        };
        let mut best = (0.0, rms_of(0.0));
        for i in -30..=30 {
            let d = i as f64 * 0.05;
            let e = rms_of(d);
            if e < best.1 {
                best = (d, e);
            }
        }
        let (mut a, mut b) = (best.0 - 0.05, best.0 + 0.05);
        let g = 0.618_033_988_749_894_9;
        for _ in 0..40 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if rms_of(c) < rms_of(d) {
                b = d;
            } else {
                a = c;
            }
        }
        let delay = 0.5 * (a + b);
        (rms_of(delay).min(best.1), delay)
    }

    #[test]
    fn a_scorer_that_kept_its_scans_scores_as_one_that_recomputes_them() {
        let t = tones(6, 0.2, 5);
        let y: Vec<f64> = (0..3000).map(|n| eval(&t, n as f64)).collect();
        let mut kept = Scorer::default();
        // Several methods at two ratios through one scorer, each against the fresh scorer of `score`.
        for (p, q) in [(3.0, 4.0), (5.0, 4.5)] {
            for m in [RsMethod::Kernel(4), RsMethod::Kernel(16), RsMethod::RubatoPoly(PolynomialDegree::Cubic)] {
                let out = rs(&y, p, q, m).unwrap();
                let (e, d) = kept.score(&out, &t, q / p);
                let (re, rd) = score_recomputing(&out, &t, q / p);
                assert_eq!((e.to_bits(), d.to_bits()), (re.to_bits(), rd.to_bits()), "{m:?} at {p}/{q}");
                let (fe, fd) = score(&out, &t, q / p);
                assert_eq!((fe.to_bits(), fd.to_bits()), (re.to_bits(), rd.to_bits()), "{m:?} at {p}/{q}, fresh");
            }
        }
        // One scan per ratio (these methods' outputs have one length per ratio), reused by the others.
        assert_eq!(kept.scans.len(), 2);
        // Another signal is not scored against the kept scans.
        let other = tones(6, 0.2, 6);
        let out = rs(&y, 3.0, 4.0, RsMethod::Kernel(4)).unwrap();
        let (e, _) = kept.score(&out, &other, 0.75);
        assert_eq!(e.to_bits(), score_recomputing(&out, &other, 0.75).0.to_bits());
        assert_eq!(kept.scans.len(), 3);
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
