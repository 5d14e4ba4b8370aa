//! `evflow report foaw`: velocity estimation from IR-frame positions —
//! FOAW (best- and end-fit) against finite differences and moving averages
//! on known trajectories sampled at 40 Hz and quantized: RMS error and lag
//! per trajectory (a Markdown table), the velocity traces of the speed-step
//! trajectory and error against lag for every estimator (PNG figures).

use anyhow::{Context, Result};
use evflow_nodes::filters::foaw::compare::{sample, Estimator, TRAJECTORIES};
use evflow_nodes::filters::foaw::estimator::Fit;
use evflow_study::precision::foaw::{estimators, family, table};
use evflow_tools::plot::{Plot, Series};
use std::path::PathBuf;

/// Arguments of `evflow report foaw`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the PNG figures.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Position sample rate, Hz (an IR frame reports at 40 Hz).
    #[arg(long, default_value_t = 40.0)]
    rate: f64,
    /// Position quantization step, mm.
    #[arg(long, default_value_t = 0.5)]
    step: f64,
    /// Seconds of each trajectory (the first 0.5 s are not scored).
    #[arg(long, default_value_t = 6.0)]
    seconds: f64,
}

/// Runs `evflow report foaw`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.rate > 0.0 && a.rate.is_finite(), "--rate {}: must be a positive number of Hz", a.rate);
    anyhow::ensure!(a.step >= 0.0 && a.step.is_finite(), "--step {}: must be ≥ 0 mm", a.step);
    anyhow::ensure!(a.seconds > 1.0, "--seconds {}: needs more than 1 s", a.seconds);
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let step = a.step * 1e-3;
    let ests = estimators(step);
    println!(
        "Velocity from positions sampled at {} Hz, quantized to {} mm ({} s per trajectory).\n",
        a.rate, a.step, a.seconds
    );
    print!("| estimator |");
    for tr in &TRAJECTORIES {
        print!(" {} RMS (cm/s) | lag (ms) |", tr.name);
    }
    println!(" mean RMS (cm/s) |");
    println!("|---|{}---:|", "---:|---:|".repeat(TRAJECTORIES.len()));
    let mut scatter: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (e, scores) in ests.iter().zip(table(&ests, a.rate, a.seconds, step)) {
        print!("| {} |", e.label());
        let mut total = 0.0;
        let mut points = Vec::new();
        for s in &scores {
            print!(" {:.2} | {:.0} |", s.rms * 100.0, s.lag * 1e3);
            total += s.rms * 100.0;
            points.push((s.lag * 1e3, s.rms * 100.0));
        }
        println!(" {:.2} |", total / TRAJECTORIES.len() as f64);
        let family = family(e);
        match scatter.iter_mut().find(|(n, _)| n == family) {
            Some((_, p)) => p.extend(points),
            None => scatter.push((family.to_string(), points)),
        }
    }

    let tradeoff = Plot {
        title: format!("Velocity estimation at {} Hz, {} mm steps: error against lag", a.rate, a.step),
        x_label: "lag (ms)".into(),
        y_label: "RMS velocity error (cm/s)".into(),
        log_x: false,
        log_y: true,
        series: scatter.into_iter().map(|(n, p)| Series::points(n, p)).collect(),
        ..Default::default()
    };
    let steps = &TRAJECTORIES[1];
    let y = sample(steps, a.rate, a.seconds, step);
    let t = |k: usize| k as f64 / a.rate;
    let trace = |e: &Estimator| -> Vec<(f64, f64)> {
        e.run(&y, 1.0 / a.rate).iter().enumerate().map(|(k, v)| (t(k), v * 100.0)).collect()
    };
    let truth: Vec<(f64, f64)> = (0..(a.seconds * 1000.0) as usize)
        .map(|k| (k as f64 * 1e-3, (steps.velocity)(k as f64 * 1e-3) * 100.0))
        .collect();
    let foaw_default = Estimator::Foaw(Fit::Best, 0.8 * step, 4);
    let traces = Plot {
        title: format!("Velocity estimates: {}", steps.name),
        x_label: "time (s)".into(),
        y_label: "velocity (cm/s)".into(),
        log_x: false,
        log_y: false,
        series: vec![
            Series::line("true velocity", truth),
            Series::line("finite difference", trace(&Estimator::FiniteDifference)),
            Series::line("moving average (5)", trace(&Estimator::MovingAverage(5))),
            Series::line(foaw_default.label(), trace(&foaw_default)),
        ],
        ..Default::default()
    };
    println!();
    for (plot, name) in [(&tradeoff, "foaw-tradeoff.png"), (&traces, "foaw-steps.png")] {
        super::save_png(plot, &a.out.join(name));
    }
    Ok(())
}
