//! The runtime of a cascade of second-order sections.
//!
//! Each section runs in transposed direct form II (Oppenheim & Schafer,
//! *Discrete-Time Signal Processing*, §6.4; scipy's `sosfilt` uses the same
//! form), two state values per section, in `f64`:
//!
//! ```text
//! y  = b0·x + s1
//! s1 = b1·x − a1·y + s2
//! s2 = b2·x − a2·y
//! ```
//!
//! A block is run two sections at a time over the whole block (the second
//! section of sample n overlaps the first of sample n + 1 in the processor's
//! pipeline, which hides the latency of each section's recursion); each
//! sample goes through exactly the same operations as when the cascade is
//! run one sample at a time, so block and per-sample processing give
//! identical bits.

use super::design::Section;

/// `v ← f(v)` for every value of `y`, first to last or last to first.
#[inline(always)]
fn each<const REVERSED: bool>(y: &mut [f64], mut f: impl FnMut(f64) -> f64) {
    if REVERSED {
        y.iter_mut().rev().for_each(|v| *v = f(*v));
    } else {
        y.iter_mut().for_each(|v| *v = f(*v));
    }
}

/// One section with its state.
#[derive(Debug, Clone, Copy)]
struct Stage {
    c: Section,
    s1: f64,
    s2: f64,
}

impl Stage {
    #[inline(always)]
    fn tick(&mut self, x: f64) -> f64 {
        let [b0, b1, b2] = self.c.b;
        let [a1, a2] = self.c.a;
        let y = b0 * x + self.s1;
        self.s1 = b1 * x - a1 * y + self.s2;
        self.s2 = b2 * x - a2 * y;
        y
    }
}

/// A cascade of second-order sections with its state. Allocates only in
/// [`Cascade::new`].
#[derive(Debug, Clone)]
pub struct Cascade {
    stages: Vec<Stage>,
}

impl Cascade {
    /// A cascade at rest (all states zero).
    pub fn new(sections: &[Section]) -> Self {
        Self { stages: sections.iter().map(|&c| Stage { c, s1: 0.0, s2: 0.0 }).collect() }
    }

    /// The sections, in the order they are applied.
    pub fn sections(&self) -> impl Iterator<Item = &Section> + '_ {
        self.stages.iter().map(|s| &s.c)
    }

    /// Filters one sample.
    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        self.stages.iter_mut().fold(x, |v, s| s.tick(v))
    }

    /// Filters a block: `y[i]` from `x[i]` for `i < min(x.len(), y.len())`.
    pub fn process(&mut self, x: &[f64], y: &mut [f64]) {
        let n = x.len().min(y.len());
        let y = &mut y[..n];
        y.copy_from_slice(&x[..n]);
        self.run::<false>(y);
    }

    /// Filters a block in place, `y[0]` first.
    pub fn process_in_place(&mut self, y: &mut [f64]) {
        self.run::<false>(y);
    }

    /// Filters a block in place from its last sample to its first (the
    /// filter run backwards in time, as an adjoint needs it).
    pub fn process_reversed_in_place(&mut self, y: &mut [f64]) {
        self.run::<true>(y);
    }

    /// The block, two sections at a time over all of it (module
    /// documentation), in time order or reversed.
    fn run<const REVERSED: bool>(&mut self, y: &mut [f64]) {
        let mut pairs = self.stages.chunks_exact_mut(2);
        for pair in &mut pairs {
            let [a, b] = pair else { unreachable!("chunks of two") };
            each::<REVERSED>(y, |v| b.tick(a.tick(v)));
        }
        for s in pairs.into_remainder() {
            each::<REVERSED>(y, |v| s.tick(v));
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        for s in &mut self.stages {
            s.s1 = 0.0;
            s.s2 = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::design::{butterworth, ideal_power, Kind};
    use super::*;
    use std::f64::consts::PI;

    /// Direct-form difference equation of one section, the textbook way,
    /// as an independent reference for the transposed form.
    fn direct_form(c: &Section, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for n in 0..x.len() {
            let xm = |k: usize| if n >= k { x[n - k] } else { 0.0 };
            let ym = |y: &[f64], k: usize| if n >= k { y[n - k] } else { 0.0 };
            y[n] = c.b[0] * xm(0) + c.b[1] * xm(1) + c.b[2] * xm(2) - c.a[0] * ym(&y, 1) - c.a[1] * ym(&y, 2);
        }
        y
    }

    #[test]
    fn matches_the_difference_equation() {
        let x: Vec<f64> = (0..500).map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0).collect();
        let sections = butterworth(Kind::Lowpass, 5, 30.0, 1000.0).unwrap();
        let mut want = x.clone();
        for c in &sections {
            want = direct_form(c, &want);
        }
        let mut y = vec![0.0; x.len()];
        Cascade::new(&sections).process(&x, &mut y);
        for (a, b) in y.iter().zip(&want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn block_and_sample_by_sample_are_identical() {
        let x: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.37).sin() + 0.3 * (i as f64 * 2.1).cos()).collect();
        for kind in [Kind::Lowpass, Kind::Highpass] {
            let sections = butterworth(kind, 7, 120.0, 1000.0).unwrap();
            let mut a = Cascade::new(&sections);
            let one: Vec<f64> = x.iter().map(|&v| a.tick(v)).collect();
            let mut b = Cascade::new(&sections);
            let mut blocks = vec![0.0; x.len()];
            let mut i = 0;
            for len in [1usize, 63, 200, 7, 729] {
                b.process(&x[i..i + len], &mut blocks[i..i + len]);
                i += len;
            }
            assert_eq!(one, blocks);
            // In place, forwards and backwards in time.
            let mut c = Cascade::new(&sections);
            let mut inplace = x.clone();
            c.process_in_place(&mut inplace);
            assert_eq!(one, inplace);
            let mut d = Cascade::new(&sections);
            let mut back: Vec<f64> = x.iter().rev().map(|&v| d.tick(v)).collect();
            back.reverse();
            let mut e = Cascade::new(&sections);
            let mut reversed = x.clone();
            e.process_reversed_in_place(&mut reversed);
            assert_eq!(back, reversed);
        }
    }

    /// Impulse responses at the extreme cut-offs (0.01 Hz and 499 Hz at 1 kHz)
    /// for every order: finite, and decayed by the time the slowest pole
    /// predicts (|p|ⁿ < 1e-4, checked over the final stretch).
    #[test]
    fn impulse_responses_decay_at_extreme_cutoffs() {
        for fc in [0.01, 499.0] {
            for kind in [Kind::Lowpass, Kind::Highpass] {
                for order in 1..=8 {
                    let sections = butterworth(kind, order, fc, 1000.0).unwrap();
                    let r = sections.iter().map(Section::pole_radius).fold(0.0, f64::max);
                    // Samples until the slowest mode is below 1e-4 of its start,
                    // plus room for the polynomial factor of near-equal poles.
                    let n = ((1e-4f64).ln() / r.ln()).ceil() as usize * 2 + 64;
                    let mut c = Cascade::new(&sections);
                    let mut peak = 0.0f64;
                    let mut tail = 0.0f64;
                    for i in 0..n {
                        let h = c.tick(if i == 0 { 1.0 } else { 0.0 });
                        assert!(h.is_finite(), "{kind:?} N={order} fc={fc}: h[{i}] = {h}");
                        peak = peak.max(h.abs());
                        if i >= n - n / 8 {
                            tail = tail.max(h.abs());
                        }
                    }
                    assert!(tail < 1e-4 * peak, "{kind:?} N={order} fc={fc}: tail {tail:e}, peak {peak:e}");
                }
            }
        }
    }

    /// Pass-band gain measured on the running cascade: a constant input
    /// settles to the same constant (low-pass), an alternating ±1 input
    /// settles to ±1 (high-pass); the opposite input is removed.
    #[test]
    fn running_passband_gain_is_one_at_extreme_cutoffs() {
        for order in 1..=8 {
            // 499 Hz at 1 kHz: fast poles, so a short run settles.
            for kind in [Kind::Lowpass, Kind::Highpass] {
                let sections = butterworth(kind, order, 499.0, 1000.0).unwrap();
                let mut c = Cascade::new(&sections);
                let nyq = |i: usize| if i & 1 == 0 { 1.0 } else { -1.0 };
                let mut last = (0.0, 0.0);
                for i in 0..20_000 {
                    let x = match kind {
                        Kind::Lowpass => 1.0,
                        Kind::Highpass => nyq(i),
                    };
                    let y = c.tick(x);
                    assert!(y.is_finite() && y.abs() < 10.0);
                    last = (x, y);
                }
                assert!((last.1 - last.0).abs() < 1e-9, "{kind:?} N={order}: {last:?}");
            }
            // 0.01 Hz high-pass: Nyquist passes. The first sample is halved so
            // the input has no DC content (its z-transform vanishes at z = 1)
            // and does not excite the slow poles near z = 1.
            let sections = butterworth(Kind::Highpass, order, 0.01, 1000.0).unwrap();
            let mut c = Cascade::new(&sections);
            let mut y = 0.0;
            for i in 0..2000 {
                let x = if i == 0 {
                    0.5
                } else if i % 2 == 0 {
                    1.0
                } else {
                    -1.0
                };
                y = c.tick(x);
            }
            assert!((y.abs() - 1.0).abs() < 1e-6, "HP N={order} 0.01 Hz at Nyquist: {y}");
        }
    }

    /// Steady-state amplitude of a long sine against the analytic response.
    #[test]
    fn steady_state_sine_amplitude() {
        let fs = 1000.0;
        for (kind, order, fc) in [(Kind::Lowpass, 4, 100.0), (Kind::Highpass, 3, 10.0), (Kind::Lowpass, 8, 40.0)] {
            let sections = butterworth(kind, order, fc, fs).unwrap();
            // Periods of whole numbers of samples.
            for f in [5.0, 10.0, 20.0, 40.0, 50.0, 100.0, 200.0] {
                let mut c = Cascade::new(&sections);
                let w = 2.0 * PI * f / fs;
                let n = 6000;
                let y: Vec<f64> = (0..n).map(|i| c.tick((w * i as f64).sin())).collect();
                // Project the last 2000 samples (a whole number of periods) on sin and cos.
                let (mut s, mut co) = (0.0, 0.0);
                for (i, v) in y.iter().enumerate().skip(n - 2000) {
                    s += v * (w * i as f64).sin();
                    co += v * (w * i as f64).cos();
                }
                let amp = (s * s + co * co).sqrt() * 2.0 / 2000.0;
                let want = ideal_power(kind, order, fc, fs, f).sqrt();
                assert!(
                    (amp - want).abs() < 1e-9 * want.max(1e-3),
                    "{kind:?} N={order} fc={fc} f={f}: {amp} vs {want}"
                );
            }
        }
    }

    #[test]
    fn reset_returns_to_rest() {
        let sections = butterworth(Kind::Highpass, 6, 50.0, 1000.0).unwrap();
        let x: Vec<f64> = (0..300).map(|i| (i as f64 * 0.05).sin()).collect();
        let mut c = Cascade::new(&sections);
        let mut first = vec![0.0; x.len()];
        c.process(&x, &mut first);
        c.reset();
        let mut second = vec![0.0; x.len()];
        c.process(&x, &mut second);
        assert_eq!(first, second);
    }
}
