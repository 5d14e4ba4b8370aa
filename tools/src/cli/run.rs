//! `evflow run FILE`: the offline driver from the command line, for one run
//! or a sweep over graph variables.

use super::graph_args::GraphArgs;
use super::run_report::{print_report, report_json, sweep_csv, sweep_table};
use anyhow::{anyhow, bail, Result};
use evflow_engine::sweep::{parse_axis, points, Point};
use evflow_engine::{check, read_graph, run_offline, Checked, Plan, PlanOptions, RunOptions, RunReport};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Arguments of `evflow run`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    graph: GraphArgs,
    /// Sweep a graph variable over values (`name=v1,v2,…` or
    /// `name=[v1, v2]`); may be repeated: every combination runs. Adds to or
    /// replaces the graph's `[sweep]` table; `--set name=v` fixes a swept
    /// variable instead.
    #[arg(long = "sweep", value_name = "NAME=V1,V2,…")]
    sweep: Vec<String>,
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
    /// Also write the results (summaries and timings; one entry per run of a
    /// sweep) as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<std::path::PathBuf>,
    /// Also write a sweep's table (one row per run, one column per reported
    /// value) as CSV to this file.
    #[arg(long, value_name = "FILE")]
    csv: Option<std::path::PathBuf>,
}

/// Runs `evflow run`.
pub fn main(a: Args) -> Result<()> {
    let overrides = a.graph.overrides()?;
    let axes = a.sweep.iter().map(|s| parse_axis(s).map_err(|e| anyhow!("--sweep {e}"))).collect::<Result<Vec<_>>>()?;
    let graph = read_graph(&a.graph.file).map_err(|e| anyhow!("{e}"))?;
    let registry = evflow_nodes::registry();
    for ax in &axes {
        if !graph.vars.iter().any(|v| v.name == ax.name) {
            let help = evflow_engine::suggest::help(&ax.name, graph.vars.iter().map(|v| v.name.as_str()));
            bail!("--sweep {}: the graph has no variable `{}`; {help}", ax.name, ax.name);
        }
    }

    // Validate every run of the sweep before anything is built or written.
    let sweep =
        evflow_engine::sweep_files::expand(&graph, &overrides, &evflow_nodes::recording::sweep_fields::sweep_fields)
            .map_err(|e| anyhow!("{}: {e}", graph.file.display()))?;
    let runs = points(&sweep, &axes, &overrides);
    let mut checked: Vec<(Point, Checked)> = Vec::with_capacity(runs.len());
    for p in runs {
        let mut o = overrides.clone();
        o.extend(p.overrides());
        match check(&graph, &registry, &o) {
            Ok(c) => checked.push((p, c)),
            Err(e) if p.values.is_empty() => bail!("{e}"),
            Err(e) => bail!("sweep run {}: {e}", p.label()),
        }
    }
    if !a.quiet {
        for p in &checked[0].1.pruned {
            eprintln!("left out `{}`: {}", p.node, p.reason);
        }
    }
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second Ctrl-C (or a failure to install the handler) falls back to the default.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let sweep = checked.len() > 1;
    let mut reports: Vec<(Point, RunReport)> = Vec::new();
    let n = checked.len();
    for (k, (point, c)) in checked.into_iter().enumerate() {
        if stop.load(Ordering::Relaxed) {
            bail!("interrupted after {k} of {n} runs");
        }
        if sweep && !a.quiet {
            println!("── run {}/{n}: {} ──", k + 1, point.label());
        }
        let report =
            run_one(&c, &a, &stop).map_err(|e| if sweep { anyhow!("sweep run {}: {e}", point.label()) } else { e })?;
        print_report(&report, a.quiet);
        if sweep && !a.quiet {
            println!();
        }
        reports.push((point, report));
    }
    if sweep {
        print!("{}", sweep_table(&reports));
    }
    if let Some(path) = &a.json {
        std::fs::write(path, report_json(&reports, sweep))
            .map_err(|e| anyhow!("{}: cannot write results: {e}", path.display()))?;
    }
    let (lines, errors) = super::run_plots::draw_plots(&graph, &reports, &overrides, &a.out);
    for l in lines {
        println!("{l}");
    }
    // A figure that cannot be drawn does not undo the runs: say why and go on.
    for e in errors {
        eprintln!("warning: {e}");
    }
    if let Some(path) = &a.csv {
        std::fs::write(path, sweep_csv(&reports))
            .map_err(|e| anyhow!("{}: cannot write table: {e}", path.display()))?;
    }
    Ok(())
}

/// Builds and runs one checked graph; returns its report.
fn run_one(checked: &Checked, a: &Args, stop: &AtomicBool) -> Result<RunReport> {
    let opts = PlanOptions {
        max_block: a.block.max(1),
        seed: a.seed,
        base_dir: None,
        out_dir: Some(a.out.clone()),
        timing: true,
        mode: evflow_engine::RunMode::Offline,
    };
    let mut plan = Plan::build(checked, &opts).map_err(|e| anyhow!("{e}"))?;
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
    Ok(report)
}
