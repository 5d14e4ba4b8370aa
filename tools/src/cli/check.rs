//! `evflow check FILE`: validate and print the plan.

use super::graph_args::GraphArgs;
use anyhow::{anyhow, Result};
use evflow_engine::{Direction, Plan, PlanOptions};

/// Arguments of `evflow check`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Also construct and prepare the plan's nodes (opens their files),
    /// without running anything.
    #[arg(long)]
    build: bool,
}

/// Runs `evflow check`.
pub fn main(a: Args) -> Result<()> {
    let c = a.graph.load()?;
    let g = &c.graph;
    println!("graph `{}` ({}), format {}, base rate {} Hz", g.name, a.graph.file.display(), g.format, g.rate);
    if !g.description.is_empty() {
        println!("  {}", g.description);
    }
    println!("\nplan ({} of {} nodes, in execution order):", c.order.len(), c.nodes.len());
    for &i in &c.order {
        let n = &c.nodes[i];
        let ins: Vec<String> = c
            .edges
            .iter()
            .filter(|e| e.to.0 == i)
            .map(|e| {
                format!(
                    "{}←{}.{}",
                    n.ports[e.to.1].name, c.nodes[e.from.0].name, c.nodes[e.from.0].ports[e.from.1].name
                )
            })
            .collect();
        let outs: Vec<String> =
            n.ports.iter().filter(|p| p.dir == Direction::Out).map(|p| format!("{} [{}]", p.name, p.unit)).collect();
        println!(
            "  {:<16} {:<16} {:>9} Hz ({})  in: {}  out: {}",
            n.name,
            n.spec.name,
            n.ratio.hz(g.rate),
            n.ratio,
            if ins.is_empty() { "-".into() } else { ins.join(", ") },
            if outs.is_empty() { "-".into() } else { outs.join(", ") }
        );
    }
    if c.pruned.is_empty() {
        println!("\nleft out: nothing");
    } else {
        println!("\nleft out (never constructed, their files never opened):");
        for p in &c.pruned {
            println!("  {:<16} {}", p.node, p.reason);
        }
    }
    if !c.in_cycle.is_empty() {
        let names: Vec<&str> = c.in_cycle.iter().map(|&i| c.nodes[i].name.as_str()).collect();
        println!("\nfeedback cycles broken by: {}", names.join(", "));
    }
    if !g.sweep.is_empty() {
        let sweep = evflow_engine::sweep_files::expand(
            g,
            &a.graph.overrides()?,
            &evflow_nodes::recording::sweep_fields::sweep_fields,
        )
        .map_err(|e| anyhow!("{}: {e}", g.file.display()))?;
        let axes: Vec<String> = sweep
            .iter()
            .map(|ax| match &ax.files {
                Some(p) => format!("{} ({} files matching `{p}`)", ax.name, ax.values.len()),
                None => format!("{} ({} values)", ax.name, ax.values.len()),
            })
            .collect();
        let runs = evflow_engine::sweep::points(&sweep, &[], &a.graph.overrides()?).len();
        println!(
            "
sweep: {} → {runs} runs (`evflow run` runs them all)",
            axes.join(" × ")
        );
    }
    for p in &g.plots {
        let fit =
            if p.fit == evflow_engine::graph::Fit::None { String::new() } else { format!(", {} fit", p.fit.name()) };
        println!("plot {}: {} against {}{fit}", p.file, p.y.join(", "), p.x);
    }
    if a.build {
        let plan = Plan::build(&c, &PlanOptions::default()).map_err(|e| anyhow!("{e}"))?;
        println!("\nbuilt: {} nodes, block {} base ticks", plan.schedule().len(), plan.max_block());
    }
    println!("\nok");
    Ok(())
}
