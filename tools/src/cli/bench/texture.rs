//! `evflow bench texture`: per-tick compute time of the live texture chain
//! (`graphs/texture-live.toml`), split into the ticks where `interp` starts
//! a new table (every 100 ms, the 10 Hz update of §6.5.1) and the others,
//! so that the update's cost shows if it ever bunches into one tick.

use super::stats::percentile;
use crate::cli::graph_args::load_with;
use anyhow::{anyhow, Result};
use evflow_engine::{Plan, PlanOptions};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evflow bench texture`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Ticks timed (after 1000 warm-up ticks).
    #[arg(long, default_value_t = 60_000)]
    ticks: usize,
    /// The live chain to time.
    #[arg(long, default_value = "graphs/texture-live.toml")]
    graph: PathBuf,
    /// Set a graph variable or node parameter (`name=value`, repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

/// Runs the benchmark and prints a Markdown table.
pub fn main(a: Args) -> Result<()> {
    let checked = load_with(&a.graph, &a.set)?;
    let opts = PlanOptions { max_block: 1, seed: None, base_dir: None, out_dir: None, timing: false };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| anyhow!("{e}"))?;
    let update_every = (plan.base_rate() / 10.0).round().max(1.0) as u64;
    for _ in 0..1000 {
        plan.tick().map_err(|e| anyhow!("{e}"))?;
    }
    let (mut update, mut other) = (Vec::new(), Vec::with_capacity(a.ticks));
    let mut slowest = (0u64, 0.0f64);
    for _ in 0..a.ticks.max(1) {
        let k = plan.ticks();
        let t = Instant::now();
        plan.tick().map_err(|e| anyhow!("{e}"))?;
        let us = t.elapsed().as_secs_f64() * 1e6;
        if us > slowest.1 {
            slowest = (k, us);
        }
        if k % update_every == 0 {
            update.push(us);
        } else {
            other.push(us);
        }
    }
    let mut all: Vec<f64> = update.iter().chain(&other).copied().collect();
    println!("| ticks | count | p50 | p99 | p99.9 | max |");
    println!("|---|---:|---:|---:|---:|---:|");
    for (name, v) in [("all", &mut all), ("table starts (10 Hz)", &mut update), ("others", &mut other)] {
        println!(
            "| {name} | {} | {:.2} µs | {:.2} µs | {:.2} µs | {:.1} µs |",
            v.len(),
            percentile(v, 0.5),
            percentile(v, 0.99),
            percentile(v, 0.999),
            percentile(v, 1.0)
        );
    }
    println!("\nslowest tick: {} ({:.1} µs)", slowest.0, slowest.1);
    Ok(())
}
