//! Adam (Kingma & Ba, "Adam: a method for stochastic optimization", ICLR
//! 2015) on the mean squared error: first-order, mini-batches in a seeded
//! shuffled order, β₁ = 0.9, β₂ = 0.999, ε = 1e-8; an epoch is one pass
//! over the training rows; early stopping on the validation block as in
//! [`super::lm`] (with `max_fail` counted in epochs).

use super::{finish, interrupted, mse, Data, Epoch, Settings, Stop, Trained, Watch};
use crate::lab::rng::Rng;
use crate::narx::net::Net;
use std::sync::atomic::AtomicBool;

/// Adam's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adam {
    /// Learning rate.
    pub rate: f64,
    /// Rows per mini-batch.
    pub batch: usize,
    /// Shuffling seed.
    pub seed: u64,
}

impl Default for Adam {
    fn default() -> Self {
        Adam { rate: 1e-3, batch: 32, seed: 1 }
    }
}

/// Trains `net` on `train`, early-stopping on `validation` (may be empty).
pub fn train(
    mut net: Net,
    train: &Data,
    validation: &Data,
    s: &Settings,
    a: &Adam,
    mut progress: impl FnMut(&Epoch),
    stop: Option<&AtomicBool>,
) -> Trained {
    let p = net.params.len();
    let (b1, b2, eps) = (0.9f64, 0.999f64, 1e-8);
    let mut m = vec![0.0; p];
    let mut v = vec![0.0; p];
    let mut g = vec![0.0; p];
    let mut row_grad = vec![0.0; p];
    let mut work = net.work();
    let mut order: Vec<usize> = (0..train.len()).collect();
    let mut rng = Rng::substream(a.seed, 0xada);
    let mut t = 0i32;
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
        // Fisher–Yates with the seeded stream.
        for i in (1..order.len()).rev() {
            let j = (rng.uniform() * (i + 1) as f64) as usize;
            order.swap(i, j.min(i));
        }
        let mut gnorm2 = 0.0;
        for batch in order.chunks(a.batch.max(1)) {
            g.iter_mut().for_each(|x| *x = 0.0);
            for &i in batch {
                let e = net.gradient(&train.rows[i], &mut work, &mut row_grad) - train.targets[i];
                for (gk, rk) in g.iter_mut().zip(&row_grad) {
                    *gk += 2.0 * e * rk / batch.len() as f64;
                }
            }
            gnorm2 += g.iter().map(|x| x * x).sum::<f64>();
            t += 1;
            let (c1, c2) = (1.0 - b1.powi(t), 1.0 - b2.powi(t));
            for k in 0..p {
                m[k] = b1 * m[k] + (1.0 - b1) * g[k];
                v[k] = b2 * v[k] + (1.0 - b2) * g[k] * g[k];
                net.params[k] -= a.rate * (m[k] / c1) / ((v[k] / c2).sqrt() + eps);
            }
        }
        epochs = epoch;
        let perf = mse(&net, train, &mut work);
        let val = if validation.is_empty() { f64::NAN } else { mse(&net, validation, &mut work) };
        progress(&Epoch { epoch, train: perf, validation: val, step: a.rate });
        if perf <= s.goal {
            reason = Stop::Goal;
            break;
        }
        if gnorm2.sqrt() < s.min_grad {
            reason = Stop::MinGradient;
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
    use crate::narx::train::lm;

    fn curve(n: usize) -> Data {
        let rows: Vec<Vec<f64>> = (0..n).map(|i| vec![-1.0 + 2.0 * i as f64 / (n - 1) as f64]).collect();
        let targets = rows.iter().map(|r| (2.0 * r[0]).sin()).collect();
        Data { rows, targets }
    }

    #[test]
    fn learns_a_curve_and_lm_needs_far_fewer_epochs_for_the_same_error() {
        let data = curve(60);
        let s = Settings { max_epochs: 3000, goal: 1e-4, ..Settings::default() };
        let adam = train(
            Net::new(1, &[8], 3),
            &data,
            &Data::default(),
            &s,
            &Adam { rate: 0.01, batch: 16, seed: 1 },
            |_| {},
            None,
        );
        assert_eq!(adam.stop, Stop::Goal, "{adam:?}");
        let lm = lm::train(Net::new(1, &[8], 3), &data, &Data::default(), &s, &lm::Mu::default(), |_| {}, None);
        assert_eq!(lm.stop, Stop::Goal);
        assert!(lm.epochs * 10 < adam.epochs, "LM {} vs Adam {} epochs", lm.epochs, adam.epochs);
    }

    #[test]
    fn deterministic_per_seed() {
        let data = curve(30);
        let s = Settings { max_epochs: 20, ..Settings::default() };
        let run = |seed| {
            train(Net::new(1, &[4], 2), &data, &Data::default(), &s, &Adam { seed, ..Adam::default() }, |_| {}, None)
                .net
        };
        assert_eq!(run(1), run(1));
        assert_ne!(run(1), run(2));
    }
}
