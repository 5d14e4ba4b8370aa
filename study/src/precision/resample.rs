//! Re-sampling 𝓡𝓢 (§6.2) against the exact answer: a band-limited
//! multi-tone signal re-sampled by the velocity ratios of a 3–7 cm/s grid
//! by every resampler the texture chain can use
//! ([`evflow_nodes::texture::rs_precision`]); `evflow report resample`
//! prints these rows, `evflow report precision` draws them (the `resample`
//! node's qualities, rubato's resamplers) and the kernel `interp` runs live
//! at each half-width ([`interp_curve`]).

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Size};
use evflow_nodes::rate::resampler::Quality;
use evflow_nodes::texture::rs::RsMethod;
use evflow_nodes::texture::rs_precision::{tones, Scorer};
use rubato::PolynomialDegree;

/// Velocity ratios v_j/v_u of a 3–7 cm/s grid (p/q of 𝓡𝓢).
pub const RATIOS: [(f64, f64); 4] = [(3.0, 3.5), (5.0, 4.5), (7.0, 5.5), (3.0, 6.5)];

/// The shipped `interp` kernel half-width (its `half_width` default).
pub const INTERP_DEFAULT_WIDTH: usize = 16;

/// The methods of `evflow report resample`, each with its family.
pub fn methods() -> Vec<(&'static str, RsMethod)> {
    let mut v = Vec::new();
    for n in [16, 32, 64, 128, 256] {
        v.push(("rubato sinc", RsMethod::RubatoSinc(n)));
    }
    for d in [PolynomialDegree::Linear, PolynomialDegree::Cubic, PolynomialDegree::Quintic, PolynomialDegree::Septic] {
        v.push(("rubato polynomial", RsMethod::RubatoPoly(d)));
    }
    v.push(("rubato FFT", RsMethod::RubatoFft));
    for w in [4, 8, 16, 32] {
        v.push(("interp kernel (live)", RsMethod::Kernel(w)));
    }
    for q in Quality::ALL {
        v.push(("resample node (streaming)", RsMethod::Node(q)));
    }
    v
}

/// The test signal: 12 tones from 5 Hz to 0.2 × the rate, below the new
/// Nyquist frequency at every ratio (≥ 0.46).
pub fn signal() -> Vec<(f64, f64, f64)> {
    tones(12, 0.2, 11)
}

/// One method over every ratio.
#[derive(Debug, Clone)]
pub struct MethodRow {
    /// Its family (one line of the figure).
    pub family: &'static str,
    /// The method.
    pub method: RsMethod,
    /// Relative RMS error at the worst ratio.
    pub worst: f64,
    /// Run time per output sample, ns (mean over the ratios of the best of the repeats).
    pub ns: f64,
    /// The largest constant delay the scorer removed, output samples.
    pub delay: f64,
}

/// Measures one method on `samples` samples of [`signal`] at every ratio;
/// `scorer` keeps what the methods' scores share (pass the same one for
/// every method: the same results, sooner).
pub fn measure_method(
    scorer: &mut Scorer,
    signal: &[(f64, f64, f64)],
    family: &'static str,
    m: RsMethod,
    samples: usize,
    repeats: usize,
) -> Result<MethodRow, PrecisionError> {
    let (mut worst, mut ns, mut delay) = (0.0f64, 0.0f64, 0.0f64);
    for &(p, q) in &RATIOS {
        let r = scorer
            .measure(signal, samples, p, q, m, repeats)
            .map_err(|e| PrecisionError::Method(format!("{}: {e}", m.label())))?;
        worst = worst.max(r.error);
        ns += r.seconds * 1e9 / r.samples.max(1) as f64 / RATIOS.len() as f64;
        if r.delay.abs() > delay.abs() {
            delay = r.delay;
        }
    }
    Ok(MethodRow { family, method: m, worst, ns, delay })
}

fn point(r: &MethodRow, series: &str) -> WorkPoint {
    let work = match r.method {
        RsMethod::RubatoSinc(n) => n as f64,
        RsMethod::RubatoPoly(d) => d.nbr_points() as f64,
        RsMethod::RubatoFft => f64::NAN,
        // Two sides of W taps at cutoff ≤ 1 (wider below).
        RsMethod::Kernel(w) => 2.0 * w as f64,
        RsMethod::Node(q) => match q {
            Quality::Fast => 4.0,
            Quality::Balanced => 128.0,
            Quality::Best => 256.0,
        },
    };
    WorkPoint { setting: r.method.label(), series: series.into(), error: r.worst, cost: r.ns * 1e-9, work }
}

fn samples(size: Size) -> usize {
    match size {
        Size::Ci => 2000,
        Size::Full => 10_000,
    }
}

/// The curve of the resamplers other than `interp`'s kernel.
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let signal = signal();
    let mut scorer = Scorer::default();
    let mut points = Vec::new();
    for (family, m) in methods() {
        if matches!(m, RsMethod::Kernel(_)) || (size == Size::Ci && matches!(m, RsMethod::RubatoSinc(16 | 64))) {
            continue;
        }
        points.push(point(&measure_method(&mut scorer, &signal, family, m, samples(size), size.repeats())?, family));
    }
    Ok(Curve {
        name: "resample".into(),
        computation: "resample node / rubato (𝓡𝓢, 4 grid ratios)".into(),
        knob: "method and length".into(),
        error_unit: "relative RMS, worst ratio".into(),
        cost_unit: "output sample".into(),
        reference: "the tones at the new instants (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default: RsMethod::Node(Quality::Balanced).label(),
        points,
    })
}

/// The curve of `interp`'s windowed-sinc kernel over its half-width.
pub fn interp_curve(size: Size) -> Result<Curve, PrecisionError> {
    let widths: &[usize] = match size {
        Size::Ci => &[2, 4, 8, 16, 32],
        Size::Full => &[2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64],
    };
    let signal = signal();
    let mut scorer = Scorer::default();
    let mut points = Vec::new();
    for &w in widths {
        let r = measure_method(
            &mut scorer,
            &signal,
            "interp kernel (live)",
            RsMethod::Kernel(w),
            samples(size),
            size.repeats(),
        )?;
        points.push(point(&r, "Kaiser-windowed sinc, β 8.6, γ 0.9"));
    }
    Ok(Curve {
        name: "interp-kernel".into(),
        computation: "interp's re-sampling kernel (𝓡𝓢 live)".into(),
        knob: "half_width W".into(),
        error_unit: "relative RMS, worst ratio".into(),
        cost_unit: "output sample".into(),
        reference: "the tones at the new instants (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default: RsMethod::Kernel(INTERP_DEFAULT_WIDTH).label(),
        points,
    })
}
