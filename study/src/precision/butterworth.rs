//! `butterworth` against its analytic response: the shipped filter (4th
//! order high-pass at 10 Hz, §5.1.1) run at sample rates from 5 to 1024 ×
//! its cutoff on a sum of tones, scored in the steady state against the
//! analog Butterworth response H(jω) = Π (−p_k) / (ω_c/(jω) − p_k) applied
//! to each tone — exact, evaluated in closed form. The bilinear transform's
//! frequency warping is the discretization error; it falls as (f/f_s)².
//! The knob is the sample rate the filter runs at (cost grows with it).

use super::curve::{Curve, WorkPoint};
use super::{time_best, PrecisionError, Size};
use evflow_nodes::filters::butterworth::design::{butterworth, Kind};
use evflow_nodes::filters::butterworth::sos::Cascade;
use rustfft::num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// The cutoff of the shipped use, Hz.
const CUTOFF: f64 = 10.0;
/// The order of the shipped use (the node's default).
const ORDER: usize = 4;
/// Sample rate ÷ cutoff of the shipped use (1 kHz tribometer forces).
pub const DEFAULT_RATIO: f64 = 100.0;

/// The tones (Hz, amplitude, phase): 0.5 … 2 × the cutoff, below the
/// Nyquist frequency of the coarsest rate.
fn tones() -> Vec<(f64, f64, f64)> {
    (0..7).map(|k| (CUTOFF * (0.5 + 0.25 * k as f64), 1.0 / (1.0 + k as f64).sqrt(), 0.7 * k as f64)).collect()
}

/// The analog Butterworth high-pass response of order `n`, cutoff `fc`, at `f` Hz.
pub fn analog_highpass(n: usize, fc: f64, f: f64) -> Complex64 {
    let s = Complex64::new(0.0, f / fc);
    let mut h = Complex64::new(1.0, 0.0);
    for k in 1..=n {
        let p = Complex64::from_polar(1.0, PI * (2 * k + n - 1) as f64 / (2 * n) as f64);
        h *= -p / (s.inv() - p);
    }
    h
}

/// The relative RMS steady-state error of the filter run at `ratio` × the
/// cutoff against the analog response, and its run time per second of
/// signal (best of `repeats`).
pub fn measure(ratio: f64, repeats: usize) -> Result<(f64, f64), PrecisionError> {
    let fs = ratio * CUTOFF;
    let sections = butterworth(Kind::Highpass, ORDER, CUTOFF, fs)
        .map_err(|e| PrecisionError::Method(format!("butterworth: {e}")))?;
    let tones = tones();
    // The slowest pole decays as exp(−ω_c sin(π/2N) t): 2 s leave < 1e-20 of the onset.
    let (warm, scored) = (2.0, 2.0);
    let n = ((warm + scored) * fs).round() as usize;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            tones.iter().map(|&(f, a, ph)| a * (TAU * f * t + ph).sin()).sum()
        })
        .collect();
    let mut y = vec![0.0; n];
    let seconds = time_best(repeats, || {
        let mut c = Cascade::new(&sections);
        c.process(&x, &mut y);
    });
    let responses: Vec<Complex64> = tones.iter().map(|&(f, _, _)| analog_highpass(ORDER, CUTOFF, f)).collect();
    let (mut e, mut r) = (0.0, 0.0);
    for (i, yi) in y.iter().enumerate().skip((warm * fs) as usize) {
        let t = i as f64 / fs;
        let want: f64 = tones
            .iter()
            .zip(&responses)
            .map(|(&(f, a, ph), h)| a * h.norm() * (TAU * f * t + ph + h.arg()).sin())
            .sum();
        e += (yi - want).powi(2);
        r += want * want;
    }
    Ok(((e / r).sqrt(), seconds / (warm + scored)))
}

/// The curve.
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let ratios: &[f64] = match size {
        Size::Ci => &[5.0, 10.0, 25.0, 100.0, 400.0],
        Size::Full => &[5.0, 8.0, 12.5, 25.0, 50.0, 100.0, 200.0, 400.0, 1000.0, 2000.0],
    };
    let mut points = Vec::new();
    for &r in ratios {
        let (error, cost) = measure(r, size.repeats())?;
        points.push(WorkPoint {
            setting: format!("f_s = {r} f_c"),
            series: format!("order {ORDER} high-pass"),
            error,
            cost,
            // Multiply-adds per second of signal: 5 per second-order section per sample.
            work: r * CUTOFF * 5.0 * (ORDER / 2) as f64,
        });
    }
    Ok(Curve {
        name: "butterworth".into(),
        computation: "butterworth (order 4 high-pass, 10 Hz)".into(),
        knob: "sample rate ÷ cutoff".into(),
        error_unit: "relative RMS, steady state".into(),
        cost_unit: "second of signal".into(),
        reference: "analog Butterworth H(jω) per tone (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default: format!("f_s = {DEFAULT_RATIO} f_c"),
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_analog_response_is_butterworth() {
        for f in [1.0, 5.0, 10.0, 20.0, 80.0] {
            let h = analog_highpass(4, 10.0, f);
            let want = 1.0 / (1.0 + (10.0 / f).powi(8)).sqrt();
            assert!((h.norm() - want).abs() < 1e-12, "{f}: {h}");
        }
        // High-pass of order 4: the phase at the cutoff is +4·45° = π.
        assert!((analog_highpass(4, 10.0, 10.0).arg().abs() - PI).abs() < 1e-9);
    }
}
