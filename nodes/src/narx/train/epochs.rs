//! The epoch loop both trainers share ([`super::lm`], [`super::adam`]):
//! the errors before training, the early stop on the validation block
//! ([`super::EarlyStop`]), an [`Epoch`] reported after every epoch that
//! ran, the reasons to stop that do not depend on the algorithm (no rows,
//! a zero error, `max_epochs`), and the best weights put back at the end.
//! A trainer gives one epoch's step.

use super::{mse, Data, EarlyStop, Epoch, Options, Report, StopReason};
use crate::narx::net::Mlp;
use std::time::Instant;

/// What one epoch's step did.
#[derive(Debug, Clone, Copy)]
pub(super) struct Stepped {
    /// The gradient norm it reports.
    pub gradient: f64,
    /// μ after it (0 when the algorithm has none).
    pub mu: f64,
    /// A reason to stop once the epoch is reported.
    pub stop: Option<StopReason>,
}

/// Trains `net` with `step` epoch after epoch: `step` updates the weights
/// and the training error (`perf`, the MSE on `train`), or returns the
/// reason to stop before the epoch counts. Stops early on `val`; returns
/// the report of the best weights, which `net` is left with.
pub(super) fn run(
    net: &mut Mlp,
    train: &Data<'_>,
    val: &Data<'_>,
    opts: &Options,
    progress: &mut dyn FnMut(&Epoch),
    mut step: impl FnMut(&mut Mlp, &mut f64) -> Result<Stepped, StopReason>,
) -> Report {
    let start = Instant::now();
    let mut perf = mse(net, train);
    let mut stop = EarlyStop::new(net.weights(), mse(net, val), perf, opts.max_fail);
    let mut epochs = 0;
    let mut reason = StopReason::MaxEpochs;
    for epoch in 1..=opts.max_epochs {
        if train.is_empty() {
            break;
        }
        if perf == 0.0 {
            reason = StopReason::Goal;
            break;
        }
        let stepped = match step(net, &mut perf) {
            Ok(s) => s,
            Err(r) => {
                reason = r;
                break;
            }
        };
        epochs = epoch;
        let vperf = mse(net, val);
        progress(&Epoch {
            epoch,
            train_mse: perf,
            val_mse: vperf,
            gradient: stepped.gradient,
            mu: stepped.mu,
            seconds: start.elapsed().as_secs_f64(),
        });
        if let Some(r) = stepped.stop {
            reason = r;
            break;
        }
        if stop.update(epoch, net.weights(), vperf, perf) {
            reason = StopReason::ValidationStop;
            break;
        }
    }
    stop.finish(net.weights_mut(), epochs, reason, start)
}
