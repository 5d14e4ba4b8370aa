//! Velocity from IR-frame positions (§6.5.1): FOAW against finite
//! differences and moving averages on the known trajectories of
//! [`evflow_nodes::filters::foaw::compare`]. [`estimators`] and [`table`]
//! are `evflow report foaw`'s rows; [`curve`] is its work-precision curve
//! for `evflow report precision` (error against the analytic velocity, cost
//! the estimator's run time per position sample).

use super::curve::{Curve, WorkPoint};
use super::{time_best, PrecisionError, Size};
use evflow_nodes::filters::foaw::compare::{sample, score, Estimator, Score, TRAJECTORIES};
use evflow_nodes::filters::foaw::estimator::Fit;

/// The estimators `evflow report foaw` compares: the baselines, then FOAW
/// over noise bounds (× the quantization step `step_m`, m) and windows.
pub fn estimators(step_m: f64) -> Vec<Estimator> {
    let mut v = vec![
        Estimator::FiniteDifference,
        Estimator::MovingAverage(3),
        Estimator::MovingAverage(5),
        Estimator::MovingAverage(8),
    ];
    for d in [0.5, 0.6, 0.8, 1.0, 1.5] {
        for n in [4, 8, 16] {
            v.push(Estimator::Foaw(Fit::Best, d * step_m, n));
            v.push(Estimator::Foaw(Fit::End, d * step_m, n));
        }
    }
    v
}

/// The family an estimator is drawn in.
pub fn family(e: &Estimator) -> &'static str {
    match e {
        Estimator::FiniteDifference => "finite difference",
        Estimator::MovingAverage(_) => "moving average",
        Estimator::Foaw(Fit::Best, ..) => "FOAW best-fit",
        Estimator::Foaw(Fit::End, ..) => "FOAW end-fit",
    }
}

/// Each estimator's score on every trajectory (in [`TRAJECTORIES`] order),
/// positions at `rate` Hz quantized to `step` m, `seconds` long, the first
/// 0.5 s not scored.
pub fn table(ests: &[Estimator], rate: f64, seconds: f64, step: f64) -> Vec<Vec<Score>> {
    ests.iter().map(|e| TRAJECTORIES.iter().map(|tr| score(tr, e, rate, seconds, step, 0.5)).collect()).collect()
}

/// The position rate (an IR frame), Hz; the quantization step, m; and the
/// `foaw` node's default noise bound, m.
const RATE: f64 = 40.0;
const STEP: f64 = 0.5e-3;
const NOISE: f64 = 0.4e-3;
/// The `foaw` node's default `max_window`.
pub const DEFAULT_WINDOW: usize = 4;

/// The curve: mean RMS error over the trajectories of FOAW (both fits, the
/// node's default noise bound) over the window, beside the baselines.
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let (seconds, windows): (f64, &[usize]) = match size {
        Size::Ci => (6.0, &[2, 4, 8, 16]),
        Size::Full => (30.0, &[2, 3, 4, 6, 8, 12, 16, 24, 32]),
    };
    let mut ests = vec![
        Estimator::FiniteDifference,
        Estimator::MovingAverage(2),
        Estimator::MovingAverage(3),
        Estimator::MovingAverage(5),
        Estimator::MovingAverage(8),
    ];
    for fit in [Fit::Best, Fit::End] {
        ests.extend(windows.iter().map(|&n| Estimator::Foaw(fit, NOISE, n)));
    }
    let mut points = Vec::new();
    for e in &ests {
        let scores = table(std::slice::from_ref(e), RATE, seconds, STEP).remove(0);
        let error = scores.iter().map(|s| s.rms).sum::<f64>() / scores.len() as f64 * 100.0;
        let y = sample(&TRAJECTORIES[2], RATE, seconds, STEP);
        let seconds_run = time_best(size.repeats(), || {
            std::hint::black_box(e.run(&y, 1.0 / RATE));
        });
        let work = match *e {
            Estimator::FiniteDifference => 1.0,
            Estimator::MovingAverage(_) => 1.0,
            Estimator::Foaw(_, _, n) => n as f64,
        };
        points.push(WorkPoint {
            setting: e.label(),
            series: family(e).into(),
            error,
            cost: seconds_run / y.len() as f64,
            work,
        });
    }
    Ok(Curve {
        name: "foaw".into(),
        computation: "foaw (velocity from 40 Hz positions, 0.5 mm steps)".into(),
        knob: "estimator and window".into(),
        error_unit: "mean RMS velocity error, cm/s".into(),
        cost_unit: "position sample".into(),
        reference: "the trajectories' analytic velocity (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default: Estimator::Foaw(Fit::Best, NOISE, DEFAULT_WINDOW).label(),
        points,
    })
}
