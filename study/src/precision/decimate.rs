//! `decimate` against the exact answer: a signal of tones inside the
//! passband (below `passband` × the new Nyquist frequency f_N) and as many
//! tones above f_N (which must not fold back) decimated by 10 at each
//! stopband attenuation; the exact output is the in-band tones alone at the
//! output instants, delayed by the filter's whole-sample group delay. The
//! knob is `attenuation` (the filter's length follows it).

use super::curve::{Curve, WorkPoint};
use super::{time_best, PrecisionError, Size};
use evflow_nodes::rate::decimator::{design, Decimator};
use std::f64::consts::TAU;

/// The factor: 10 kHz to 1 kHz (the force data of §3.1.2).
const FACTOR: usize = 10;
/// The node's default passband (fraction of f_N).
const PASSBAND: f64 = 0.8;
/// The node's default attenuation, dB.
pub const DEFAULT_ATTENUATION: f64 = 100.0;

/// (cycles per input sample, amplitude, phase, in band?).
fn tones() -> Vec<(f64, f64, f64, bool)> {
    let f_n = 0.5 / FACTOR as f64;
    let mut v = Vec::new();
    for k in 0..6 {
        // In band: 0.03 … 0.78 f_N.
        v.push((f_n * (0.03 + 0.15 * k as f64), 1.0, 0.9 * k as f64, true));
        // Above f_N: 1.02 f_N … near the input Nyquist frequency.
        v.push((f_n * (1.02 + 1.7 * k as f64), 1.0, 0.4 + 1.3 * k as f64, false));
    }
    v
}

/// The relative RMS error of `decimate` at `attenuation` dB, its run time per
/// output sample (best of `repeats`) and its taps.
pub fn measure(attenuation: f64, outputs: usize, repeats: usize) -> Result<(f64, f64, usize), PrecisionError> {
    let d = design(FACTOR, PASSBAND, attenuation).map_err(|e| PrecisionError::Method(format!("decimate: {e}")))?;
    let tones = tones();
    let n = outputs * FACTOR + d.taps.len();
    let x: Vec<f64> =
        (0..n).map(|i| tones.iter().map(|&(f, a, ph, _)| a * (TAU * f * i as f64 + ph).sin()).sum()).collect();
    let mut y = Vec::with_capacity(n / FACTOR + 1);
    let seconds = time_best(repeats, || {
        y.clear();
        let mut dec = Decimator::new(&d);
        y.extend(x.iter().filter_map(|&v| dec.push(v)));
    });
    let delay = d.delay_out();
    let (mut e, mut r) = (0.0, 0.0);
    for (k, yk) in y.iter().enumerate().skip(2 * delay + 1) {
        let t = ((k - delay) * FACTOR) as f64;
        let want: f64 = tones.iter().filter(|t| t.3).map(|&(f, a, ph, _)| a * (TAU * f * t + ph).sin()).sum();
        e += (yk - want).powi(2);
        r += want * want;
    }
    Ok(((e / r).sqrt(), seconds / y.len().max(1) as f64, d.taps.len()))
}

/// The curve.
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let (atts, outputs): (&[f64], usize) = match size {
        Size::Ci => (&[20.0, 40.0, 60.0, 100.0, 140.0], 2000),
        Size::Full => (&[20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 140.0, 160.0, 180.0, 200.0], 20_000),
    };
    let mut points = Vec::new();
    for &a in atts {
        let (error, cost, taps) = measure(a, outputs, size.repeats())?;
        points.push(WorkPoint {
            setting: format!("{a} dB ({taps} taps)"),
            series: format!("÷{FACTOR}, passband {PASSBAND}"),
            error,
            cost,
            work: taps as f64,
        });
    }
    let default = points
        .iter()
        .find(|p| p.setting.starts_with(&format!("{DEFAULT_ATTENUATION} dB")))
        .map(|p| p.setting.clone())
        .unwrap_or_default();
    Ok(Curve {
        name: "decimate".into(),
        computation: "decimate (÷10, passband 0.8)".into(),
        knob: "attenuation".into(),
        error_unit: "relative RMS".into(),
        cost_unit: "output sample".into(),
        reference: "the in-band tones at the output instants (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default,
        points,
    })
}
