//! Levenberg–Marquardt training as MATLAB's `trainlm`: each epoch forms
//! the Jacobian J of the outputs with respect to the parameters and the
//! errors e, and tries dX = −(JᵀJ + μI)⁻¹Jᵀe, dividing μ by 10 on success
//! and multiplying it by 10 until a step lowers the error or μ exceeds
//! μ_max (1e10); μ starts at 1e-3. The solve is faer's Cholesky (LLᵀ) of the
//! damped normal matrix; a matrix that is not positive definite counts as
//! a failed step (μ grows).

use super::{finish, interrupted, mse, Data, Epoch, Settings, Stop, Trained, Watch};
use crate::narx::net::Net;
use faer::prelude::*;
use faer::Mat;
use std::sync::atomic::AtomicBool;

/// μ schedule of `trainlm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mu {
    /// Initial μ (1e-3).
    pub initial: f64,
    /// Factor on failure (10).
    pub increase: f64,
    /// Factor on success (0.1).
    pub decrease: f64,
    /// Largest μ (1e10).
    pub max: f64,
}

impl Default for Mu {
    fn default() -> Self {
        Mu { initial: 1e-3, increase: 10.0, decrease: 0.1, max: 1e10 }
    }
}

/// Trains `net` on `train`, early-stopping on `validation` (may be empty).
/// `progress` sees every epoch; `stop` interrupts between epochs.
pub fn train(
    mut net: Net,
    train: &Data,
    validation: &Data,
    s: &Settings,
    mu_s: &Mu,
    mut progress: impl FnMut(&Epoch),
    stop: Option<&AtomicBool>,
) -> Trained {
    let p = net.params.len();
    let n = train.len();
    let mut work = net.work();
    let mut grad = vec![0.0; p];
    let mut jac = Mat::<f64>::zeros(n, p);
    let mut err = Mat::<f64>::zeros(n, 1);
    let mut mu = mu_s.initial;
    let mut perf = mse(&net, train, &mut work);
    let mut watch = Watch::new();
    let mut reason = Stop::Epochs;
    let mut epochs = 0;
    if !validation.is_empty() {
        watch.update(mse(&net, validation, &mut work), &net, s.max_fail);
    }
    for epoch in 1..=s.max_epochs {
        if interrupted(stop) {
            reason = Stop::Interrupted;
            break;
        }
        if perf <= s.goal {
            reason = Stop::Goal;
            break;
        }
        for (i, (x, t)) in train.rows.iter().zip(&train.targets).enumerate() {
            let y = net.gradient(x, &mut work, &mut grad);
            err[(i, 0)] = y - t;
            for (k, g) in grad.iter().enumerate() {
                jac[(i, k)] = *g;
            }
        }
        let jt = jac.transpose();
        let jtj = jt * &jac;
        let jte = jt * &err;
        let gnorm = (0..p).map(|k| jte[(k, 0)].powi(2)).sum::<f64>().sqrt() * 2.0 / n.max(1) as f64;
        if gnorm < s.min_grad {
            reason = Stop::MinGradient;
            break;
        }
        epochs = epoch;
        let mut improved = false;
        while mu <= mu_s.max {
            let mut a = jtj.clone();
            for k in 0..p {
                a[(k, k)] += mu;
            }
            if let Ok(llt) = a.llt(faer::Side::Lower) {
                let dx = llt.solve(&jte);
                let mut trial = net.clone();
                for k in 0..p {
                    trial.params[k] -= dx[(k, 0)];
                }
                let trial_perf = mse(&trial, train, &mut work);
                if trial_perf.is_finite() && trial_perf < perf {
                    net = trial;
                    perf = trial_perf;
                    mu *= mu_s.decrease;
                    improved = true;
                    break;
                }
            }
            mu *= mu_s.increase;
        }
        let val = if validation.is_empty() { f64::NAN } else { mse(&net, validation, &mut work) };
        progress(&Epoch { epoch, train: perf, validation: val, step: mu });
        if !improved {
            reason = Stop::MaxMu;
            break;
        }
        if !validation.is_empty() && watch.update(val, &net, s.max_fail) {
            reason = Stop::Validation;
            break;
        }
    }
    finish(net, watch, train, validation, epochs, reason)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(n: usize, f: impl Fn(f64) -> f64) -> Data {
        let rows: Vec<Vec<f64>> = (0..n).map(|i| vec![-1.0 + 2.0 * i as f64 / (n - 1) as f64]).collect();
        let targets = rows.iter().map(|r| f(r[0])).collect();
        Data { rows, targets }
    }

    #[test]
    fn fits_a_smooth_curve_to_high_accuracy() {
        let data = curve(60, |x| (2.0 * x).sin());
        let t =
            train(Net::new(1, &[8], 3), &data, &Data::default(), &Settings::default(), &Mu::default(), |_| {}, None);
        assert!(t.train_mse < 1e-6, "{t:?}");
    }

    #[test]
    fn a_linear_model_reaches_least_squares_in_a_few_steps() {
        // y = 0.7·a − 0.2·b + 0.1 plus a fixed disturbance: LM on a linear
        // model converges to the normal-equations solution.
        let rows: Vec<Vec<f64>> = (0..50).map(|i| vec![(i as f64 * 0.37).sin(), (i as f64 * 0.11).cos()]).collect();
        let targets: Vec<f64> = rows
            .iter()
            .enumerate()
            .map(|(i, r)| 0.7 * r[0] - 0.2 * r[1] + 0.1 + 0.01 * (i as f64 * 1.3).sin())
            .collect();
        let data = Data { rows: rows.clone(), targets: targets.clone() };
        let s = Settings { max_epochs: 20, ..Settings::default() };
        let t = train(Net::new(2, &[], 1), &data, &Data::default(), &s, &Mu::default(), |_| {}, None);
        // Normal equations with faer.
        let x = Mat::<f64>::from_fn(50, 3, |i, j| if j < 2 { rows[i][j] } else { 1.0 });
        let y = Mat::<f64>::from_fn(50, 1, |i, _| targets[i]);
        let xt = x.transpose();
        let beta = (xt * &x).llt(faer::Side::Lower).unwrap().solve(&(xt * &y));
        for k in 0..3 {
            assert!((t.net.params[k] - beta[(k, 0)]).abs() < 1e-6, "{:?} vs {:?}", t.net.params, beta);
        }
    }

    #[test]
    fn early_stopping_returns_the_best_validation_network() {
        // Few noisy samples, a big network: the validation error must rise.
        let mut data = curve(30, |x| x * x);
        for (i, t) in data.targets.iter_mut().enumerate() {
            *t += 0.2 * ((i * 7919) % 13) as f64 / 13.0 - 0.1;
        }
        let val = curve(17, |x| x * x);
        let mut history = Vec::new();
        let t = train(
            Net::new(1, &[20, 20], 5),
            &data,
            &val,
            &Settings::default(),
            &Mu::default(),
            |e| history.push(e.validation),
            None,
        );
        assert_eq!(t.stop, Stop::Validation, "{t:?}");
        let best = history.iter().copied().fold(f64::INFINITY, f64::min);
        let initial = mse(&Net::new(1, &[20, 20], 5), &val, &mut Net::new(1, &[20, 20], 5).work());
        assert!((t.validation_mse - best.min(initial)).abs() < 1e-15, "{} vs {best}", t.validation_mse);
    }

    #[test]
    fn deterministic_and_interruptible() {
        let data = curve(40, |x| x.tanh());
        let run =
            || train(Net::new(1, &[4], 9), &data, &Data::default(), &Settings::default(), &Mu::default(), |_| {}, None);
        assert_eq!(run().net, run().net);
        let flag = AtomicBool::new(true);
        let t = train(
            Net::new(1, &[4], 9),
            &data,
            &Data::default(),
            &Settings::default(),
            &Mu::default(),
            |_| {},
            Some(&flag),
        );
        assert_eq!((t.stop, t.epochs), (Stop::Interrupted, 0));
    }
}
