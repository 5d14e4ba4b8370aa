//! Training the network on regressor rows: Levenberg–Marquardt as MATLAB's
//! `trainlm` ([`lm`]) and Adam ([`adam`]), both with early stopping on a
//! validation block, seeded, deterministic and interruptible.

pub mod adam;
pub mod lm;

use super::net::{Net, Work};
use std::sync::atomic::{AtomicBool, Ordering};

/// Regressor rows and their targets (already normalized).
#[derive(Debug, Clone, Default)]
pub struct Data {
    /// One row of network inputs per sample.
    pub rows: Vec<Vec<f64>>,
    /// One target per row.
    pub targets: Vec<f64>,
}

impl Data {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.rows.len()
    }
    /// True with no sample.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// Mean squared error of `net` on `data` (0 for no data).
pub fn mse(net: &Net, data: &Data, w: &mut Work) -> f64 {
    if data.is_empty() {
        return 0.0;
    }
    data.rows.iter().zip(&data.targets).map(|(x, t)| (net.forward(x, w) - t).powi(2)).sum::<f64>() / data.len() as f64
}

/// Why training stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The epoch limit.
    Epochs,
    /// The validation error rose `max_fail` times in a row.
    Validation,
    /// The gradient fell below `min_grad`.
    MinGradient,
    /// μ exceeded μ_max (LM only).
    MaxMu,
    /// The training error reached the goal.
    Goal,
    /// Interrupted.
    Interrupted,
}

/// Settings shared by both trainers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Most epochs.
    pub max_epochs: usize,
    /// Validation failures in a row that stop training (MATLAB: 6).
    pub max_fail: usize,
    /// Gradient norm below which training stops (MATLAB: 1e-7).
    pub min_grad: f64,
    /// Training MSE at which training stops (MATLAB: 0).
    pub goal: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings { max_epochs: 1000, max_fail: 6, min_grad: 1e-7, goal: 0.0 }
    }
}

/// What one epoch reached (for progress bars and reports).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch {
    /// Epoch number, from 1.
    pub epoch: usize,
    /// Training MSE.
    pub train: f64,
    /// Validation MSE (NaN without validation data).
    pub validation: f64,
    /// μ (LM) or the learning rate (Adam).
    pub step: f64,
}

/// The outcome of training.
#[derive(Debug, Clone, PartialEq)]
pub struct Trained {
    /// The network with the best validation error (or the last, without validation data).
    pub net: Net,
    /// Epochs run.
    pub epochs: usize,
    /// Why it stopped.
    pub stop: Stop,
    /// Training MSE of the returned network.
    pub train_mse: f64,
    /// Validation MSE of the returned network (NaN without validation data).
    pub validation_mse: f64,
}

/// Early stopping on the validation error, shared by the trainers.
#[derive(Debug, Clone)]
pub(crate) struct Watch {
    best: f64,
    best_net: Option<Net>,
    fails: usize,
}

impl Watch {
    pub(crate) fn new() -> Self {
        Watch { best: f64::INFINITY, best_net: None, fails: 0 }
    }

    /// Records a validation error; true when training should stop.
    pub(crate) fn update(&mut self, val: f64, net: &Net, max_fail: usize) -> bool {
        if val < self.best || self.best_net.is_none() {
            self.best = val;
            self.best_net = Some(net.clone());
            self.fails = 0;
            false
        } else {
            self.fails += 1;
            self.fails >= max_fail
        }
    }

    pub(crate) fn best(self, last: Net) -> Net {
        self.best_net.unwrap_or(last)
    }
}

/// The trained network — the best on validation, or the last without
/// validation data — with its errors.
pub(crate) fn finish(net: Net, watch: Watch, train: &Data, validation: &Data, epochs: usize, stop: Stop) -> Trained {
    let net = if validation.is_empty() { net } else { watch.best(net) };
    let mut work = net.work();
    let train_mse = mse(&net, train, &mut work);
    let validation_mse = if validation.is_empty() { f64::NAN } else { mse(&net, validation, &mut work) };
    Trained { net, epochs, stop, train_mse, validation_mse }
}

/// True when `flag` is set.
pub(crate) fn interrupted(flag: Option<&AtomicBool>) -> bool {
    flag.is_some_and(|f| f.load(Ordering::Relaxed))
}
