//! The spectra the study's figures draw: a signal's magnitude spectrum over
//! its constant-speed stretch, as the `metric` node takes it for E_s
//! (rectangular segments of one second, 1 Hz bins, magnitudes averaged).

use super::StudyError;
use evflow_nodes::filters::segment::open_runs;
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};

/// Magnitude spectrum of the samples of `x` where `gate` is open (> 0.5),
/// at `rate` Hz: one bin per hertz.
pub fn gated(x: &[f64], gate: &[f64], rate: f64) -> Result<Vec<f64>, StudyError> {
    let mut kept = Vec::new();
    open_runs(&[gate], x.len().min(gate.len()), |a, b| kept.extend_from_slice(&x[a..b]));
    let cfg = SpectrumConfig { rate, nfft: rate.round() as usize, window: Window::Rect, overlap: 0.0 };
    averaged_spectrum(&kept, cfg)
        .map_err(|e| StudyError::Config(e.to_string()))?
        .map(|s| s.magnitude)
        .ok_or_else(|| StudyError::Recording("too few constant-speed samples for a spectrum".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spectrum_counts_only_the_gated_samples() {
        // 3 s of a 50 Hz sine, gated to its last 2 s; the first second is a 20 Hz sine.
        let rate = 1000.0;
        let x: Vec<f64> = (0..3000)
            .map(|n| {
                let f = if n < 1000 { 20.0 } else { 50.0 };
                (2.0 * std::f64::consts::PI * f * n as f64 / rate).sin()
            })
            .collect();
        let gate: Vec<f64> = (0..3000).map(|n| if n < 1000 { 0.0 } else { 1.0 }).collect();
        let s = gated(&x, &gate, rate).unwrap();
        let peak = s.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap().0;
        assert_eq!(peak, 50);
        assert!(s[20] < 1e-6 * s[50]);
        assert!(gated(&x, &[0.0; 3000], rate).is_err());
    }
}
