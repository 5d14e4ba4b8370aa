//! `evflow check FILE`: validate and print the plan.

use super::graph_args::GraphArgs;
use anyhow::{anyhow, Result};
use evflow_engine::check::prune::{Folded, Pruning};
use evflow_engine::check::Pruned;
use evflow_engine::{Direction, Plan, PlanOptions};

/// Arguments of `evflow check`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Only validate: do not construct the plan's nodes (opens no files,
    /// loads no mesh). By default `check` also builds the plan as `run`
    /// does, without running anything, and prints what each node loaded (a
    /// mesh's bounds, up axis, scale and place on the screen) and what it
    /// then found constant and left out.
    #[arg(long)]
    no_build: bool,
}

/// Runs `evflow check`.
pub fn main(a: Args) -> Result<()> {
    let c = a.graph.load()?;
    let g = &c.graph;
    println!("graph `{}` ({}), format {}, base rate {} Hz", g.name, a.graph.file.display(), g.format, g.rate);
    if !g.description.is_empty() {
        println!("  {}", g.description);
    }
    // What an offline run leaves out before building anything.
    let pruning = Pruning::new(&c, true, true).map_err(|(i, e)| anyhow!("node `{}`: {e}", c.nodes[i].name))?;
    let order = pruning.order();
    println!("\nplan ({} of {} nodes, in execution order):", order.len(), c.nodes.len());
    for &i in &order {
        let n = &c.nodes[i];
        if let Some(k) = pruning.constant(i) {
            println!("  {:<16} {:<16} constant: {}", n.name, n.spec.name, k.reason);
            continue;
        }
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
    print_folded("replaced by constants (held, never run; docs/pruning.md):", &pruning.folded());
    print_pruned("left out (never constructed, their files never opened):", &pruning.pruned(), true);
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
    if !a.no_build {
        let plan = Plan::build(&c, &PlanOptions::default()).map_err(|e| anyhow!("{e}"))?;
        println!("\nbuilt: {} nodes, block {} base ticks", plan.schedule().len(), plan.max_block());
        for (node, lines) in plan.notes() {
            for l in lines {
                println!("  {node}: {l}");
            }
        }
        let before = pruning.folded();
        let folded: Vec<Folded> =
            plan.folded().iter().filter(|f| !before.iter().any(|b| b.node == f.node)).cloned().collect();
        let before = pruning.pruned();
        let pruned: Vec<Pruned> =
            plan.pruned().iter().filter(|p| !before.iter().any(|b| b.node == p.node)).cloned().collect();
        print_folded("replaced by constants when built:", &folded);
        print_pruned("left out when built (the nodes were built first, or never):", &pruned, false);
    } else {
        println!(
            "\n(a node may find more to leave out once it has loaded its files, e.g. `mesh.edges` on a mesh \
             without sharp edges: without `--no-build`, check builds the plan and says)"
        );
    }
    println!("\nok");
    Ok(())
}

/// Nodes replaced by constants, each with its outputs' values and why.
fn print_folded(title: &str, folded: &[Folded]) {
    if folded.is_empty() {
        return;
    }
    println!("\n{title}");
    for f in folded {
        let outs: Vec<String> = f
            .outputs
            .iter()
            .map(|(p, v)| match v {
                Some(v) => format!("{p} = {v}"),
                None => format!("{p} not computed (read by no node)"),
            })
            .collect();
        println!("  {:<16} {}: {}", f.node, outs.join(", "), f.reason);
    }
}

/// Nodes left out, and why; `nothing` says so when there are none.
fn print_pruned(title: &str, pruned: &[Pruned], nothing: bool) {
    if pruned.is_empty() {
        if nothing {
            println!("\nleft out: nothing");
        }
        return;
    }
    println!("\n{title}");
    for p in pruned {
        println!("  {:<16} {}", p.node, p.reason);
    }
}
