//! `evflow run FILE`: the offline driver from the command line.

use super::graph_args::GraphArgs;
use anyhow::{anyhow, Result};
use evflow_engine::{run_offline, Plan, PlanOptions, RunOptions, RunReport};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Arguments of `evflow run`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Seed for every random stream (overrides the graph's `seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// Run length in seconds, for graphs with endless sources (finite
    /// sources still end the run early).
    #[arg(long)]
    duration: Option<f64>,
    /// Block size in base ticks (larger is faster offline; results do not
    /// depend on it).
    #[arg(long, default_value_t = 4096)]
    block: usize,
    /// Folder for the files the graph writes (relative output paths).
    #[arg(long, value_name = "DIR", default_value = ".")]
    out: std::path::PathBuf,
    /// Print only what the sinks report.
    #[arg(long, short)]
    quiet: bool,
    /// Also write the results (summaries and timings) as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<std::path::PathBuf>,
}

/// Runs `evflow run`.
pub fn main(a: Args) -> Result<()> {
    let checked = a.graph.load()?;
    if !a.quiet {
        for p in &checked.pruned {
            eprintln!("left out `{}`: {}", p.node, p.reason);
        }
    }
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;
    let opts = PlanOptions {
        max_block: a.block.max(1),
        seed: a.seed,
        base_dir: None,
        out_dir: Some(a.out.clone()),
        timing: true,
    };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| anyhow!("{e}"))?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second Ctrl-C (or a failure to install the handler) falls back to the default.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{spinner} {bar:40} {percent:>3}% {pos}/{len} ticks, {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let mut shown = false;
    let mut progress = |done: u64, total: u64| {
        if !shown && !a.quiet && started.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            shown = true;
        }
        bar.set_length(total);
        bar.set_position(done);
        !stop.load(Ordering::Relaxed)
    };
    let result = run_offline(&mut plan, RunOptions { duration: a.duration, progress: Some(&mut progress) });
    bar.finish_and_clear();
    let report = result.map_err(|e| anyhow!("{e}"))?;
    print_report(&report, plan.base_rate(), a.quiet);
    if let Some(path) = &a.json {
        std::fs::write(path, report_json(&report, plan.base_rate()))
            .map_err(|e| anyhow!("{}: cannot write results: {e}", path.display()))?;
    }
    Ok(())
}

/// A value for people: integers as integers, others with six significant digits.
fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.0}")
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:.5e}")
    } else {
        let digits = (5 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
        format!("{v:.digits$}")
    }
}

fn print_report(r: &RunReport, base_rate: f64, quiet: bool) {
    for (node, s) in &r.summaries {
        for l in &s.lines {
            println!("{node}: {l}");
        }
        for (k, v, unit) in &s.values {
            let unit = if unit.is_empty() || unit == "1" { String::new() } else { format!(" {unit}") };
            println!("{node}: {k} = {}{unit}", number(*v));
        }
    }
    if quiet {
        return;
    }
    let secs = r.elapsed.as_secs_f64();
    let simulated = r.ticks as f64 / base_rate;
    println!(
        "\nran {} ticks ({simulated:.3} s of signal) in {:.3} s: {:.0} ticks/s, {:.0}× real time",
        r.ticks,
        secs,
        r.ticks_per_second(),
        simulated / secs.max(1e-12)
    );
    let total: f64 = r.times.iter().map(|t| t.elapsed.as_secs_f64()).sum::<f64>().max(1e-12);
    println!("{:<16} {:<16} {:>10} {:>6}", "node", "type", "time", "share");
    for t in &r.times {
        let s = t.elapsed.as_secs_f64();
        println!("{:<16} {:<16} {:>8.3}ms {:>5.1}%", t.node, t.kind, s * 1e3, 100.0 * s / total);
    }
}

fn report_json(r: &RunReport, base_rate: f64) -> String {
    let summaries: serde_json::Map<String, serde_json::Value> = r
        .summaries
        .iter()
        .map(|(node, s)| {
            let values: serde_json::Map<String, serde_json::Value> =
                s.values.iter().map(|(k, v, _)| (k.clone(), serde_json::json!(v))).collect();
            (node.clone(), serde_json::json!({ "values": values, "lines": s.lines }))
        })
        .collect();
    let times: Vec<serde_json::Value> = r
        .times
        .iter()
        .map(|t| serde_json::json!({ "node": t.node, "type": t.kind, "seconds": t.elapsed.as_secs_f64() }))
        .collect();
    serde_json::to_string_pretty(&serde_json::json!({
        "ticks": r.ticks,
        "base_rate": base_rate,
        "seconds": r.elapsed.as_secs_f64(),
        "summaries": summaries,
        "times": times,
    }))
    .unwrap_or_default()
}
