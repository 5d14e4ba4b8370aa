//! How FOAW compares with plain finite differences and a moving average on
//! known finger trajectories sampled like an IR touch frame (40 Hz,
//! positions quantized): RMS velocity error against the analytic velocity,
//! and lag (the delay of the analytic velocity that the estimate matches
//! best). The figures of `docs/texture.md` come from here
//! (`evflow report foaw`), and the tests hold FOAW to them.

use super::estimator::{Fit, Foaw};

/// A finger trajectory with its analytic velocity.
#[derive(Debug, Clone, Copy)]
pub struct Trajectory {
    /// Name in tables.
    pub name: &'static str,
    /// Position, m, at time t (s).
    pub position: fn(f64) -> f64,
    /// Velocity, m/s, at time t (s).
    pub velocity: fn(f64) -> f64,
}

/// Side to side over 8 cm, sinusoidally (peak 7.5 cm/s, smooth reversals).
fn sine_x(t: f64) -> f64 {
    0.04 * (1.0 - (std::f64::consts::TAU * 0.3 * t).cos())
}
fn sine_v(t: f64) -> f64 {
    0.04 * std::f64::consts::TAU * 0.3 * (std::f64::consts::TAU * 0.3 * t).sin()
}

/// Speed steps: 3 cm/s, rest, −7 cm/s (a sudden reversal), 5 cm/s, 1.5 s
/// each; each change takes about 60 ms (a tanh of time constant
/// [`STEP_TAU`]), as quick as a finger changes speed.
const STEPS: [(f64, f64); 3] = [(1.5, -0.03), (3.0, -0.07), (4.5, 0.12)];
/// Time constant of the speed changes, s.
const STEP_TAU: f64 = 0.015;

/// ln cosh x without overflow.
fn ln_cosh(x: f64) -> f64 {
    let a = x.abs();
    a + (-2.0 * a).exp().ln_1p() - std::f64::consts::LN_2
}
fn steps_v(t: f64) -> f64 {
    0.03 + STEPS.iter().map(|&(ti, dv)| dv * 0.5 * (1.0 + ((t - ti) / STEP_TAU).tanh())).sum::<f64>()
}
fn steps_x(t: f64) -> f64 {
    0.05 + 0.03 * t
        + STEPS
            .iter()
            .map(|&(ti, dv)| dv * 0.5 * (t + STEP_TAU * (ln_cosh((t - ti) / STEP_TAU) - ln_cosh(ti / STEP_TAU))))
            .sum::<f64>()
}

/// A person's scan: speed wandering between about 3 and 7 cm/s.
fn wander_v(t: f64) -> f64 {
    0.05 + 0.015 * (std::f64::consts::TAU * 0.4 * t).sin() + 0.005 * (std::f64::consts::TAU * 1.1 * t).sin()
}
fn wander_x(t: f64) -> f64 {
    let w1 = std::f64::consts::TAU * 0.4;
    let w2 = std::f64::consts::TAU * 1.1;
    0.05 * t + 0.015 * (1.0 - (w1 * t).cos()) / w1 + 0.005 * (1.0 - (w2 * t).cos()) / w2
}

/// The trajectories of the comparison.
pub const TRAJECTORIES: [Trajectory; 3] = [
    Trajectory { name: "side to side (sine, 0.3 Hz, 8 cm)", position: sine_x, velocity: sine_v },
    Trajectory { name: "speed steps (3, 0, −7, 5 cm/s)", position: steps_x, velocity: steps_v },
    Trajectory { name: "wandering speed (3–7 cm/s)", position: wander_x, velocity: wander_v },
];

/// A velocity estimator under comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Estimator {
    /// (y_k − y_{k−1}) / T.
    FiniteDifference,
    /// Mean of the last `w` finite differences, (y_k − y_{k−w}) / (w·T).
    MovingAverage(usize),
    /// FOAW with a fit, noise bound (m) and maximum window.
    Foaw(Fit, f64, usize),
}

impl Estimator {
    /// A short label for tables.
    pub fn label(&self) -> String {
        match self {
            Estimator::FiniteDifference => "finite difference".into(),
            Estimator::MovingAverage(w) => format!("moving average ({w})"),
            Estimator::Foaw(Fit::End, d, n) => format!("FOAW end-fit (d = {:.2} mm, N = {n})", d * 1e3),
            Estimator::Foaw(Fit::Best, d, n) => format!("FOAW best-fit (d = {:.2} mm, N = {n})", d * 1e3),
        }
    }

    /// Velocity estimates for the positions `y` sampled every `period` s.
    pub fn run(&self, y: &[f64], period: f64) -> Vec<f64> {
        match *self {
            Estimator::FiniteDifference => Estimator::MovingAverage(1).run(y, period),
            Estimator::MovingAverage(w) => {
                let w = w.max(1);
                (0..y.len())
                    .map(|k| {
                        let n = w.min(k);
                        if n == 0 {
                            0.0
                        } else {
                            (y[k] - y[k - n]) / (n as f64 * period)
                        }
                    })
                    .collect()
            }
            Estimator::Foaw(fit, d, n) => {
                let mut f = Foaw::new(fit, d, period, n);
                y.iter().map(|&p| f.push(p)).collect()
            }
        }
    }
}

/// The outcome of one estimator on one trajectory.
#[derive(Debug, Clone, Copy)]
pub struct Score {
    /// RMS of estimate − analytic velocity at the sample times, m/s.
    pub rms: f64,
    /// The delay τ (s, 0 … 0.3 in 1 ms steps) minimizing the RMS of
    /// estimate(t) − v(t − τ).
    pub lag: f64,
    /// RMS at that delay, m/s (the error lag does not explain).
    pub rms_at_lag: f64,
}

/// Positions of a trajectory as an IR frame reports them: sampled at
/// `rate` Hz for `seconds`, quantized to `step` m.
pub fn sample(tr: &Trajectory, rate: f64, seconds: f64, step: f64) -> Vec<f64> {
    let n = (rate * seconds).round() as usize;
    (0..n)
        .map(|k| {
            let x = (tr.position)(k as f64 / rate);
            if step > 0.0 {
                (x / step).round() * step
            } else {
                x
            }
        })
        .collect()
}

/// Scores an estimator on a trajectory (the first `settle` s are skipped).
pub fn score(tr: &Trajectory, est: &Estimator, rate: f64, seconds: f64, step: f64, settle: f64) -> Score {
    let y = sample(tr, rate, seconds, step);
    let v = est.run(&y, 1.0 / rate);
    let first = (settle * rate).ceil() as usize;
    let rms_for = |tau: f64| {
        let (mut acc, mut n) = (0.0, 0usize);
        for (k, vk) in v.iter().enumerate().skip(first) {
            acc += (vk - (tr.velocity)(k as f64 / rate - tau)).powi(2);
            n += 1;
        }
        (acc / n.max(1) as f64).sqrt()
    };
    let rms = rms_for(0.0);
    let (mut lag, mut rms_at_lag) = (0.0, rms);
    for ms in 1..=300 {
        let tau = ms as f64 * 1e-3;
        let r = rms_for(tau);
        if r < rms_at_lag {
            lag = tau;
            rms_at_lag = r;
        }
    }
    Score { rms, lag, rms_at_lag }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: f64 = 40.0;
    const STEP: f64 = 0.5e-3;

    #[test]
    fn trajectories_are_consistent() {
        // Each analytic velocity is the derivative of its position.
        for tr in &TRAJECTORIES {
            for k in 1..600 {
                let t = k as f64 * 0.01 + 0.0037;
                let h = 1e-6;
                let d = ((tr.position)(t + h) - (tr.position)(t - h)) / (2.0 * h);
                assert!((d - (tr.velocity)(t)).abs() < 1e-6, "{} at {t}: {d}", tr.name);
            }
        }
    }

    #[test]
    fn foaw_beats_finite_differences_and_a_moving_average_of_equal_noise() {
        // The node's defaults (d = 0.4 mm for 0.5 mm steps, N = 4) against
        // finite differences (noise) and a 5-sample moving average (lag).
        let foaw = Estimator::Foaw(Fit::Best, 0.4e-3, 4);
        for tr in &TRAJECTORIES {
            let fd = score(tr, &Estimator::FiniteDifference, RATE, 6.0, STEP, 0.5);
            let ma = score(tr, &Estimator::MovingAverage(5), RATE, 6.0, STEP, 0.5);
            let fo = score(tr, &foaw, RATE, 6.0, STEP, 0.5);
            assert!(fo.rms < 0.8 * fd.rms, "{}: FOAW {fo:?} vs FD {fd:?}", tr.name);
            assert!(fo.rms < ma.rms, "{}: FOAW {fo:?} vs MA {ma:?}", tr.name);
            assert!(fo.lag < ma.lag, "{}: FOAW {fo:?} vs MA {ma:?}", tr.name);
        }
    }

    #[test]
    fn without_quantization_foaw_is_near_exact_on_constant_speed() {
        let tr = &TRAJECTORIES[1];
        let y = sample(tr, RATE, 1.3, 0.0);
        let v = Estimator::Foaw(Fit::End, 1e-9, 16).run(&y, 1.0 / RATE);
        for vk in &v[2..] {
            assert!((vk - 0.03).abs() < 1e-9, "{vk}");
        }
    }
}
