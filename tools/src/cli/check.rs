//! `evflow check FILE`: validate and print the plan — every run of a sweep
//! validated (and built) as `evflow run` will see it.

use super::graph_args::GraphArgs;
use anyhow::{anyhow, bail, Result};
use evflow_engine::batch::{check_outputs, output_files};
use evflow_engine::check::prune::{Folded, Pruning};
use evflow_engine::check::Pruned;
use evflow_engine::graph::Axis;
use evflow_tools::plan_description::{build_runs, validate_runs, Built, PlanDescription, PlanRole};

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
    let mut v = validate_runs(&a.graph.file, &overrides, &a.sweep).map_err(|e| anyhow!(e))?;
    let (total, is_sweep) = (v.total, v.is_sweep());
    let (first, c) = &v.runs[0];
    let g = &c.graph;
    println!("graph `{}` ({}), format {}, base rate {} Hz", g.name, a.graph.file.display(), g.format, g.rate);
    if !g.description.is_empty() {
        println!("  {}", g.description);
    }
    // What an offline run leaves out before building anything.
    let pruning = Pruning::new(c, true, true).map_err(|(i, e)| anyhow!("node `{}`: {e}", c.nodes[i].name))?;
    let of_run = if is_sweep { format!(", the first run's: {}", first.label()) } else { String::new() };
    print_plan(&PlanDescription::new(c, &pruning), &of_run);
    print_sweep(&v.swept, total);
    for p in &g.plots {
        let fit =
            if p.fit == evflow_engine::graph::Fit::None { String::new() } else { format!(", {} fit", p.fit.name()) };
        println!("plot {}: {} against {}{fit}", p.file, p.y.join(", "), p.x);
    }
    // Runs that would write one file would overwrite each other: `run`
    // refuses them before running anything, and so does check.
    let outputs: Vec<_> =
        v.runs.iter().map(|(p, c)| (p.label(), output_files(c, std::path::Path::new("out")))).collect();
    check_outputs(&outputs).map_err(|e| anyhow!("{}: {e}", v.graph.file.display()))?;
    if !a.no_build {
        if let Some(b) = build_runs(&v.runs, &pruning, is_sweep, &mut v.failures).map_err(|e| anyhow!(e))? {
            print_built(&b);
        }
        if is_sweep && v.failures.is_empty() {
            println!("\nbuilt every run of the sweep ({total})");
        }
    } else {
        println!(
            "\n(a node may find more to leave out once it has loaded its files, e.g. `mesh.edges` on a mesh \
             without sharp edges: without `--no-build`, check builds the plan and says)"
        );
    }
    if !v.failures.is_empty() {
        bail!("{}", v.failures.summary_as(total, "sweep runs", "would fail (as `evflow run` runs them)").trim_end());
    }
    println!("\nok");
    Ok(())
}

/// The plan (`of_run`: whose, in a sweep): each node in execution order,
/// what replaces nodes, what is left out, what breaks feedback cycles.
fn print_plan(plan: &PlanDescription, of_run: &str) {
    println!("\nplan ({} of {} nodes, in execution order{of_run}):", plan.nodes.len(), plan.of);
    for n in &plan.nodes {
        match &n.role {
            PlanRole::Constant(reason) => println!("  {:<16} {:<16} constant: {reason}", n.name, n.type_name),
            PlanRole::Runs { hz, ratio, inputs, outputs } => println!(
                "  {:<16} {:<16} {:>9} Hz ({})  in: {}  out: {}",
                n.name,
                n.type_name,
                hz,
                ratio,
                if inputs.is_empty() { "-".into() } else { inputs.join(", ") },
                if outputs.is_empty() { "-".into() } else { outputs.join(", ") }
            ),
        }
    }
    print_folded("replaced by constants (held, never run; docs/pruning.md):", &plan.folded);
    print_pruned("left out (never constructed, their files never opened):", &plan.pruned, true);
    if !plan.cycles.is_empty() {
        println!("\nfeedback cycles broken by: {}", plan.cycles.join(", "));
    }
}

/// The axes swept and the runs they make.
fn print_sweep(swept: &[Axis], total: usize) {
    if swept.is_empty() {
        return;
    }
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

/// What building the first run's plan found.
fn print_built(b: &Built) {
    let whose = if b.run.is_empty() { String::new() } else { format!(" (run {})", b.run) };
    println!("\nbuilt{whose}: {} nodes, block {} base ticks", b.nodes, b.block);
    for (node, lines) in &b.notes {
        for l in lines {
            println!("  {node}: {l}");
        }
    }
    print_folded("replaced by constants when built:", &b.folded);
    print_pruned("left out when built (the nodes were built first, or never):", &b.pruned, false);
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
