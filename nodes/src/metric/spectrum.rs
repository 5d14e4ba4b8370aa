//! The averaged one-sided magnitude spectrum that E_s compares (dissertation
//! §5.2.3), also used by reports and plots.
//!
//! A signal is cut into segments of `nfft` samples whose starts are
//! `hop = nfft − round(overlap · nfft)` samples apart (at least 1). Each
//! segment is multiplied by the window and transformed with rustfft; the
//! spectrum is the mean over segments of |X_k| for k = 0 ..= nfft/2 (the
//! one-sided spectrum of a real signal) — Welch's method, but averaging
//! magnitudes as well as powers.
//!
//! Scaling: X_k = Σ_n w\[n\] x\[n\] e^{−2πi·kn/N}, the raw DFT sum, not rescaled.
//! A sine of amplitude A at bin k₀ reads A·N/2 with the rectangular window
//! (A·Σw/2 in general); Parseval reads Σ_n (w\[n\] x\[n\])² = (1/N) Σ_k |X_k|²
//! over the two-sided spectrum ([`Spectrum::segment_energy`]).
//!
//! Samples after the last complete segment are not used, as in Welch's
//! method ([`Spectrum::trailing`] counts them). A signal shorter than `nfft`
//! is windowed over its own length and zero-padded to one segment.
//!
//! [`SpectrumAccumulator`] takes the signal block by block without
//! allocating (FFT plan, buffers and scratch are made in its constructor);
//! the result does not depend on how the samples were split into blocks.

use rustfft::num_complex::Complex;
use rustfft::Fft;
use std::f64::consts::PI;
use std::sync::Arc;

/// Bins below this fraction of a spectrum's largest bin are at the FFT's
/// rounding level (relative error ≈ 1e-16·log₂N) and count as zero: a
/// constant's spectrum, for instance, is not exactly zero outside 0 Hz.
pub const ROUNDING_LEVEL: f64 = 1e-10;

/// The window applied to each segment before the FFT.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    /// Rectangular (no window): w\[n\] = 1.
    Rect,
    /// Periodic Hann: w\[n\] = 0.5 − 0.5·cos(2πn/L), n = 0 … L−1 (the
    /// spectral-analysis form, as scipy's `welch`); w = 1 for L = 1.
    Hann,
}

impl Window {
    /// The window named `rect` or `hann`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "rect" => Some(Window::Rect),
            "hann" => Some(Window::Hann),
            _ => None,
        }
    }

    /// The window's name as written in graph files.
    pub fn name(self) -> &'static str {
        match self {
            Window::Rect => "rect",
            Window::Hann => "hann",
        }
    }

    /// The `len` coefficients of the window.
    pub fn coefficients(self, len: usize) -> Vec<f64> {
        match self {
            Window::Rect => vec![1.0; len],
            Window::Hann if len == 1 => vec![1.0],
            Window::Hann => (0..len).map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / len as f64).cos()).collect(),
        }
    }
}

/// How a spectrum is estimated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumConfig {
    /// Sampling rate in Hz (sets the bin width rate / nfft).
    pub rate: f64,
    /// FFT length (segment length) in samples, at least 1.
    pub nfft: usize,
    /// Window applied to each segment.
    pub window: Window,
    /// Fraction of a segment shared with the next one, in [0, 1).
    pub overlap: f64,
}

/// A [`SpectrumConfig`] that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// The FFT length is zero.
    #[error("the FFT length must be at least 1 sample")]
    ZeroLength,
    /// The overlap is outside [0, 1).
    #[error("the overlap must be a fraction in [0, 1), not {0}")]
    Overlap(f64),
    /// The rate is not a positive finite number.
    #[error("the sampling rate must be a positive number of Hz, not {0}")]
    Rate(f64),
}

impl SpectrumConfig {
    /// Checks the configuration.
    pub fn validate(&self) -> Result<(), SpectrumError> {
        if self.nfft == 0 {
            return Err(SpectrumError::ZeroLength);
        }
        if !(0.0..1.0).contains(&self.overlap) {
            return Err(SpectrumError::Overlap(self.overlap));
        }
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(SpectrumError::Rate(self.rate));
        }
        Ok(())
    }

    /// Samples between the starts of consecutive segments:
    /// nfft − round(overlap · nfft), at least 1.
    pub fn hop(&self) -> usize {
        let shared = (self.overlap * self.nfft as f64).round() as usize;
        self.nfft.saturating_sub(shared).max(1)
    }

    /// Number of one-sided bins, nfft/2 + 1 (0 Hz to Nyquist).
    pub fn bins(&self) -> usize {
        self.nfft / 2 + 1
    }

    /// Width of one bin in Hz, rate / nfft.
    pub fn bin_hz(&self) -> f64 {
        self.rate / self.nfft as f64
    }
}

/// An averaged one-sided spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// Mean over segments of |X_k|, k = 0 ..= nfft/2.
    pub magnitude: Vec<f64>,
    /// Mean over segments of |X_k|² (Welch's power spectrum, unscaled).
    pub power: Vec<f64>,
    /// Sampling rate in Hz.
    pub rate: f64,
    /// FFT length.
    pub nfft: usize,
    /// Segments averaged (1 for a zero-padded short signal).
    pub segments: u64,
    /// Samples received.
    pub samples: u64,
    /// Samples after the last complete segment, not used.
    pub trailing: u64,
    /// Σ w\[n\] of the window used (of the signal's length when zero-padded).
    pub window_sum: f64,
    /// Σ w\[n\]² of the window used.
    pub window_sq_sum: f64,
}

impl Spectrum {
    /// Width of one bin in Hz.
    pub fn bin_hz(&self) -> f64 {
        self.rate / self.nfft as f64
    }

    /// Frequency of bin `k` in Hz.
    pub fn freq(&self, k: usize) -> f64 {
        k as f64 * self.rate / self.nfft as f64
    }

    /// The mean energy of one windowed segment from the spectrum by
    /// Parseval: (1/N)·Σ over all N two-sided bins of the mean |X_k|²
    /// (bins other than 0 Hz and Nyquist counted twice).
    pub fn segment_energy(&self) -> f64 {
        let n = self.nfft;
        let total: f64 =
            self.power.iter().enumerate().map(|(k, p)| if k == 0 || 2 * k == n { *p } else { 2.0 * p }).sum();
        total / n as f64
    }

    /// The bin of the largest peak of the magnitude spectrum among bins
    /// `first ..= last`, never 0 Hz: a peak is a bin larger than its lower
    /// neighbour and not smaller than its upper one (so leakage sloping down
    /// from a large mean is not a peak), and above the rounding level
    /// ([`ROUNDING_LEVEL`] of the largest bin). `None` when there is no peak.
    pub fn largest_peak(&self, first: usize, last: usize) -> Option<usize> {
        let m = &self.magnitude;
        let floor = ROUNDING_LEVEL * m.iter().fold(0.0f64, |a, x| a.max(*x));
        let last = last.min(m.len().saturating_sub(1));
        let mut best: Option<usize> = None;
        for k in first.max(1)..=last {
            let rises = m[k] > m[k - 1] && m[k] > floor;
            let holds = m.get(k + 1).is_none_or(|&up| m[k] >= up);
            if rises && holds && best.is_none_or(|b| m[k] > m[b]) {
                best = Some(k);
            }
        }
        best
    }
}

/// Accumulates the averaged spectrum of a signal arriving block by block.
pub struct SpectrumAccumulator {
    cfg: SpectrumConfig,
    hop: usize,
    window: Vec<f64>,
    fft: Arc<dyn Fft<f64>>,
    segment: Vec<f64>,
    fill: usize,
    buffer: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    mag_sum: Vec<f64>,
    pow_sum: Vec<f64>,
    segments: u64,
    samples: u64,
}

impl std::fmt::Debug for SpectrumAccumulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpectrumAccumulator")
            .field("cfg", &self.cfg)
            .field("segments", &self.segments)
            .field("samples", &self.samples)
            .finish()
    }
}

impl SpectrumAccumulator {
    /// Plans the FFT and allocates every buffer.
    pub fn new(cfg: SpectrumConfig) -> Result<Self, SpectrumError> {
        cfg.validate()?;
        let n = cfg.nfft;
        let fft = evflow_dsp::fft::forward(n);
        let scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        Ok(Self {
            cfg,
            hop: cfg.hop(),
            window: cfg.window.coefficients(n),
            fft,
            segment: vec![0.0; n],
            fill: 0,
            buffer: vec![Complex::new(0.0, 0.0); n],
            scratch,
            mag_sum: vec![0.0; cfg.bins()],
            pow_sum: vec![0.0; cfg.bins()],
            segments: 0,
            samples: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SpectrumConfig {
        &self.cfg
    }

    /// Samples received so far.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Complete segments transformed so far.
    pub fn segments(&self) -> u64 {
        self.segments
    }

    /// Takes the next samples. Does not allocate.
    pub fn push(&mut self, mut x: &[f64]) {
        let n = self.cfg.nfft;
        while !x.is_empty() {
            let take = (n - self.fill).min(x.len());
            self.segment[self.fill..self.fill + take].copy_from_slice(&x[..take]);
            self.fill += take;
            self.samples += take as u64;
            x = &x[take..];
            if self.fill == n {
                transform(
                    self.fft.as_ref(),
                    &self.segment,
                    &self.window,
                    &mut self.buffer,
                    &mut self.scratch,
                    &mut self.mag_sum,
                    &mut self.pow_sum,
                );
                self.segments += 1;
                self.segment.copy_within(self.hop.., 0);
                self.fill = n - self.hop;
            }
        }
    }

    /// Back to no samples.
    pub fn reset(&mut self) {
        self.fill = 0;
        self.samples = 0;
        self.segments = 0;
        self.mag_sum.fill(0.0);
        self.pow_sum.fill(0.0);
    }

    /// The averaged spectrum of the samples so far; `None` before the first
    /// sample. Allocates (the result, and for a signal shorter than one
    /// segment its zero-padded transform).
    pub fn spectrum(&self) -> Option<Spectrum> {
        if self.samples == 0 {
            return None;
        }
        let n = self.cfg.nfft;
        let bins = self.cfg.bins();
        let (magnitude, power, segments, trailing, window) = if self.segments == 0 {
            // Shorter than one segment: window over its own length, zero-pad.
            let window = self.cfg.window.coefficients(self.fill);
            let mut buffer = vec![Complex::new(0.0, 0.0); n];
            let mut scratch = vec![Complex::new(0.0, 0.0); self.scratch.len()];
            let mut mag = vec![0.0; bins];
            let mut pow = vec![0.0; bins];
            let fft = self.fft.as_ref();
            transform(fft, &self.segment[..self.fill], &window, &mut buffer, &mut scratch, &mut mag, &mut pow);
            (mag, pow, 1, 0, window)
        } else {
            let s = self.segments as f64;
            let mag = self.mag_sum.iter().map(|m| m / s).collect();
            let pow = self.pow_sum.iter().map(|p| p / s).collect();
            let trailing = (self.fill - (n - self.hop)) as u64;
            (mag, pow, self.segments, trailing, self.window.clone())
        };
        Some(Spectrum {
            magnitude,
            power,
            rate: self.cfg.rate,
            nfft: n,
            segments,
            samples: self.samples,
            trailing,
            window_sum: window.iter().sum(),
            window_sq_sum: window.iter().map(|w| w * w).sum(),
        })
    }
}

/// Transforms one windowed, zero-padded segment and adds |X_k| and |X_k|²
/// of the one-sided bins to the sums. `seg` and `window` have equal length
/// ≤ `buffer.len()`.
fn transform(
    fft: &dyn Fft<f64>,
    seg: &[f64],
    window: &[f64],
    buffer: &mut [Complex<f64>],
    scratch: &mut [Complex<f64>],
    mag_sum: &mut [f64],
    pow_sum: &mut [f64],
) {
    for (i, b) in buffer.iter_mut().enumerate() {
        let x = match (seg.get(i), window.get(i)) {
            (Some(x), Some(w)) => x * w,
            _ => 0.0,
        };
        *b = Complex::new(x, 0.0);
    }
    fft.process_with_scratch(buffer, scratch);
    for ((b, m), p) in buffer.iter().zip(mag_sum.iter_mut()).zip(pow_sum.iter_mut()) {
        let a = b.norm();
        *m += a;
        *p += a * a;
    }
}

/// The averaged spectrum of a whole signal at once (`None` when empty).
pub fn averaged_spectrum(x: &[f64], cfg: SpectrumConfig) -> Result<Option<Spectrum>, SpectrumError> {
    let mut acc = SpectrumAccumulator::new(cfg)?;
    acc.push(x);
    Ok(acc.spectrum())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Seeded standard normal samples (SplitMix64 + Box–Muller), so the
    /// tests need no RNG crate and are reproducible.
    pub(crate) fn gaussian(seed: u64, n: usize) -> Vec<f64> {
        let mut s = seed;
        let mut uniform = move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n).map(|_| (-2.0 * uniform().ln()).sqrt() * (2.0 * PI * uniform()).cos()).collect()
    }

    /// A sine of amplitude `a` at `bins` cycles per `nfft` samples.
    pub(crate) fn sine(a: f64, bins: f64, nfft: usize, len: usize) -> Vec<f64> {
        (0..len).map(|i| a * (2.0 * PI * bins * i as f64 / nfft as f64).sin()).collect()
    }

    fn cfg(nfft: usize, window: Window, overlap: f64) -> SpectrumConfig {
        SpectrumConfig { rate: 1000.0, nfft, window, overlap }
    }

    fn spectrum(x: &[f64], c: SpectrumConfig) -> Spectrum {
        averaged_spectrum(x, c).unwrap().unwrap()
    }

    /// Textbook O(N²) DFT magnitudes of one zero-padded segment: the
    /// independent reference for the FFT path.
    fn naive_dft_magnitude(seg: &[f64], nfft: usize) -> Vec<f64> {
        (0..=nfft / 2)
            .map(|k| {
                let (mut re, mut im) = (0.0, 0.0);
                for (i, x) in seg.iter().enumerate() {
                    let ph = -2.0 * PI * (k * i % nfft) as f64 / nfft as f64;
                    re += x * ph.cos();
                    im += x * ph.sin();
                }
                re.hypot(im)
            })
            .collect()
    }

    #[test]
    fn sine_on_a_bin_reads_a_times_nfft_over_two_in_that_bin_only() {
        // Analytic: Σ_n A sin(2π k0 n/N) e^{−2πi kn/N} = ∓i·A·N/2 at k = ±k0, 0 elsewhere.
        let (a, nfft, k0) = (0.37, 1000, 37);
        for segments in [1, 3] {
            let s = spectrum(&sine(a, k0 as f64, nfft, segments * nfft), cfg(nfft, Window::Rect, 0.0));
            assert_eq!(s.segments, segments as u64);
            assert_eq!(s.magnitude.len(), nfft / 2 + 1);
            for (k, m) in s.magnitude.iter().enumerate() {
                let expected = if k == k0 { a * nfft as f64 / 2.0 } else { 0.0 };
                assert!((m - expected).abs() < 1e-10, "bin {k}: {m} vs {expected}");
            }
            assert_eq!(s.largest_peak(0, 500), Some(k0));
            assert_eq!(s.freq(k0), 37.0);
        }
    }

    #[test]
    fn hann_sine_reads_quarter_and_eighth_of_nfft() {
        // Periodic Hann = 1/2 − (e^{iθ} + e^{−iθ})/4: a sine at bin k0 reads
        // A·N/4 at k0 and A·N/8 at k0 ± 1, 0 elsewhere (A·Σw/2 with Σw = N/2).
        let (a, nfft, k0) = (2.0, 256, 40);
        let s = spectrum(&sine(a, k0 as f64, nfft, 4 * nfft), cfg(nfft, Window::Hann, 0.5));
        assert_eq!(s.segments, 7);
        assert!((s.window_sum - nfft as f64 / 2.0).abs() < 1e-9);
        assert!((s.window_sq_sum - 3.0 * nfft as f64 / 8.0).abs() < 1e-9);
        for (k, m) in s.magnitude.iter().enumerate() {
            let expected = match k.abs_diff(k0) {
                0 => a * nfft as f64 / 4.0,
                1 => a * nfft as f64 / 8.0,
                _ => 0.0,
            };
            assert!((m - expected).abs() < 1e-9, "bin {k}: {m} vs {expected}");
        }
    }

    #[test]
    fn averaged_overlapping_hann_matches_a_naive_dft_reference() {
        let (nfft, overlap) = (60, 0.3);
        let c = cfg(nfft, Window::Hann, overlap);
        let hop = c.hop();
        assert_eq!(hop, 42); // 60 − round(18)
        let x: Vec<f64> = gaussian(7, 500).iter().enumerate().map(|(i, g)| g + 0.01 * i as f64).collect();
        let s = spectrum(&x, c);
        let w = Window::Hann.coefficients(nfft);
        let starts: Vec<usize> = (0..).map(|j| j * hop).take_while(|st| st + nfft <= x.len()).collect();
        assert_eq!(s.segments, starts.len() as u64);
        assert_eq!(s.trailing, (x.len() - (starts.last().unwrap() + nfft)) as u64);
        let mut mean = vec![0.0; nfft / 2 + 1];
        for st in &starts {
            let seg: Vec<f64> = x[*st..st + nfft].iter().zip(&w).map(|(x, w)| x * w).collect();
            for (m, d) in mean.iter_mut().zip(naive_dft_magnitude(&seg, nfft)) {
                *m += d / starts.len() as f64;
            }
        }
        for (k, (m, r)) in s.magnitude.iter().zip(&mean).enumerate() {
            assert!((m - r).abs() < 1e-9 * (1.0 + r), "bin {k}: {m} vs {r}");
        }
    }

    #[test]
    fn white_noise_magnitude_matches_the_rayleigh_mean() {
        // For white noise of variance σ² and a rectangular window, each bin
        // 0 < k < N/2 is X_k = Σ x_n e^{−2πi kn/N}: complex Gaussian with
        // independent real and imaginary parts of variance N·σ²/2 each, so
        // |X_k| is Rayleigh with scale² = N·σ²/2 and mean
        // scale·√(π/2) = √(π/4 · N · σ²). With a window the variance per part
        // is σ²·Σw²/2, giving √(π/4 · σ² · Σw²). The mean over M segments and
        // K bins has a relative standard deviation √((4−π)/π)/√(MK) ≈ 0.52/√(MK)
        // (≈ 0.5 % here); the tolerance is 3 %. The mean power is N·σ²
        // (resp. σ²·Σw²) with relative deviation 1/√(MK).
        let (nfft, sigma) = (500, 0.3);
        let x: Vec<f64> = gaussian(42, 40 * nfft).iter().map(|g| sigma * g).collect();
        for window in [Window::Rect, Window::Hann] {
            let s = spectrum(&x, cfg(nfft, window, 0.0));
            let inner = &s.magnitude[1..nfft / 2];
            let mean_mag = inner.iter().sum::<f64>() / inner.len() as f64;
            let theory = (PI / 4.0 * sigma * sigma * s.window_sq_sum).sqrt();
            assert!((mean_mag / theory - 1.0).abs() < 0.03, "{window:?}: {mean_mag} vs {theory}");
            let inner_p = &s.power[1..nfft / 2];
            let mean_pow = inner_p.iter().sum::<f64>() / inner_p.len() as f64;
            let theory_p = sigma * sigma * s.window_sq_sum;
            assert!((mean_pow / theory_p - 1.0).abs() < 0.05, "{window:?}: {mean_pow} vs {theory_p}");
        }
    }

    #[test]
    fn parseval_holds_for_one_and_many_segments() {
        // Σ_n (w x)² = (1/N) Σ_k |X_k|² per segment, hence for the mean over segments.
        let nfft = 128;
        let x: Vec<f64> = gaussian(3, 1000).iter().map(|g| 1.5 + g).collect();
        for (window, overlap) in [(Window::Rect, 0.0), (Window::Hann, 0.5), (Window::Rect, 0.9)] {
            let c = cfg(nfft, window, overlap);
            let s = spectrum(&x, c);
            let w = window.coefficients(nfft);
            let mut energy = 0.0;
            for j in 0..s.segments as usize {
                let st = j * c.hop();
                energy += x[st..st + nfft].iter().zip(&w).map(|(x, w)| (x * w).powi(2)).sum::<f64>();
            }
            energy /= s.segments as f64;
            assert!((s.segment_energy() / energy - 1.0).abs() < 1e-12, "{window:?} {overlap}");
        }
        // Odd length: no Nyquist bin.
        let s = spectrum(&x[..99], cfg(99, Window::Rect, 0.0));
        let energy: f64 = x[..99].iter().map(|x| x * x).sum();
        assert!((s.segment_energy() / energy - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_short_signal_is_zero_padded_to_one_segment() {
        // A constant 1 over L = 250 samples padded to N = 1000 is a boxcar:
        // |X_k| = |sin(π k L/N) / sin(π k/N)| (Dirichlet kernel), |X_0| = L.
        let (nfft, len) = (1000, 250);
        let s = spectrum(&vec![1.0; len], cfg(nfft, Window::Rect, 0.0));
        assert_eq!((s.segments, s.samples, s.trailing), (1, len as u64, 0));
        for (k, m) in s.magnitude.iter().enumerate() {
            let expected = if k == 0 {
                len as f64
            } else {
                let t = PI * k as f64 / nfft as f64;
                ((t * len as f64).sin() / t.sin()).abs()
            };
            assert!((m - expected).abs() < 1e-9, "bin {k}: {m} vs {expected}");
        }
        // Parseval still holds for the padded segment.
        assert!((s.segment_energy() - len as f64).abs() < 1e-9);
        // A Hann window is taken over the signal's own length.
        let x = gaussian(5, 77);
        let s = spectrum(&x, cfg(256, Window::Hann, 0.5));
        let w = Window::Hann.coefficients(77);
        let seg: Vec<f64> = x.iter().zip(&w).map(|(x, w)| x * w).collect();
        for (m, r) in s.magnitude.iter().zip(naive_dft_magnitude(&seg, 256)) {
            assert!((m - r).abs() < 1e-9);
        }
        // One sample: a flat spectrum at |x|, whatever the window.
        let s = spectrum(&[-2.5], cfg(16, Window::Hann, 0.0));
        assert!(s.magnitude.iter().all(|m| (m - 2.5).abs() < 1e-12));
    }

    #[test]
    fn block_splitting_does_not_change_a_bit() {
        let x = gaussian(11, 3001);
        let c = cfg(200, Window::Hann, 0.25);
        let whole = spectrum(&x, c);
        for chunk in [1, 7, 199, 200, 201, 4096] {
            let mut acc = SpectrumAccumulator::new(c).unwrap();
            for b in x.chunks(chunk) {
                acc.push(b);
            }
            assert_eq!(acc.spectrum().unwrap(), whole, "chunk {chunk}");
        }
        // Reset returns to an empty accumulator.
        let mut acc = SpectrumAccumulator::new(c).unwrap();
        acc.push(&x[..500]);
        acc.reset();
        assert!(acc.spectrum().is_none());
        acc.push(&x);
        assert_eq!(acc.spectrum().unwrap(), whole);
    }

    #[test]
    fn trailing_samples_are_counted_not_used() {
        let c = cfg(100, Window::Rect, 0.0);
        let s = spectrum(&gaussian(1, 366), c);
        assert_eq!((s.segments, s.samples, s.trailing), (3, 366, 66));
        let c = cfg(100, Window::Rect, 0.5);
        let s = spectrum(&gaussian(1, 366), c);
        assert_eq!((s.segments, s.trailing), (6, 16)); // starts 0, 50, …, 250; last ends at 350
    }

    #[test]
    fn peaks_ignore_dc_and_its_leakage() {
        // A large mean with a Hann window leaks into bin 1 (half of bin 0):
        // not a peak. The true peak is the sine at bin 9.
        let nfft = 64;
        let x: Vec<f64> = sine(0.1, 9.0, nfft, nfft).iter().map(|s| 100.0 + s).collect();
        let s = spectrum(&x, cfg(nfft, Window::Hann, 0.0));
        assert!(s.magnitude[1] > s.magnitude[9]);
        assert_eq!(s.largest_peak(0, nfft / 2), Some(9));
        // x[n] = rⁿ: |X_k| = |1 − r^N| / |1 − r·e^{−iθ_k}| falls monotonically
        // from 0 Hz to Nyquist, so it has no peak; a peak at Nyquist counts.
        let decay: Vec<f64> = (0..64).map(|i| 0.8f64.powi(i)).collect();
        assert_eq!(spectrum(&decay, cfg(nfft, Window::Rect, 0.0)).largest_peak(0, 32), None);
        // A constant: exact zeros or rounding noise outside 0 Hz, never a peak.
        for n in [64, 97, 1000] {
            assert_eq!(spectrum(&vec![2.5; 3 * n], cfg(n, Window::Rect, 0.0)).largest_peak(0, n / 2), None, "{n}");
        }
        let alt: Vec<f64> = (0..64).map(|i| if i % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert_eq!(spectrum(&alt, cfg(nfft, Window::Rect, 0.0)).largest_peak(0, 32), Some(32));
    }

    #[test]
    fn bad_configurations_are_refused() {
        assert_eq!(SpectrumAccumulator::new(cfg(0, Window::Rect, 0.0)).unwrap_err(), SpectrumError::ZeroLength);
        assert!(matches!(SpectrumAccumulator::new(cfg(8, Window::Rect, 1.0)), Err(SpectrumError::Overlap(_))));
        assert!(matches!(SpectrumAccumulator::new(cfg(8, Window::Rect, f64::NAN)), Err(SpectrumError::Overlap(_))));
        let bad_rate = SpectrumConfig { rate: 0.0, ..cfg(8, Window::Rect, 0.0) };
        assert!(matches!(SpectrumAccumulator::new(bad_rate), Err(SpectrumError::Rate(_))));
        assert_eq!(averaged_spectrum(&[], cfg(8, Window::Rect, 0.0)).unwrap(), None);
        // Extreme overlap on a tiny FFT still advances one sample at a time.
        assert_eq!(cfg(2, Window::Rect, 0.9).hop(), 1);
        assert_eq!(cfg(1, Window::Hann, 0.5).hop(), 1);
        assert_eq!(Window::from_name("hann"), Some(Window::Hann));
        assert_eq!(Window::from_name("rect").map(Window::name), Some("rect"));
        assert_eq!(Window::from_name("hamming"), None);
    }
}
