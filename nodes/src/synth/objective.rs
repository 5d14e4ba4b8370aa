//! What the optimized synthesis minimizes: the distance between the force
//! the forward model predicts for an actuation u — through the output
//! filter — and the real texture force, over the kept (constant-speed)
//! samples, plus the noise the actuation itself brings.
//!
//! * **time**: J = Σ_K (ŷ − f)² / Σ_K f²  — matching the force sample by
//!   sample (phase included), the real recording's waveform;
//! * **spectral**: J = E_s²(ŷ_K, f_K) with the `metric` node's spectra
//!   ([`super::spectral`]) — matching only what E_s compares;
//! * **expected**: J = E_s² of the spectra the display is expected to
//!   deliver — each bin's magnitude √(|Ŷ|² + (π/4)·P_k(p)), with the
//!   residual noise spectrum P_k(p) = p0_k + p·p1_k the forward model
//!   learned, p a segment's mean u². Where the display's own noise already
//!   exceeds the texture, rendering more there gains nothing and adds noise;
//!   this objective sees it, the others do not.
//!
//! **Noise weight.** A display's friction noise grows with the normal force
//! its actuation adds, so of two actuations that make the same force the
//! weaker one renders better. The forward model's noise model
//! (r² ≈ σ₀² + β·p, p the local mean of u²; [`super::volterra_fit`]) gives
//! the expected squared error of an actuation as Σ(ŷ − f)² + Σ(σ₀² + β·u²);
//! divided by Σ f² that is the time objective plus λ·mean_K(u²) with
//! λ = β / mean_K(f²) (the σ₀² part is a constant). The same term is added
//! to the spectral objective, where it is an approximation.
//!
//! The gradient is exact: ∂J/∂ŷ on the kept samples, through the filter's
//! adjoint, through the model ([`Volterra::eval_grad`]).

use super::output_filter::OutputFilter;
use super::spectral::{NoiseSpectrum, SpectralTarget};
use super::volterra::Volterra;

/// The distance measure.
pub enum Loss {
    /// Relative squared error over the kept samples.
    Time,
    /// E_s² of the kept samples' spectra.
    Spectral(Box<SpectralTarget>),
    /// E_s² of the spectra the display is expected to deliver: the model's
    /// force plus the residual noise, whose power grows with the actuation
    /// ([`super::spectral::SpectralTarget::value_grad_noisy`]). The noise
    /// weight λ is not added: the noise is in the spectra.
    Expected(Box<SpectralTarget>, NoiseSpectrum),
}

/// The objective of one synthesis.
pub struct Objective<'a> {
    model: &'a Volterra,
    filter: &'a OutputFilter,
    target: &'a [f64],
    kept: Vec<usize>,
    loss: Loss,
    lambda: f64,
    norm: f64,
    y: Vec<f64>,
    ybar: Vec<f64>,
    yk: Vec<f64>,
    gk: Vec<f64>,
    pk: Vec<f64>,
    gpk: Vec<f64>,
}

impl<'a> Objective<'a> {
    /// The objective for the real force `target` (whole recording) on the
    /// samples where `keep` is set, through `model` and `filter`, with noise
    /// weight `lambda`.
    pub fn new(
        model: &'a Volterra,
        filter: &'a OutputFilter,
        target: &'a [f64],
        keep: &[bool],
        loss: Loss,
        lambda: f64,
    ) -> Self {
        let kept: Vec<usize> = (0..target.len()).filter(|&n| keep[n]).collect();
        let norm = kept.iter().map(|&n| target[n] * target[n]).sum::<f64>().max(f64::MIN_POSITIVE);
        let n = target.len();
        Self {
            model,
            filter,
            target,
            loss,
            lambda,
            norm,
            y: vec![0.0; n],
            ybar: vec![0.0; n],
            yk: vec![0.0; kept.len()],
            gk: vec![0.0; kept.len()],
            pk: vec![0.0; kept.len()],
            gpk: vec![0.0; kept.len()],
            kept,
        }
    }

    /// The noise weight λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The model's force for `u`, filtered (the whole series).
    pub fn predict(&self, u: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; u.len()];
        self.model.eval(u, &mut y);
        self.filter.apply_in_place(&mut y);
        y
    }

    /// J(u), with ∂J/∂u written into `g`.
    pub fn value_grad(&mut self, u: &[f64], g: &mut [f64]) -> f64 {
        // Forward: y = T·V(u). The model pass is repeated in eval_grad with ȳ;
        // a first pass gets ŷ for the loss.
        self.model.eval(u, &mut self.y);
        self.filter.apply_in_place(&mut self.y);
        for (k, &n) in self.kept.iter().enumerate() {
            self.yk[k] = self.y[n];
        }
        let nk = self.kept.len().max(1) as f64;
        let mut j = match &mut self.loss {
            Loss::Time => {
                let mut s = 0.0;
                for (k, &n) in self.kept.iter().enumerate() {
                    let e = self.yk[k] - self.target[n];
                    s += e * e;
                    self.gk[k] = 2.0 * e / self.norm;
                }
                s / self.norm
            }
            Loss::Spectral(t) => t.value_grad(&self.yk, &mut self.gk),
            Loss::Expected(t, noise) => {
                for (k, &n) in self.kept.iter().enumerate() {
                    self.pk[k] = u[n] * u[n];
                }
                t.value_grad_noisy(&self.yk, &self.pk, noise, &mut self.gk, &mut self.gpk)
            }
        };
        self.ybar.iter_mut().for_each(|v| *v = 0.0);
        for (k, &n) in self.kept.iter().enumerate() {
            self.ybar[n] = self.gk[k];
        }
        self.filter.adjoint_in_place(&mut self.ybar);
        g.iter_mut().for_each(|v| *v = 0.0);
        self.model.eval_grad(u, &self.ybar, &mut self.y, g);
        if let Loss::Expected(..) = self.loss {
            for (k, &n) in self.kept.iter().enumerate() {
                g[n] += self.gpk[k] * 2.0 * u[n];
            }
        }
        if self.lambda > 0.0 {
            let mut p = 0.0;
            for &n in &self.kept {
                p += u[n] * u[n];
                g[n] += 2.0 * self.lambda * u[n] / nk;
            }
            j += self.lambda * p / nk;
        }
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::spectral_error::Band;
    use crate::metric::spectrum::{SpectrumConfig, Window};
    use crate::rng::Rng;

    fn check_gradient(make: &dyn Fn() -> Loss) {
        let mut r = Rng::new(7);
        let m = 4;
        let upper: Vec<f64> = (0..m * (m + 1) / 2).map(|_| r.gaussian()).collect();
        let model = Volterra::from_upper(&upper, (0..m).map(|_| r.gaussian()).collect(), 0.3).unwrap();
        let filter = OutputFilter::highpass(2, 5.0, 1000.0).unwrap();
        let n = 300;
        let target: Vec<f64> = (0..n).map(|k| (k as f64 * 0.2).sin()).collect();
        let keep: Vec<bool> = (0..n).map(|k| (40..280).contains(&k)).collect();
        let u: Vec<f64> = (0..n).map(|_| 0.5 * r.gaussian()).collect();
        let mut obj = Objective::new(&model, &filter, &target, &keep, make(), 0.2);
        let mut g = vec![0.0; n];
        obj.value_grad(&u, &mut g);
        let mut scratch = vec![0.0; n];
        let h = 1e-6;
        for k in [0, 10, 39, 40, 100, 279, 280, 299] {
            let (mut a, mut b) = (u.clone(), u.clone());
            a[k] += h;
            b[k] -= h;
            let fd = (obj.value_grad(&a, &mut scratch) - obj.value_grad(&b, &mut scratch)) / (2.0 * h);
            assert!((fd - g[k]).abs() < 1e-5 * (1.0 + fd.abs()), "u[{k}]: {} vs {fd}", g[k]);
        }
    }

    #[test]
    fn the_time_objective_gradient_matches_central_differences() {
        check_gradient(&|| Loss::Time);
    }

    #[test]
    fn the_expected_objective_gradient_matches_central_differences() {
        check_gradient(&|| {
            let target: Vec<f64> = (0..300).map(|k| (k as f64 * 0.2).sin()).collect();
            let kept: Vec<f64> = target[40..280].to_vec();
            let cfg = SpectrumConfig { rate: 1000.0, nfft: 100, window: Window::Hann, overlap: 0.5 };
            let band = Band::new(1000.0, 100, 20.0, 300.0, false).unwrap();
            let noise = NoiseSpectrum {
                nfft: 100,
                p0: (0..51).map(|k| 0.001 * (1.0 + k as f64 / 20.0)).collect(),
                p1: (0..51).map(|k| 0.003 / (1.0 + k as f64 / 5.0)).collect(),
            };
            Loss::Expected(Box::new(SpectralTarget::new(&kept, cfg, band).unwrap()), noise)
        });
    }

    #[test]
    fn the_spectral_objective_gradient_matches_central_differences() {
        check_gradient(&|| {
            let target: Vec<f64> = (0..300).map(|k| (k as f64 * 0.2).sin()).collect();
            let kept: Vec<f64> = target[40..280].to_vec();
            let cfg = SpectrumConfig { rate: 1000.0, nfft: 100, window: Window::Hann, overlap: 0.5 };
            let band = Band::new(1000.0, 100, 20.0, 300.0, false).unwrap();
            Loss::Spectral(Box::new(SpectralTarget::new(&kept, cfg, band).unwrap()))
        });
    }
}
