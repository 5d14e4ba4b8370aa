//! `evflow check FILE`: validate and print the plan — every run of a sweep
//! validated (and built) as `evflow run` will see it.

use super::graph_args::GraphArgs;
use anyhow::{anyhow, bail, Result};
use evflow_engine::batch::{check_outputs, output_files, Failures};
use evflow_engine::check::prune::{Folded, Pruning};
use evflow_engine::check::Pruned;
use evflow_engine::sweep::{validate, Point};
use evflow_engine::{Checked, Direction, Plan, PlanOptions};
use evflow_tools::batch::sweep_runs::sweep_runs;

/// Arguments of `evflow check`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Sweep a graph variable over values as `evflow run --sweep` does
    /// (replaces the graph's `[sweep]` axis of that name); may be
    /// repeated. Every run of the sweep is checked.
    #[arg(long = "sweep", value_name = "NAME=V1,V2,…")]
    sweep: Vec<String>,
    /// Only validate: do not construct the plan's nodes (opens no files,
    /// loads no mesh). By default `check` also builds the plan of every
    /// run as `run` does, without running anything, and prints what each
    /// node of the first run loaded (a mesh's bounds, up axis, scale and
    /// place on the screen) and what it then found constant and left out.
    #[arg(long)]
    no_build: bool,
}

/// Runs `evflow check`.
///
/// A graph with a `[sweep]` (or `--sweep`) is checked run by run, as
/// `evflow run` checks it: each run's values are validated (a `[vars]`
/// default that every run overrides is not), no two runs may write one
/// file, and each run's plan is built. The plan printed is the first
/// run's; a run that fails is named with its reason, and check then
/// exits 1.
pub fn main(a: Args) -> Result<()> {
    let overrides = a.graph.overrides()?;
    let (graph, swept, all) = sweep_runs(&a.graph.file, &overrides, &a.sweep).map_err(|e| anyhow!("{e}"))?;
    let total = all.len();
    let is_sweep = total > 1;
    let registry = evflow_nodes::registry();
    let mut failures = Failures::new();
    let mut runs: Vec<(Point, Checked)> = Vec::with_capacity(total);
    for v in validate(&graph, &registry, &overrides, all, 0..total) {
        match v.checked {
            Ok(c) => runs.push((v.point, c)),
            Err(e) if !is_sweep => bail!("{e}"),
            Err(e) => failures.push(v.point.label(), e),
        }
    }
    let Some((first, c)) = runs.first() else {
        bail!("no run of the sweep validates: {}", failures.summary_as(total, "sweep runs", "fail").trim_end());
    };
    let g = &c.graph;
    println!("graph `{}` ({}), format {}, base rate {} Hz", g.name, a.graph.file.display(), g.format, g.rate);
    if !g.description.is_empty() {
        println!("  {}", g.description);
    }
    // What an offline run leaves out before building anything.
    let pruning = Pruning::new(c, true, true).map_err(|(i, e)| anyhow!("node `{}`: {e}", c.nodes[i].name))?;
    let order = pruning.order();
    let of_run = if is_sweep { format!(", the first run's: {}", first.label()) } else { String::new() };
    println!("\nplan ({} of {} nodes, in execution order{of_run}):", order.len(), c.nodes.len());
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
        let outs: Vec<String> = (n.ports.iter().enumerate())
            .filter(|(_, p)| p.dir == Direction::Out)
            .map(|(k, p)| format!("{} [{}]", p.name, evflow_engine::check::units::output_unit(c, i, k)))
            .collect();
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
    if !swept.is_empty() {
        let shown: Vec<String> = swept
            .iter()
            .map(|ax| match &ax.files {
                Some(p) => format!("{} ({} files matching `{p}`)", ax.name, ax.values.len()),
                None => format!("{} ({} values)", ax.name, ax.values.len()),
            })
            .collect();
        let plural = if total == 1 { "" } else { "s" };
        println!("\nsweep: {} → {total} run{plural} (`evflow run` runs them all)", shown.join(" × "));
    }
    for p in &g.plots {
        let fit =
            if p.fit == evflow_engine::graph::Fit::None { String::new() } else { format!(", {} fit", p.fit.name()) };
        println!("plot {}: {} against {}{fit}", p.file, p.y.join(", "), p.x);
    }
    // Runs that would write one file would overwrite each other: `run`
    // refuses them before running anything, and so does check.
    let outputs: Vec<_> = runs.iter().map(|(p, c)| (p.label(), output_files(c, std::path::Path::new("out")))).collect();
    check_outputs(&outputs).map_err(|e| anyhow!("{}: {e}", graph.file.display()))?;
    if !a.no_build {
        let opts = PlanOptions { check_only: true, ..PlanOptions::default() };
        let mut shown = false;
        for (p, c) in &runs {
            let plan = match Plan::build(c, &opts) {
                Ok(plan) => plan,
                Err(e) if !is_sweep => bail!("{e}"),
                Err(e) => {
                    failures.push(p.label(), e);
                    continue;
                }
            };
            if shown {
                continue;
            }
            shown = true;
            let whose = if is_sweep { format!(" (run {})", p.label()) } else { String::new() };
            println!("\nbuilt{whose}: {} nodes, block {} base ticks", plan.schedule().len(), plan.max_block());
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
        }
        if is_sweep && failures.is_empty() {
            println!("\nbuilt every run of the sweep ({total})");
        }
    } else {
        println!(
            "\n(a node may find more to leave out once it has loaded its files, e.g. `mesh.edges` on a mesh \
             without sharp edges: without `--no-build`, check builds the plan and says)"
        );
    }
    if !failures.is_empty() {
        bail!("{}", failures.summary_as(total, "sweep runs", "would fail (as `evflow run` runs them)").trim_end());
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
