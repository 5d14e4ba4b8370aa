//! Training of the open-loop (series-parallel) NARX network, dissertation
//! Fig. 5.3(a): the regressors hold the *true* past outputs, so training is
//! ordinary supervised regression. Two algorithms: Levenberg–Marquardt as
//! MATLAB `trainlm` (the toolbox default the dissertation used) and Adam.
//! Both stop early on a contiguous validation block.

pub mod adam;
mod epochs;
pub mod lm;

use super::net::Mlp;
use super::packed::{PackedMlp, Tanh};
use ndarray::{ArrayView1, ArrayView2};
use serde::{Deserialize, Serialize};

/// Regressors (one row per sample) and their targets.
#[derive(Debug, Clone, Copy)]
pub struct Data<'a> {
    /// Regressors, row-major: sample after sample, `cols` values each.
    flat: &'a [f64],
    /// Network inputs per sample.
    cols: usize,
    /// Target per sample.
    t: &'a [f64],
}

impl<'a> Data<'a> {
    /// Data over a regressor matrix (samples × inputs, standard row-major
    /// layout) and its targets; `None` when the shapes disagree or the
    /// matrix is not contiguous.
    pub fn new(x: ArrayView2<'a, f64>, t: ArrayView1<'a, f64>) -> Option<Self> {
        let cols = x.ncols();
        (x.nrows() == t.len()).then_some(())?;
        Some(Self { flat: x.to_slice()?, cols, t: t.to_slice()? })
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// Network inputs per sample.
    pub fn cols(&self) -> usize {
        self.cols
    }
    /// The regressors of sample `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &'a [f64] {
        &self.flat[i * self.cols..(i + 1) * self.cols]
    }
    /// The target of sample `i`.
    #[inline]
    pub fn target(&self, i: usize) -> f64 {
        self.t[i]
    }
    /// The samples `range` as their own data.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Self {
        Self { flat: &self.flat[range.start * self.cols..range.end * self.cols], cols: self.cols, t: &self.t[range] }
    }
}

/// Why training stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The epoch limit was reached.
    MaxEpochs,
    /// The validation error rose `max_fail` epochs in a row (weights of the best validation epoch kept).
    ValidationStop,
    /// The gradient norm fell below `min_grad`.
    MinGradient,
    /// Levenberg–Marquardt: μ exceeded μ_max without an improving step.
    MuMax,
    /// The training error reached zero.
    Goal,
}

impl StopReason {
    /// A few words for people.
    pub fn describe(&self) -> &'static str {
        match self {
            StopReason::MaxEpochs => "epoch limit reached",
            StopReason::ValidationStop => "validation error stopped improving",
            StopReason::MinGradient => "gradient below min_grad",
            StopReason::MuMax => "mu above mu_max",
            StopReason::Goal => "training error reached 0",
        }
    }
}

/// Options of both algorithms (each reads the ones it uses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Largest number of epochs.
    pub max_epochs: usize,
    /// Validation failures in a row that stop training (MATLAB `max_fail`, 6).
    pub max_fail: usize,
    /// Gradient norm of the MSE below which training stops (MATLAB `min_grad`, 1e-7).
    pub min_grad: f64,
    /// Initial damping μ (MATLAB `mu`, 0.001).
    pub mu: f64,
    /// Factor on μ after an improving step (MATLAB `mu_dec`, 0.1).
    pub mu_dec: f64,
    /// Factor on μ after a step that did not improve (MATLAB `mu_inc`, 10).
    pub mu_inc: f64,
    /// Largest μ (MATLAB `mu_max`, 1e10).
    pub mu_max: f64,
    /// Adam: step size.
    pub learning_rate: f64,
    /// Adam: samples per mini-batch.
    pub batch: usize,
    /// Seed (Adam's shuffling).
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            max_epochs: 1000,
            max_fail: 6,
            min_grad: 1e-7,
            mu: 1e-3,
            mu_dec: 0.1,
            mu_inc: 10.0,
            mu_max: 1e10,
            learning_rate: 1e-3,
            batch: 64,
            seed: 1,
        }
    }
}

/// One epoch, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch {
    /// Epoch number, from 1.
    pub epoch: usize,
    /// Mean squared error on the training block (normalized units).
    pub train_mse: f64,
    /// Mean squared error on the validation block (NaN without one).
    pub val_mse: f64,
    /// Norm of the MSE's gradient.
    pub gradient: f64,
    /// Levenberg–Marquardt's μ after the epoch (0 for Adam).
    pub mu: f64,
    /// Seconds since training started.
    pub seconds: f64,
}

/// The outcome of a training run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report {
    /// Epochs run.
    pub epochs: usize,
    /// The epoch whose weights were kept (best validation error, or the last).
    pub best_epoch: usize,
    /// Training MSE of the kept weights.
    pub train_mse: f64,
    /// Validation MSE of the kept weights (NaN without a validation block).
    pub val_mse: f64,
    /// Why training stopped.
    pub stop: StopReason,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Mean squared error of `net` on `data`. The rows go through the blocked
/// layout ([`PackedMlp`], exact tanh: each output equal to
/// [`Mlp::forward`]'s bit for bit, so the same value as a row-by-row pass
/// of the network, in about 0.6 of its time).
pub fn mse(net: &Mlp, data: &Data<'_>) -> f64 {
    if data.is_empty() {
        return f64::NAN;
    }
    let mut packed = PackedMlp::new(net, Tanh::Exact);
    let mut s = 0.0;
    for i in 0..data.len() {
        let e = packed.forward(data.row(i), &[]) - data.target(i);
        s += e * e;
    }
    s / data.len() as f64
}

/// Early stopping on the validation block, as MATLAB: an epoch whose
/// validation error is lower than the best so far becomes the best (its
/// weights are kept); one that is higher counts a failure; `max_fail`
/// failures in a row stop training.
#[derive(Debug, Clone)]
pub struct EarlyStop {
    best: f64,
    best_w: Vec<f64>,
    best_epoch: usize,
    best_train: f64,
    fails: usize,
    max_fail: usize,
}

impl EarlyStop {
    /// Starts from the initial weights and their validation error.
    pub fn new(w: &[f64], val: f64, train: f64, max_fail: usize) -> Self {
        Self { best: val, best_w: w.to_vec(), best_epoch: 0, best_train: train, fails: 0, max_fail }
    }

    /// Records an epoch; true when training must stop.
    pub fn update(&mut self, epoch: usize, w: &[f64], val: f64, train: f64) -> bool {
        if val.is_nan() {
            // No validation block: the last weights are the result.
            self.best_w.copy_from_slice(w);
            self.best_epoch = epoch;
            self.best_train = train;
            return false;
        }
        if val < self.best {
            self.best = val;
            self.best_w.copy_from_slice(w);
            self.best_epoch = epoch;
            self.best_train = train;
            self.fails = 0;
        } else if val > self.best {
            self.fails += 1;
        }
        self.fails >= self.max_fail
    }

    /// The kept weights, their epoch, training and validation errors.
    pub fn best(&self) -> (&[f64], usize, f64, f64) {
        (&self.best_w, self.best_epoch, self.best_train, self.best)
    }

    /// Puts the best weights into `weights` and reports the run (both
    /// trainers end this way).
    pub fn finish(&self, weights: &mut [f64], epochs: usize, stop: StopReason, start: std::time::Instant) -> Report {
        let (w, best_epoch, train_mse, val_mse) = self.best();
        weights.copy_from_slice(w);
        Report { epochs, best_epoch, train_mse, val_mse, stop, seconds: start.elapsed().as_secs_f64() }
    }
}
