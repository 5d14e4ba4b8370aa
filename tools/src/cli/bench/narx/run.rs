//! The run of `evflow bench narx`: the lab data, training, scoring,
//! the throughput and the table (the module doc says what is measured).

use super::export;
use super::{Curve, Excitation, Measured, KNOWN};
use anyhow::{anyhow, Result};
use evflow_nodes::narx::eval;
use evflow_nodes::narx::fit::{fit, FitConfig};
use evflow_nodes::narx::labdata::{prbs, rbs, Lab};
use evflow_nodes::narx::model::{ClosedLoopScore, Condition, Model};
use evflow_nodes::narx::train::Options;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

/// Seed of the held-out excitation.
const HELDOUT_SEED: u64 = 77;
/// Seed of the lab noise of the held-out recording (training: the default, 11).
const HELDOUT_LAB_SEED: u64 = 99;

/// Arguments of `evflow bench narx`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Training samples at 1 kHz (3066 = six periods of PRBS9, §5.2.1).
    #[arg(long, default_value_t = 3066)]
    samples: usize,
    /// Held-out samples (another random binary sequence, other lab noise).
    #[arg(long, default_value_t = 3000)]
    heldout: usize,
    /// Training excitation.
    #[arg(long, value_enum, default_value_t = Excitation::Rbs)]
    excitation: Excitation,
    /// Largest number of Levenberg–Marquardt epochs.
    #[arg(long, default_value_t = 1000)]
    epochs: usize,
    /// Seed of the initial weights (and of the random binary sequence).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Closed-loop samples timed for the inference throughput.
    #[arg(long, default_value_t = 10_000_000)]
    inference_samples: usize,
    /// Also score, on the held-out data, the model each epoch budget gives
    /// (retrains once per budget, untimed): closed-loop error against
    /// training time.
    #[arg(long)]
    curve: bool,
    /// Write the data, the set-up and the results here (CSV and JSON).
    #[arg(long, value_name = "DIR")]
    export: Option<PathBuf>,
}

/// Runs the benchmark and prints a Markdown table.
pub fn main(a: Args) -> Result<()> {
    let u = match a.excitation {
        Excitation::Rbs => rbs(a.samples, a.seed),
        Excitation::Prbs20 => prbs(20, a.samples),
    };
    let x = Lab::default().force(&u);
    let uh = rbs(a.heldout, HELDOUT_SEED);
    let xh = Lab { seed: HELDOUT_LAB_SEED, ..Lab::default() }.force(&uh);
    if a.heldout <= KNOWN + 1 {
        return Err(anyhow!("--heldout {} leaves nothing to score after the {KNOWN} known samples", a.heldout));
    }
    let cfg = config(&a, a.epochs);

    eprintln!("training on {} samples …", a.samples);
    let mut epoch_seconds = Vec::new();
    let t = Instant::now();
    let model = fit(&x, &u, &cfg, &mut |e| epoch_seconds.push(e.seconds))?;
    let fit_seconds = t.elapsed().as_secs_f64();
    let heldout = score(&model, &xh, &uh)?;

    eprintln!("closed loop over {} samples …", a.inference_samples);
    let inference = throughput(&model, &xh, a.inference_samples)?;

    let mut curve = Vec::new();
    if a.curve {
        eprintln!("closed-loop error per epoch budget (retraining, untimed) …");
        for k in 0..=model.training.epochs {
            let m = fit(&x, &u, &config(&a, k), &mut |_| {})?;
            let s = score(&m, &xh, &uh)?;
            let seconds = if k == 0 { 0.0 } else { epoch_seconds[k - 1] };
            curve.push(Curve { epoch: k, seconds, score: s });
        }
    }
    let m = Measured { model, fit_seconds, epoch_seconds, heldout, inference, curve };
    print_table(&a, &m);
    if let Some(dir) = &a.export {
        export::write(dir, &export::Setup { x: &x, u: &u, xh: &xh, uh: &uh, cfg: &cfg, excitation: a.excitation }, &m)?;
        eprintln!("wrote {}", dir.display());
    }
    Ok(())
}

/// The fit configuration: `narx.train`'s defaults (15-10-5, k_y = 1,
/// k_x = 10, d from the cross-correlation up to 10, LM, 15 % validation).
fn config(a: &Args, max_epochs: usize) -> FitConfig {
    FitConfig {
        feedback: 1,
        input: 10,
        lookahead: None,
        options: Options { max_epochs, ..Options::default() },
        seed: a.seed,
        condition: Condition { mass_g: Some(85.0), speed_cm_s: Some(5.0) },
        ..FitConfig::default()
    }
}

/// Closed-loop score on a held-out recording: the first [`KNOWN`] samples
/// start the loop from the true states and are not scored.
pub fn score(m: &Model, x: &[f64], u: &[f64]) -> Result<ClosedLoopScore> {
    let est = m.closed_loop()?.run_known(x, u, KNOWN);
    eval::score(&est[KNOWN..], &u[KNOWN..]).ok_or_else(|| anyhow!("no held-out sample to score"))
}

/// Times `n` closed-loop samples (the held-out force over and over, after
/// one warm-up pass); returns the samples run and their seconds.
fn throughput(m: &Model, force: &[f64], n: usize) -> Result<(usize, f64)> {
    let mut cl = m.closed_loop()?;
    let mut sink = 0.0;
    for &v in force {
        sink += cl.step(v);
    }
    let passes = n.div_ceil(force.len()).max(1);
    let t = Instant::now();
    for _ in 0..passes {
        for &v in force {
            sink += cl.step(black_box(v));
        }
    }
    let seconds = t.elapsed().as_secs_f64();
    black_box(sink);
    Ok((passes * force.len(), seconds))
}

fn print_table(a: &Args, m: &Measured) {
    let t = &m.model.training;
    let d = &m.model.delays;
    println!(
        "network 15-10-5, taps: feedback {}, input {}, look-ahead {} ({} inputs, {} weights); {} training samples ({:?}), {} held-out",
        d.feedback,
        d.input,
        d.lookahead,
        d.n_inputs(),
        m.model.weights.len(),
        a.samples,
        a.excitation,
        a.heldout
    );
    println!();
    println!("| measure | value |");
    println!("|---|---:|");
    println!("| training wall time (fit, one core) | {:.3} s |", m.fit_seconds);
    println!("| of which Levenberg–Marquardt | {:.3} s |", t.seconds);
    println!("| epochs (best) | {} ({}), stop: {} |", t.epochs, t.best_epoch, t.stop.describe());
    println!("| time per epoch | {:.1} ms |", t.seconds / t.epochs.max(1) as f64 * 1e3);
    let h = &m.heldout;
    println!(
        "| held-out closed loop: transitions / sign / RMS | {:.3} / {:.3} / {:.3} ({} samples) |",
        h.transition_agreement, h.sign_agreement, h.rms, h.samples
    );
    if let Some(v) = &t.closed_loop {
        println!(
            "| validation block closed loop: transitions / sign / RMS | {:.3} / {:.3} / {:.3} |",
            v.transition_agreement, v.sign_agreement, v.rms
        );
    }
    let (n, s) = m.inference;
    println!(
        "| closed-loop inference | {:.2} M samples/s ({n} samples, {:.3} s, {:.0} ns/sample) |",
        n as f64 / s / 1e6,
        s,
        s / n as f64 * 1e9
    );
    if !m.curve.is_empty() {
        println!();
        println!("| epochs | training time | held-out transitions | sign | RMS |");
        println!("|---:|---:|---:|---:|---:|");
        for c in &m.curve {
            println!(
                "| {} | {:.3} s | {:.3} | {:.3} | {:.3} |",
                c.epoch, c.seconds, c.score.transition_agreement, c.score.sign_agreement, c.score.rms
            );
        }
    }
}
