//! The frequency–velocity relation of dissertation §6.3 (Fig. 6.6): the
//! frequency of a texture's main spectral component against the scanning
//! velocity, with a least-squares line and its R². A linear relation is
//! what lets Eq. 6.3 replace frequencies by velocities in the re-sampling.

use super::grid::Grid;
use crate::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};

/// A least-squares line y = slope·x + intercept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearFit {
    /// Slope (Hz per cm/s for the relation: cycles per cm).
    pub slope: f64,
    /// Intercept (Hz).
    pub intercept: f64,
    /// Coefficient of determination, 1 − SS_res/SS_tot (1 for a perfect line;
    /// 1 by convention when every y is equal and the line fits them).
    pub r2: f64,
}

/// Why no relation could be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FreqVelError {
    /// Fewer than two distinct velocities.
    #[error("a frequency–velocity fit needs at least two distinct velocities, got {0}")]
    TooFew(usize),
    /// No spectral peak in the band for this velocity.
    #[error("no spectral peak between {lo} and {hi} Hz in the signal at {velocity} cm/s")]
    NoPeak {
        /// Velocity, cm/s.
        velocity: f64,
        /// Band low end, Hz.
        lo: f64,
        /// Band high end, Hz.
        hi: f64,
    },
    /// A signal or rate that cannot be analysed.
    #[error("{0}")]
    Signal(String),
}

/// Least squares over (x, y) points.
pub fn fit_line(points: &[(f64, f64)]) -> Result<LinearFit, FreqVelError> {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if points.len() < 2 || sxx.is_nan() || sxx <= 0.0 {
        return Err(FreqVelError::TooFew(points.len()));
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ss_res: f64 = points.iter().map(|p| (p.1 - slope * p.0 - intercept).powi(2)).sum();
    let r2 = if syy > 0.0 { 1.0 - ss_res / syy } else { 1.0 };
    Ok(LinearFit { slope, intercept, r2 })
}

/// The frequency of the largest spectral peak of `x` (sampled at `rate` Hz)
/// between `lo` and `hi` Hz: averaged Hann spectrum with an FFT as long as
/// one second (§5.2.3: 1 Hz bins) or the signal if shorter, refined between
/// bins by a parabola through the log magnitudes of the peak and its
/// neighbours (exact for a Gaussian-shaped peak, within a few hundredths of
/// a bin for a Hann-windowed sine).
pub fn main_frequency(x: &[f64], rate: f64, lo: f64, hi: f64) -> Option<f64> {
    let nfft = (rate.round() as usize).min(x.len()).max(4);
    let cfg = SpectrumConfig { rate, nfft, window: Window::Hann, overlap: 0.5 };
    let s = averaged_spectrum(x, cfg).ok()??;
    let bin = s.bin_hz();
    let first = (lo / bin).ceil().max(1.0) as usize;
    let last = (hi / bin).floor() as usize;
    let k = s.largest_peak(first, last)?;
    let m = &s.magnitude;
    let mut f = k as f64;
    if k + 1 < m.len() && m[k - 1] > 0.0 && m[k + 1] > 0.0 {
        let (a, b, c) = (m[k - 1].ln(), m[k].ln(), m[k + 1].ln());
        let den = a - 2.0 * b + c;
        if den < 0.0 {
            f += (0.5 * (a - c) / den).clamp(-0.5, 0.5);
        }
    }
    Some(f * bin)
}

/// The main-component frequency of each (velocity, signal) and the line
/// through them (Fig. 6.6's inset).
#[derive(Debug, Clone, PartialEq)]
pub struct Relation {
    /// (velocity cm/s, main frequency Hz), in the order given.
    pub points: Vec<(f64, f64)>,
    /// The least-squares line, frequency against velocity.
    pub fit: LinearFit,
}

/// The relation for signals recorded at known velocities.
pub fn relation(signals: &[(f64, &[f64])], rate: f64, lo: f64, hi: f64) -> Result<Relation, FreqVelError> {
    if !(rate.is_finite() && rate > 0.0 && lo < hi) {
        return Err(FreqVelError::Signal(format!("rate {rate} Hz and band {lo}–{hi} Hz cannot be analysed")));
    }
    let points = signals
        .iter()
        .map(|(v, x)| {
            main_frequency(x, rate, lo, hi).map(|f| (*v, f)).ok_or(FreqVelError::NoPeak { velocity: *v, lo, hi })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let fit = fit_line(&points)?;
    Ok(Relation { points, fit })
}

/// The relation of one load row of a grid (cells U_i1 … U_iJ).
pub fn grid_relation(grid: &Grid, load_index: usize, lo: f64, hi: f64) -> Result<Relation, FreqVelError> {
    let signals: Vec<(f64, &[f64])> =
        grid.velocities.iter().enumerate().map(|(j, v)| (*v, grid.cell(load_index, j))).collect();
    relation(&signals, grid.rate, lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn least_squares_by_hand() {
        // x̄ = ȳ = 2.5, Sxy = 4, Sxx = 5, Syy = 5: slope 0.8, intercept 0.5, R² = 16/25.
        let f = fit_line(&[(1.0, 1.0), (2.0, 3.0), (3.0, 2.0), (4.0, 4.0)]).unwrap();
        assert!((f.slope - 0.8).abs() < 1e-15 && (f.intercept - 0.5).abs() < 1e-15);
        assert!((f.r2 - 0.64).abs() < 1e-15);
        assert_eq!(fit_line(&[(3.0, 1.0), (3.0, 2.0)]), Err(FreqVelError::TooFew(2)));
    }

    #[test]
    fn a_rippled_surface_gives_a_line_through_the_origin() {
        // A sinusoidal surface of 4.2 ripples per cm scanned at 3..7 cm/s
        // (the velocities of Fig. 6.6): f = 4.2·v, off the 1 Hz bins.
        let sigs: Vec<(f64, Vec<f64>)> = [3.0, 4.0, 5.0, 6.0, 7.0]
            .iter()
            .map(|&v| {
                (
                    v,
                    (0..5000)
                        .map(|n| {
                            (TAU * 4.2 * v * n as f64 / 1000.0).sin() + 0.1 * (TAU * 3.0 * n as f64 / 1000.0).sin()
                        })
                        .collect(),
                )
            })
            .collect();
        let refs: Vec<(f64, &[f64])> = sigs.iter().map(|(v, x)| (*v, x.as_slice())).collect();
        let r = relation(&refs, 1000.0, 5.0, 200.0).unwrap();
        for (v, f) in &r.points {
            assert!((f - 4.2 * v).abs() < 0.05, "{v} cm/s: {f} Hz");
        }
        assert!((r.fit.slope - 4.2).abs() < 0.01 && r.fit.intercept.abs() < 0.05 && r.fit.r2 > 0.9999, "{:?}", r.fit);
    }

    #[test]
    fn no_peak_in_band_is_an_error() {
        let x: Vec<f64> = (0..2000).map(|n| (TAU * 10.0 * n as f64 / 1000.0).sin()).collect();
        assert!(matches!(relation(&[(3.0, &x), (4.0, &x)], 1000.0, 100.0, 200.0), Err(FreqVelError::NoPeak { .. })));
    }
}
