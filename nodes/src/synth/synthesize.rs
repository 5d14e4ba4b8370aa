//! Optimized synthesis: the actuation that makes the forward model's force
//! closest to a real texture force, bounded to [−bound, bound], found by
//! projected L-BFGS ([`super::lbfgsb`]) from a given start, gradients by
//! backpropagation through the model and the output filter
//! ([`super::objective`]).

use super::error::SynthError;
use super::lbfgsb::{minimize, Options, Stop};
use super::model_file::ForwardModel;
use super::objective::{Loss, Objective};
use super::spectral::SpectralTarget;
use crate::metric::spectral_error::Band;
use crate::metric::spectrum::SpectrumConfig;
use std::time::Instant;

/// What the synthesis matches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObjectiveKind {
    /// The force sample by sample.
    Time,
    /// The spectra E_s compares (segments `cfg`, bins `band`).
    Spectral {
        /// Segments.
        cfg: SpectrumConfig,
        /// Bins.
        band: Band,
    },
    /// The spectra the display is expected to deliver, with the model's
    /// learned noise spectrum (segments `cfg` of the noise spectrum's
    /// length, bins `band`).
    Expected {
        /// Segments.
        cfg: SpectrumConfig,
        /// Bins.
        band: Band,
    },
}

/// How much the noise an actuation brings weighs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoiseWeight {
    /// λ = β / mean(f²) from the model's noise model.
    Learned,
    /// A given λ (0: ignore the noise).
    Fixed(f64),
}

/// Settings of [`synthesize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthConfig {
    /// What to match.
    pub objective: ObjectiveKind,
    /// The noise weight.
    pub noise: NoiseWeight,
    /// |u| ≤ bound.
    pub bound: f64,
    /// The optimizer's settings (its `max_iter` is the iteration budget).
    pub options: Options,
}

impl Default for SynthConfig {
    fn default() -> Self {
        Self {
            objective: ObjectiveKind::Time,
            noise: NoiseWeight::Learned,
            bound: 1.0,
            options: Options { max_iter: 100, ..Options::default() },
        }
    }
}

/// An optimized actuation and how it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct Synthesis {
    /// The actuation, one sample per target sample, within ±bound.
    pub u: Vec<f64>,
    /// The noise weight used.
    pub lambda: f64,
    /// J at the start.
    pub objective_start: f64,
    /// J at the end (never above the start).
    pub objective_end: f64,
    /// J after each iteration.
    pub history: Vec<f64>,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Why the optimizer stopped.
    pub stop: Stop,
    /// Wall-clock time, s.
    pub seconds: f64,
}

/// Synthesizes the actuation for the real force `target` (the whole
/// recording, as filtered as the model's training force) on the samples
/// where `keep` is set, through `model`, from `start`.
pub fn synthesize(
    model: &ForwardModel,
    target: &[f64],
    keep: &[bool],
    start: &[f64],
    cfg: &SynthConfig,
) -> Result<Synthesis, SynthError> {
    let t0 = Instant::now();
    let n = target.len();
    if keep.len() != n || start.len() != n {
        return Err(SynthError::Data(format!(
            "the target ({n}), gate ({}) and start ({}) have different lengths",
            keep.len(),
            start.len()
        )));
    }
    if let Some(i) = target.iter().position(|v| !v.is_finite()) {
        return Err(SynthError::Data(format!("the target force is not finite at sample {i}")));
    }
    if let Some(i) = start.iter().position(|v| !v.is_finite()) {
        return Err(SynthError::Data(format!("the start is not finite at sample {i}")));
    }
    if !(cfg.bound.is_finite() && cfg.bound > 0.0) {
        return Err(SynthError::Config(format!("the bound must be a positive number, not {}", cfg.bound)));
    }
    let kept: Vec<f64> = (0..n).filter(|&i| keep[i]).map(|i| target[i]).collect();
    if kept.is_empty() {
        return Err(SynthError::Data("no sample of the target is kept (is the gate ever open?)".into()));
    }
    let power = kept.iter().map(|v| v * v).sum::<f64>() / kept.len() as f64;
    if power <= 0.0 {
        return Err(SynthError::Data("the target force is zero on every kept sample".into()));
    }
    let lambda = match cfg.noise {
        NoiseWeight::Learned => model.noise.per_u2_n2 / power,
        NoiseWeight::Fixed(l) if l.is_finite() && l >= 0.0 => l,
        NoiseWeight::Fixed(l) => return Err(SynthError::Config(format!("the noise weight must be ≥ 0, not {l}"))),
    };
    let loss = match cfg.objective {
        ObjectiveKind::Time => Loss::Time,
        ObjectiveKind::Spectral { cfg, band } => Loss::Spectral(Box::new(SpectralTarget::new(&kept, cfg, band)?)),
        ObjectiveKind::Expected { cfg, band } => {
            let noise = model.noise_spectrum.clone().ok_or_else(|| {
                SynthError::Config(
                    "the forward model has no noise spectrum (its recording was shorter than three seconds of kept \
                     samples): use the time or spectral objective, or identify it on a longer recording"
                        .into(),
                )
            })?;
            if noise.nfft != cfg.nfft {
                return Err(SynthError::Config(format!(
                    "the model's noise spectrum has {}-sample segments, the objective {}",
                    noise.nfft, cfg.nfft
                )));
            }
            Loss::Expected(Box::new(SpectralTarget::new(&kept, cfg, band)?), noise)
        }
    };
    let lambda = if matches!(cfg.objective, ObjectiveKind::Expected { .. }) { 0.0 } else { lambda };
    let volterra = model.volterra()?;
    let filter = model.filter()?;
    let mut obj = Objective::new(&volterra, &filter, target, keep, loss, lambda);
    let mut f = |u: &[f64], g: &mut [f64]| obj.value_grad(u, g);
    let out = minimize(&mut f, start, -cfg.bound, cfg.bound, &cfg.options);
    Ok(Synthesis {
        u: out.x,
        lambda,
        objective_start: out.history[0],
        objective_end: out.f,
        history: out.history,
        evaluations: out.evaluations,
        stop: out.stop,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
