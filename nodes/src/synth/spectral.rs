//! E_s (dissertation Eq. 5.2) of a series against a fixed target spectrum,
//! with its gradient: the spectral objective of the synthesis and of the
//! achievable floor.
//!
//! The spectra are those of the `metric` node ([`crate::metric::spectrum`]):
//! segments of `nfft` samples `hop` apart, windowed, |X_k| averaged over
//! segments; E_s = ‖S − R‖/‖R‖ over the band's bins. With
//! X_{p,k} = Σ_n w_n x[s_p + n] e^{−2πikn/N} and S_k = (1/P) Σ_p |X_{p,k}|,
//!
//! ```text
//! ∂|X_{p,k}|/∂x[s_p + n] = w_n · Re( conj(X_{p,k})/|X_{p,k}| · e^{−2πikn/N} )
//! ```
//!
//! so the gradient of J = E_s² on segment p is
//! w_n · Re(DFT(c)\[n\]) / P with c_k = 2(S_k − R_k)/‖R‖² · conj(X_{p,k})/|X_{p,k}|
//! on the band's bins (0 elsewhere): one more FFT per segment. |X| is not
//! differentiable where X = 0; there the bin contributes no gradient.

use super::error::SynthError;
use crate::metric::spectral_error::Band;
use crate::metric::spectrum::{averaged_spectrum, SpectrumConfig, ROUNDING_LEVEL};
use rustfft::num_complex::Complex;
use rustfft::Fft;
use std::sync::Arc;

/// A noise power spectrum that grows with the actuation: the expected
/// |DFT|² of the noise in one windowed segment, per unit of window energy
/// Σw², at bin k when the segment's mean u² is p: P_k(p) = p0_k + p·p1_k
/// (k = 0 … nfft/2). Learned with the forward model
/// ([`super::volterra_fit`]).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct NoiseSpectrum {
    /// Segment length the spectrum was taken over (its bins are rate/nfft apart).
    pub nfft: usize,
    /// Noise power with no actuation, per bin.
    pub p0: Vec<f64>,
    /// Noise power added per unit of mean u², per bin.
    pub p1: Vec<f64>,
}

/// E|Y + N| ≈ √(|Y|² + (π/4)·E|N|²): the mean magnitude of a bin holding a
/// deterministic Y and circular Gaussian noise N — exact at Y = 0 (the
/// Rayleigh mean √(π/4·E|N|²)) and to first order in E|N|²/|Y|² for a
/// strong Y.
pub const RICE: f64 = std::f64::consts::FRAC_PI_4;

/// One segment's window, FFT plan and buffers.
struct SegmentFft {
    window: Vec<f64>,
    fft: Arc<dyn Fft<f64>>,
    buf: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

impl SegmentFft {
    /// The windowed segment of `v` starting at `start`, transformed into `buf`.
    fn transform(&mut self, v: &[f64], start: usize) {
        for (b, (w, x)) in self.buf.iter_mut().zip(self.window.iter().zip(&v[start..])) {
            *b = Complex::new(w * x, 0.0);
        }
        self.fft.process_with_scratch(&mut self.buf, &mut self.scratch);
    }
}

/// A target spectrum and the machinery to score series against it.
pub struct SpectralTarget {
    cfg: SpectrumConfig,
    band: Band,
    len: usize,
    /// Target magnitudes on the band's bins.
    r: Vec<f64>,
    r_norm2: f64,
    seg: SegmentFft,
    /// Per segment, X on the band's bins and |X| (kept from the forward pass).
    x: Vec<Complex<f64>>,
    mag: Vec<f64>,
    /// The forward pass's mean magnitudes S on the band's bins.
    s: Vec<f64>,
    starts: Vec<usize>,
}

impl std::fmt::Debug for SpectralTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpectralTarget")
            .field("cfg", &self.cfg)
            .field("band", &self.band)
            .field("len", &self.len)
            .finish()
    }
}

impl SpectralTarget {
    /// The target `real` (the kept samples, concatenated) scored in `cfg`'s
    /// segments over `band`. Series scored later must have `real.len()` samples,
    /// at least one segment.
    pub fn new(real: &[f64], cfg: SpectrumConfig, band: Band) -> Result<Self, SynthError> {
        cfg.validate().map_err(|e| SynthError::Config(e.to_string()))?;
        let nfft = cfg.nfft;
        if real.len() < nfft {
            return Err(SynthError::Data(format!(
                "the target has {} kept samples, fewer than one spectral segment of {nfft}",
                real.len()
            )));
        }
        if band.last() > nfft / 2 {
            return Err(SynthError::Config("the band reaches past the Nyquist bin".into()));
        }
        let spec = averaged_spectrum(real, cfg)
            .map_err(|e| SynthError::Config(e.to_string()))?
            .ok_or_else(|| SynthError::Data("the target has no spectrum".into()))?;
        let r: Vec<f64> = band.bins().map(|k| spec.magnitude[k]).collect();
        let r_norm2: f64 = r.iter().map(|v| v * v).sum();
        let largest = spec.magnitude.iter().cloned().fold(0.0, f64::max);
        let in_band = r.iter().cloned().fold(0.0, f64::max);
        if !(r_norm2.is_finite() && in_band > ROUNDING_LEVEL * largest) {
            return Err(SynthError::Data("the target has no spectral energy in the band".into()));
        }
        let hop = cfg.hop();
        let starts: Vec<usize> = (0..).map(|p| p * hop).take_while(|s| s + nfft <= real.len()).collect();
        let fft = evflow_dsp::fft::forward(nfft);
        let scratch = vec![Complex::default(); fft.get_inplace_scratch_len()];
        Ok(Self {
            cfg,
            band,
            len: real.len(),
            r,
            r_norm2,
            seg: SegmentFft {
                window: cfg.window.coefficients(nfft),
                fft,
                buf: vec![Complex::default(); nfft],
                scratch,
            },
            x: vec![Complex::default(); starts.len() * band.len()],
            mag: vec![0.0; starts.len() * band.len()],
            s: vec![0.0; band.len()],
            starts,
        })
    }

    /// Samples a scored series must have.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True for a target without samples (never: [`SpectralTarget::new`] refuses it).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// E_s of `v` against the target.
    pub fn es(&mut self, v: &[f64]) -> f64 {
        self.forward(v).sqrt()
    }

    /// J = E_s² and its forward-pass spectra (X, |X| and S, kept).
    fn forward(&mut self, v: &[f64]) -> f64 {
        let (nb, first) = (self.band.len(), self.band.first());
        let p = self.starts.len() as f64;
        self.s.fill(0.0);
        for (seg, &start) in self.starts.iter().enumerate() {
            self.seg.transform(v, start);
            for (b, sb) in self.s.iter_mut().enumerate() {
                let xk = self.seg.buf[first + b];
                let mag = xk.norm();
                self.x[seg * nb + b] = xk;
                self.mag[seg * nb + b] = mag;
                *sb += mag / p;
            }
        }
        self.s.iter().zip(&self.r).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / self.r_norm2
    }

    /// J = E_s² of the spectrum `v` is expected to have once the noise of
    /// `noise` is added — each segment's magnitudes √(|X|² + RICE·P_k(p_seg)),
    /// p_seg the window-weighted mean of `p` (the actuation's u², per sample)
    /// over the segment — with ∂J/∂v in `gv` and ∂J/∂p in `gp`. The noise
    /// spectrum must have been taken with this target's nfft.
    pub fn value_grad_noisy(
        &mut self,
        v: &[f64],
        p: &[f64],
        noise: &NoiseSpectrum,
        gv: &mut [f64],
        gp: &mut [f64],
    ) -> f64 {
        let (nfft, nb, first) = (self.cfg.nfft, self.band.len(), self.band.first());
        let np = self.starts.len();
        let energy: f64 = self.seg.window.iter().map(|w| w * w).sum();
        let segp: Vec<f64> = self
            .starts
            .iter()
            .map(|&s| (0..nfft).map(|n| self.seg.window[n] * self.seg.window[n] * p[s + n]).sum::<f64>() / energy)
            .collect();
        // Forward: the expected magnitudes M, their mean S.
        let mut m = vec![0.0; np * nb];
        let mut s = vec![0.0; nb];
        for (seg, &start) in self.starts.iter().enumerate() {
            self.seg.transform(v, start);
            for (b, sb) in s.iter_mut().enumerate() {
                let k = first + b;
                let xk = self.seg.buf[k];
                self.x[seg * nb + b] = xk;
                let pn = energy * (noise.p0[k] + segp[seg] * noise.p1[k]).max(0.0);
                let mk = (xk.norm_sqr() + RICE * pn).sqrt();
                m[seg * nb + b] = mk;
                *sb += mk / np as f64;
            }
        }
        let j = s.iter().zip(&self.r).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / self.r_norm2;
        // Backward.
        gv.iter_mut().for_each(|x| *x = 0.0);
        gp.iter_mut().for_each(|x| *x = 0.0);
        for (seg, &start) in self.starts.iter().enumerate() {
            self.seg.buf.iter_mut().for_each(|c| *c = Complex::default());
            let mut dseg = 0.0;
            for (b, (sb, rb)) in s.iter().zip(&self.r).enumerate() {
                let mk = m[seg * nb + b];
                if mk > 0.0 {
                    let a = 2.0 * (sb - rb) / self.r_norm2 / np as f64;
                    self.seg.buf[first + b] = self.x[seg * nb + b].conj() * (a / mk);
                    dseg += a * RICE * energy * noise.p1[first + b] / (2.0 * mk);
                }
            }
            self.seg.fft.process_with_scratch(&mut self.seg.buf, &mut self.seg.scratch);
            for n in 0..nfft {
                gv[start + n] += self.seg.window[n] * self.seg.buf[n].re;
                gp[start + n] += dseg * self.seg.window[n] * self.seg.window[n] / energy;
            }
        }
        j
    }

    /// The target's segment configuration.
    pub fn config(&self) -> SpectrumConfig {
        self.cfg
    }

    /// J = E_s² of `v`, with ∂J/∂v written into `g` (same length).
    pub fn value_grad(&mut self, v: &[f64], g: &mut [f64]) -> f64 {
        let j = self.forward(v);
        let (nfft, nb, first) = (self.cfg.nfft, self.band.len(), self.band.first());
        let p = self.starts.len() as f64;
        g.iter_mut().for_each(|v| *v = 0.0);
        for (seg, &start) in self.starts.iter().enumerate() {
            self.seg.buf.iter_mut().for_each(|c| *c = Complex::default());
            for (b, (sb, rb)) in self.s.iter().zip(&self.r).enumerate() {
                let xk = self.x[seg * nb + b];
                let mag = self.mag[seg * nb + b];
                if mag > 0.0 {
                    let a = 2.0 * (sb - rb) / self.r_norm2;
                    self.seg.buf[first + b] = xk.conj() * (a / mag);
                }
            }
            self.seg.fft.process_with_scratch(&mut self.seg.buf, &mut self.seg.scratch);
            for n in 0..nfft {
                g[start + n] += self.seg.window[n] * self.seg.buf[n].re / p;
            }
        }
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::spectral_error::spectral_rms_error;
    use crate::metric::spectrum::Window;
    use crate::rng::Rng;

    fn series(n: usize, seed: u64) -> Vec<f64> {
        let mut r = Rng::new(seed);
        (0..n).map(|k| (k as f64 * 0.11).sin() + 0.3 * r.gaussian()).collect()
    }

    #[test]
    fn the_value_is_the_metric_nodes_e_s() {
        for (window, overlap) in [(Window::Rect, 0.0), (Window::Hann, 0.5)] {
            let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window, overlap };
            let band = Band::new(1000.0, 1000, 2.0, 200.0, false).unwrap();
            let (real, virt) = (series(2600, 1), series(2600, 2));
            let mut t = SpectralTarget::new(&real, cfg, band).unwrap();
            let sr = averaged_spectrum(&real, cfg).unwrap().unwrap();
            let sv = averaged_spectrum(&virt, cfg).unwrap().unwrap();
            let want = spectral_rms_error(&sv.magnitude, &sr.magnitude, &band).unwrap();
            assert!((t.es(&virt) - want).abs() < 1e-12, "{window:?}: {} vs {want}", t.es(&virt));
            assert!(t.es(&real) < 1e-12);
        }
    }

    #[test]
    fn the_gradient_matches_central_differences() {
        for (window, overlap) in [(Window::Rect, 0.0), (Window::Hann, 0.5)] {
            let cfg = SpectrumConfig { rate: 100.0, nfft: 64, window, overlap };
            let band = Band::new(100.0, 64, 3.0, 30.0, false).unwrap();
            let (real, virt) = (series(150, 3), series(150, 4));
            let mut t = SpectralTarget::new(&real, cfg, band).unwrap();
            let mut g = vec![0.0; 150];
            let j = t.value_grad(&virt, &mut g);
            assert!((j - t.es(&virt).powi(2)).abs() < 1e-14);
            let h = 1e-6;
            for k in [0, 5, 40, 63, 64, 100, 127, 128, 149] {
                let (mut a, mut b) = (virt.clone(), virt.clone());
                a[k] += h;
                b[k] -= h;
                let fd = (t.es(&a).powi(2) - t.es(&b).powi(2)) / (2.0 * h);
                assert!((fd - g[k]).abs() < 1e-6 * (1.0 + fd.abs()), "{window:?} x[{k}]: {} vs {fd}", g[k]);
            }
        }
    }

    #[test]
    fn the_noisy_gradient_matches_central_differences_and_no_noise_is_the_plain_objective() {
        let cfg = SpectrumConfig { rate: 100.0, nfft: 64, window: Window::Hann, overlap: 0.5 };
        let band = Band::new(100.0, 64, 3.0, 30.0, false).unwrap();
        let (real, virt) = (series(150, 3), series(150, 4));
        let mut t = SpectralTarget::new(&real, cfg, band).unwrap();
        let mut r = Rng::new(6);
        let p: Vec<f64> = (0..150).map(|_| r.uniform()).collect();
        let quiet = NoiseSpectrum { nfft: 64, p0: vec![0.0; 33], p1: vec![0.0; 33] };
        let (mut gv, mut gp, mut g) = (vec![0.0; 150], vec![0.0; 150], vec![0.0; 150]);
        let j0 = t.value_grad_noisy(&virt, &p, &quiet, &mut gv, &mut gp);
        let j1 = t.value_grad(&virt, &mut g);
        assert!((j0 - j1).abs() < 1e-14 && gv.iter().zip(&g).all(|(a, b)| (a - b).abs() < 1e-12));
        let noise = NoiseSpectrum {
            nfft: 64,
            p0: (0..33).map(|k| 0.01 * (1.0 + k as f64 / 10.0)).collect(),
            p1: (0..33).map(|k| 0.02 / (1.0 + k as f64)).collect(),
        };
        let j = t.value_grad_noisy(&virt, &p, &noise, &mut gv, &mut gp);
        assert!(j > 0.0);
        let f = |t: &mut SpectralTarget, v: &[f64], p: &[f64]| {
            let (mut a, mut b) = (vec![0.0; 150], vec![0.0; 150]);
            t.value_grad_noisy(v, p, &noise, &mut a, &mut b)
        };
        let h = 1e-6;
        for k in [0, 40, 63, 64, 100, 127, 149] {
            let (mut a, mut b) = (virt.clone(), virt.clone());
            a[k] += h;
            b[k] -= h;
            let fd = (f(&mut t, &a, &p) - f(&mut t, &b, &p)) / (2.0 * h);
            assert!((fd - gv[k]).abs() < 1e-6 * (1.0 + fd.abs()), "v[{k}]: {} vs {fd}", gv[k]);
            let (mut a, mut b) = (p.clone(), p.clone());
            a[k] += h;
            b[k] -= h;
            let fd = (f(&mut t, &virt, &a) - f(&mut t, &virt, &b)) / (2.0 * h);
            assert!((fd - gp[k]).abs() < 1e-6 * (1.0 + fd.abs()), "p[{k}]: {} vs {fd}", gp[k]);
        }
    }

    #[test]
    fn a_target_too_short_or_silent_in_the_band_is_refused() {
        let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window: Window::Rect, overlap: 0.0 };
        let band = Band::new(1000.0, 1000, 2.0, 200.0, false).unwrap();
        assert!(SpectralTarget::new(&[1.0; 500], cfg, band).is_err());
        assert!(SpectralTarget::new(&[1.0; 1500], cfg, band).is_err(), "a constant has no energy above 0 Hz");
    }
}
