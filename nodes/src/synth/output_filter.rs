//! The filter the recorded force went through after the display (the
//! 10 Hz Butterworth high-pass of dissertation §5.1.1), as a linear
//! operator on whole series, with its adjoint.
//!
//! The forward model predicts the force at the sensor; the recordings it is
//! identified from and the texture forces it is matched to were high-passed.
//! Both are linear and time-invariant, so the filter is applied to the
//! model's output (and, identifying, to each regressor column). Filtering
//! from rest over a series of N samples is a lower-triangular Toeplitz
//! matrix T; its adjoint Tᵀ is the same filter run backwards in time
//! (reverse, filter, reverse), which is what reverse-mode gradients need.

use super::error::SynthError;
use crate::filters::butterworth::design::{butterworth, Kind, Section};
use crate::filters::butterworth::sos::Cascade;

/// A Butterworth high-pass (or nothing) applied from rest.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputFilter {
    order: usize,
    cutoff_hz: f64,
    sections: Vec<Section>,
}

impl OutputFilter {
    /// No filter: the identity.
    pub fn none() -> Self {
        Self { order: 0, cutoff_hz: 0.0, sections: Vec::new() }
    }

    /// A Butterworth high-pass of `order` at `cutoff_hz` for `rate` Hz
    /// (order 0 = none), designed as the `butterworth` node designs it.
    pub fn highpass(order: usize, cutoff_hz: f64, rate: f64) -> Result<Self, SynthError> {
        if order == 0 {
            return Ok(Self::none());
        }
        let sections = butterworth(Kind::Highpass, order, cutoff_hz, rate)
            .map_err(|e| SynthError::Config(format!("output high-pass: {e}")))?;
        Ok(Self { order, cutoff_hz, sections })
    }

    /// Order (0 = none).
    pub fn order(&self) -> usize {
        self.order
    }

    /// Cut-off, Hz.
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }

    /// y ← T·x, from rest.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        if self.sections.is_empty() {
            y[..x.len()].copy_from_slice(x);
            return;
        }
        Cascade::new(&self.sections).process(x, y);
    }

    /// x ← T·x in place.
    pub fn apply_in_place(&self, x: &mut [f64]) {
        if self.sections.is_empty() {
            return;
        }
        Cascade::new(&self.sections).process_in_place(x);
    }

    /// x ← Tᵀ·x in place: the filter run backwards in time.
    pub fn adjoint_in_place(&self, x: &mut [f64]) {
        if self.sections.is_empty() {
            return;
        }
        Cascade::new(&self.sections).process_reversed_in_place(x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn the_adjoint_satisfies_the_inner_product_identity() {
        // ⟨T x, y⟩ = ⟨x, Tᵀ y⟩ for random x, y.
        let f = OutputFilter::highpass(4, 10.0, 1000.0).unwrap();
        let mut r = Rng::new(5);
        let x: Vec<f64> = (0..3000).map(|_| r.gaussian()).collect();
        let y: Vec<f64> = (0..3000).map(|_| r.gaussian()).collect();
        let mut tx = vec![0.0; 3000];
        f.apply(&x, &mut tx);
        let mut tty = y.clone();
        f.adjoint_in_place(&mut tty);
        let a: f64 = tx.iter().zip(&y).map(|(a, b)| a * b).sum();
        let b: f64 = x.iter().zip(&tty).map(|(a, b)| a * b).sum();
        assert!((a - b).abs() < 1e-9 * a.abs().max(1.0), "{a} vs {b}");
        let mut inplace = x.clone();
        f.apply_in_place(&mut inplace);
        assert_eq!(inplace, tx);
    }

    #[test]
    fn a_high_pass_removes_a_constant_and_none_is_the_identity() {
        let f = OutputFilter::highpass(4, 10.0, 1000.0).unwrap();
        let mut y = vec![1.0; 2000];
        f.apply_in_place(&mut y);
        assert!(y[1500..].iter().all(|v| v.abs() < 1e-6), "{}", y[1999]);
        let id = OutputFilter::none();
        let mut z = vec![0.5, -1.0];
        id.apply_in_place(&mut z);
        id.adjoint_in_place(&mut z);
        assert_eq!(z, vec![0.5, -1.0]);
        assert!(OutputFilter::highpass(4, 600.0, 1000.0).is_err(), "above Nyquist");
    }
}
