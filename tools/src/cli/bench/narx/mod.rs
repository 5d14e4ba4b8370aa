//! `evflow bench narx`: training time and closed-loop inference throughput
//! of the default inverse NARX model (dissertation §5.2.1, docs/narx.md)
//! on data recorded on the simulated lab, with the closed-loop error it
//! reaches on a held-out recording — error against run time.
//!
//! Training data: `--samples` (3066, the dissertation's six periods of
//! PRBS9) of a random binary sequence (or an order-20 PRBS) through the
//! nominal virtual display and force sensor at 85 g and 5 cm/s,
//! high-passed at 10 Hz (`narx::labdata`). Held-out data: another random
//! binary sequence recorded with other lab noise. Network: 15-10-5 tanh,
//! one feedback tap, ten input taps, look-ahead from the cross-correlation,
//! Levenberg–Marquardt with early stopping on the last 15 % (the defaults
//! of `narx.train`), seeded. `--export DIR` writes the data, the set-up
//! (including the initial weights) and the results as CSV and JSON, for
//! `bench/narx_peer.py`, which trains the same network in Python on the
//! same data.

pub mod export;
pub mod run;

pub use run::{main, Args};

use evflow_nodes::narx::model::{ClosedLoopScore, Model};

/// Samples at the start of the held-out run fed back with the true u (the
/// loop's initial states, as MATLAB's `preparets`); not scored.
pub const KNOWN: usize = 60;

/// The training excitation.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Excitation {
    /// Random binary sequence (independent ±1 coin flips, seeded).
    Rbs,
    /// PRBS of order 20 (as graphs/model-build.toml).
    Prbs20,
}

/// What one run measured.
pub struct Measured {
    /// The trained model.
    pub model: Model,
    /// Wall time of the whole fit (alignment, regressors, training, scoring), s.
    pub fit_seconds: f64,
    /// Seconds since training started at the end of each epoch.
    pub epoch_seconds: Vec<f64>,
    /// Closed-loop score on the held-out recording.
    pub heldout: ClosedLoopScore,
    /// Closed-loop samples timed and their seconds.
    pub inference: (usize, f64),
    /// Closed-loop error per epoch budget (with `--curve`).
    pub curve: Vec<Curve>,
}

/// The closed-loop error of the model an epoch budget gives.
pub struct Curve {
    /// Epoch budget (0 = the initial weights).
    pub epoch: usize,
    /// Seconds of training the budget took (in the timed run).
    pub seconds: f64,
    /// Held-out closed-loop score.
    pub score: ClosedLoopScore,
}
