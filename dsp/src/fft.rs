//! Forward FFTs of `f64` samples (rustfft).

use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// A forward FFT of length `n` (unnormalized, e⁻ⁱ²ᵖⁱᵏⁿ/ᴺ), as rustfft's
/// planner chooses it for this machine. Call it through the [`Fft`] trait
/// (`process`, `process_with_scratch`).
pub fn forward(n: usize) -> Arc<dyn Fft<f64>> {
    FftPlanner::<f64>::new().plan_fft_forward(n)
}
