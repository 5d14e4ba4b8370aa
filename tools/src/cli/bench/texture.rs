//! `evflow bench texture`: per-tick compute time of the live texture chain
//! (`graphs/texture-live.toml`), split into the ticks where `interp` starts
//! a new table (every 100 ms, the 10 Hz update of §6.5.1) and the others,
//! so that the update's cost shows if it ever bunches into one tick.

use super::stats::percentile;
use crate::cli::graph_args::load_with;
use anyhow::{anyhow, Result};
use evflow_engine::live::thread_cpu_ns;
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
    let mut plan = super::tick_plan(&checked)?;
    let update_every = (plan.base_rate() / 10.0).round().max(1.0) as u64;
    for _ in 0..1000 {
        plan.tick().map_err(|e| anyhow!("{e}"))?;
    }
    // Wall time (what a deadline sees, the machine's stalls included) and
    // the thread's CPU time (what the tick itself costs).
    let n = a.ticks.max(1);
    let (mut wall, mut cpu, mut starts) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        let k = plan.ticks();
        let (c0, t) = (thread_cpu_ns(), Instant::now());
        plan.tick().map_err(|e| anyhow!("{e}"))?;
        let us = t.elapsed().as_secs_f64() * 1e6;
        let c = thread_cpu_ns().zip(c0).map_or(f64::NAN, |(c1, c0)| (c1 - c0) as f64 * 1e-3);
        wall.push(us);
        cpu.push(c);
        starts.push(k % update_every == 0);
    }
    for (clock, v) in [("wall-clock time", &wall), ("thread CPU time", &cpu)] {
        let pick = |table: Option<bool>| -> Vec<f64> {
            v.iter().zip(&starts).filter(|(_, &s)| table.is_none_or(|t| t == s)).map(|(x, _)| *x).collect()
        };
        let slowest = v.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |(i, _)| i);
        println!("\nper tick, {clock}:\n");
        println!("| ticks | count | p50 | p99 | p99.9 | max |");
        println!("|---|---:|---:|---:|---:|---:|");
        for (name, mut s) in
            [("all", pick(None)), ("table starts (10 Hz)", pick(Some(true))), ("others", pick(Some(false)))]
        {
            println!(
                "| {name} | {} | {:.2} µs | {:.2} µs | {:.2} µs | {:.1} µs |",
                s.len(),
                percentile(&mut s, 0.5),
                percentile(&mut s, 0.99),
                percentile(&mut s, 0.999),
                percentile(&mut s, 1.0)
            );
        }
        println!("\nslowest tick: {} ({:.1} µs)", 1000 + slowest, v[slowest]);
    }
    Ok(())
}
