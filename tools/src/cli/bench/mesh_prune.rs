//! `evflow bench mesh --pruning`: the per-tick compute time of a live chain
//! (by default `graphs/mesh-live.toml` on its Gaussian scenes) with the
//! planner's constants (`docs/pruning.md`: `mesh.edges` on meshes without a
//! sharp edge is held, never stepped) against the same plan without them.
//! The two plans tick in alternating rounds, so load on the machine falls
//! on both alike.

use super::stats::percentile;
use crate::cli::graph_args::load_with;
use anyhow::{anyhow, Result};
use evflow_engine::plan::Folding;
use evflow_engine::{Plan, PlanOptions};
use std::path::Path;
use std::time::Instant;

/// Per-tick times (µs) of one plan.
struct Times {
    label: &'static str,
    plan: Plan,
    us: Vec<f64>,
}

/// Times `ticks` ticks of each plan in `rounds` alternating rounds (after
/// 1000 warm-up ticks each) and prints a Markdown table.
pub fn compare(graph: &Path, sets: &[String], ticks: usize, rounds: usize) -> Result<()> {
    let checked = load_with(graph, sets)?;
    let opts = PlanOptions { max_block: 1, timing: false, ..Default::default() };
    let build = |folding| Plan::build_with(&checked, &opts, folding).map_err(|e| anyhow!("{e}"));
    let mut runs = [
        Times { label: "without pruning", plan: build(Folding::Off)?, us: Vec::new() },
        Times { label: "with pruning", plan: build(Folding::On)?, us: Vec::new() },
    ];
    let folded: Vec<String> = runs[1].plan.folded().iter().map(|f| format!("`{}` ({})", f.node, f.reason)).collect();
    eprintln!("held as constants: {}", if folded.is_empty() { "none".into() } else { folded.join("; ") });
    let per_round = (ticks / rounds.max(1)).max(1);
    for r in &mut runs {
        for _ in 0..1000 {
            r.plan.tick().map_err(|e| anyhow!("{e}"))?;
        }
        r.us.reserve(per_round * rounds.max(1));
    }
    for _ in 0..rounds.max(1) {
        for r in &mut runs {
            for _ in 0..per_round {
                let t = Instant::now();
                r.plan.tick().map_err(|e| anyhow!("{e}"))?;
                r.us.push(t.elapsed().as_secs_f64() * 1e6);
            }
        }
    }
    println!("| plan | nodes stepped | tick mean | tick p50 | tick p99 | tick max |");
    println!("|---|---:|---:|---:|---:|---:|");
    let mut means = Vec::new();
    for r in &mut runs {
        let mean = r.us.iter().sum::<f64>() / r.us.len() as f64;
        means.push(mean);
        let stepped = r.plan.len() - r.plan.folded().len();
        println!(
            "| {} | {} | {:.2} µs | {:.2} µs | {:.2} µs | {:.1} µs |",
            r.label,
            stepped,
            mean,
            percentile(&mut r.us, 0.5),
            percentile(&mut r.us, 0.99),
            percentile(&mut r.us, 1.0)
        );
    }
    println!("\nmean per tick with pruning / without: {:.3}", means[1] / means[0]);
    Ok(())
}
