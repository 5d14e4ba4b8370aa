//! Files of `evflow bench narx --export DIR`, for a peer implementation
//! (`bench/narx_peer.py`) to train and score the same network on the same
//! data without evflow:
//!
//! * `train.csv`, `heldout.csv` — columns `force_N,actuation`, one row per
//!   sample at 1 kHz, every number printed so it reads back bit for bit;
//! * `setup.json` — the network, taps, normalization, validation split,
//!   LM options, the number of known samples starting the held-out loop,
//!   and the initial (Nguyen–Widrow, seeded) weights;
//! * `rust.json` — what this run measured: training time per epoch, stop,
//!   the trained weights, the held-out closed-loop score, the inference
//!   throughput and (with `--curve`) the error per epoch budget.
//!
//! Weights are laid out layer after layer, each weight matrix row-major
//! (one row per neuron) followed by its biases, as in the model file.

use super::{Excitation, Measured, KNOWN};
use anyhow::{Context, Result};
use evflow_nodes::narx::fit::FitConfig;
use evflow_nodes::narx::net::Mlp;
use evflow_nodes::rng::Rng;
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

/// The data and configuration of a run.
pub struct Setup<'a> {
    /// Training force, N.
    pub x: &'a [f64],
    /// Training actuation.
    pub u: &'a [f64],
    /// Held-out force, N.
    pub xh: &'a [f64],
    /// Held-out actuation.
    pub uh: &'a [f64],
    /// The fit configuration.
    pub cfg: &'a FitConfig,
    /// The training excitation.
    pub excitation: Excitation,
}

/// Writes the four files into `dir` (created if missing), each through a
/// temporary file and a rename.
pub fn write(dir: &Path, s: &Setup<'_>, m: &Measured) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    put(&dir.join("train.csv"), &csv(s.x, s.u))?;
    put(&dir.join("heldout.csv"), &csv(s.xh, s.uh))?;
    let model = &m.model;
    let mut init = Mlp::new(model.architecture.inputs, &model.architecture.hidden)?;
    init.init_nguyen_widrow(&mut Rng::new(s.cfg.seed));
    let o = &s.cfg.options;
    let t = &model.training;
    let setup = json!({
        "format": "evflow-narx-bench",
        "version": 1,
        "rate_hz": model.rate_hz,
        "excitation": format!("{:?}", s.excitation).to_lowercase(),
        "condition": model.condition,
        "hidden": model.architecture.hidden,
        "delays": model.delays,
        "normalization": model.normalization,
        "validation_fraction": s.cfg.validation,
        "train_rows": t.train_rows,
        "validation_rows": t.validation_rows,
        "known": KNOWN,
        "lm": { "max_epochs": o.max_epochs, "max_fail": o.max_fail, "min_grad": o.min_grad,
                "mu": o.mu, "mu_dec": o.mu_dec, "mu_inc": o.mu_inc, "mu_max": o.mu_max },
        "seed": s.cfg.seed,
        "initial_weights": init.weights(),
    });
    put(&dir.join("setup.json"), &serde_json::to_string_pretty(&setup)?)?;
    let (n, secs) = m.inference;
    let curve: Vec<_> =
        m.curve.iter().map(|c| json!({ "epoch": c.epoch, "seconds": c.seconds, "heldout": c.score })).collect();
    let rust = json!({
        "fit_seconds": m.fit_seconds,
        "train_seconds": t.seconds,
        "epoch_seconds": m.epoch_seconds,
        "epochs": t.epochs,
        "best_epoch": t.best_epoch,
        "stop": t.stop,
        "train_mse": t.train_mse,
        "validation_mse": t.validation_mse,
        "validation_block": t.closed_loop,
        "heldout": m.heldout,
        "inference": { "samples": n, "seconds": secs, "samples_per_second": n as f64 / secs },
        "curve": curve,
        "weights": model.weights,
    });
    put(&dir.join("rust.json"), &serde_json::to_string_pretty(&rust)?)?;
    Ok(())
}

/// Two columns, force and actuation, with a header.
fn csv(x: &[f64], u: &[f64]) -> String {
    let mut s = String::with_capacity(x.len() * 48);
    s.push_str("force_N,actuation\n");
    for (a, b) in x.iter().zip(u) {
        // `{:?}` prints the shortest decimal that reads back to the same f64.
        let _ = writeln!(s, "{a:?},{b:?}");
    }
    s
}

/// Writes `text` to `path` through `path.tmp` and a rename.
fn put(path: &Path, text: &str) -> Result<()> {
    evflow_engine::atomic_file::write_atomically(path, text).with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::csv;

    #[test]
    fn csv_numbers_read_back_bit_for_bit() {
        let x = [0.1 + 0.2, -1e-300, 1.0 / 3.0, 12345.678e10];
        let u = [1.0, -1.0, 0.0, f64::MIN_POSITIVE];
        let text = csv(&x, &u);
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("force_N,actuation"));
        for (line, (a, b)) in lines.zip(x.iter().zip(&u)) {
            let (p, q) = line.split_once(',').unwrap();
            assert_eq!(p.parse::<f64>().unwrap().to_bits(), a.to_bits());
            assert_eq!(q.parse::<f64>().unwrap().to_bits(), b.to_bits());
        }
    }
}
