//! `evflow run FILE`: the offline driver from the command line, for one run
//! or a sweep over graph variables — a sweep's runs on `--jobs` threads
//! (through `evflow_engine::batch`), printed and written in sweep order.

use super::graph_args::GraphArgs;
use super::run_report::print_report;
use anyhow::{anyhow, bail, Result};
use evflow_engine::batch::{check_outputs, for_each_ordered, output_files, Failures};
use evflow_engine::sweep::{validate, Point};
use evflow_engine::sweep_shared;
use evflow_engine::{run_offline, Checked, Plan, PlanOptions, RunOptions, RunReport};
use evflow_tools::batch::shard_record::{relative_to, ShardRecord};
use evflow_tools::batch::sweep_runs::sweep_runs;
use evflow_tools::batch::tables::{report_json, sweep_csv, sweep_table, Timings};
use evflow_tools::batch::{progress_bar, BatchArgs};
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
    /// Run a sweep's points as one plan: every node that is the same at
    /// every point (same type, parameters and ports, fed only by such
    /// nodes) runs once for all of them, the rest once per point — the
    /// same results as separate runs, without repeating what the swept
    /// values do not change (e.g. every synthesis before a swept `gain`).
    /// One thread (--jobs is not used); each run's times count the shared
    /// nodes' in full. Points whose graphs differ in structure run one by
    /// one, as without it.
    #[arg(long)]
    shared: bool,
    #[command(flatten)]
    batch: BatchArgs,
    /// Seed for every random stream (overrides the graph's `seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// Run length in seconds, for graphs with endless sources (finite
    /// sources still end the run early).
    #[arg(long, value_parser = super::graph_args::parse_duration)]
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
    /// Leave run times out of the printed table, --json and --csv, so that
    /// they are the same from run to run (and comparable byte for byte).
    #[arg(long)]
    no_times: bool,
    /// Also write the results (summaries and timings; one entry per run of a
    /// sweep) as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<std::path::PathBuf>,
    /// Also write a sweep's table (one row per run, one column per reported
    /// value) as CSV to this file.
    #[arg(long, value_name = "FILE")]
    csv: Option<std::path::PathBuf>,
}

/// A run of the slice: its sweep index, its values and its checked graph
/// (or why it does not validate).
type Item = (usize, Point, Result<Checked, String>);

/// What the runs gave, in sweep order.
#[derive(Default)]
struct Done {
    /// Each finished run's values and report.
    reports: Vec<(Point, RunReport)>,
    /// The sweep index of each report, for a shard's record.
    indices: Vec<usize>,
    /// The runs that failed, with why.
    failures: Failures,
    /// Runs whose outcome came back (fewer when interrupted).
    received: usize,
}

impl Done {
    /// Prints run `i` of the sweep (of `total`) and keeps its report, or
    /// its failure.
    fn take(
        &mut self,
        i: usize,
        point: Point,
        outcome: Result<RunReport, String>,
        a: &Args,
        total: usize,
        timings: Timings,
    ) {
        if !a.quiet {
            println!("── run {}/{total}: {} ──", i + 1, point.label());
        }
        match outcome {
            Ok(report) => {
                print_report(&report, a.quiet, timings);
                self.reports.push((point, report));
                self.indices.push(i);
            }
            Err(e) => {
                println!("run {} failed: {}", point.label(), e.lines().next().unwrap_or(""));
                self.failures.push(point.label(), e);
            }
        }
        if !a.quiet {
            println!();
        }
    }
}

/// Runs `evflow run`.
pub fn main(a: Args) -> Result<()> {
    let overrides = a.graph.overrides()?;
    let (graph, _, all) = sweep_runs(&a.graph.file, &overrides, &a.sweep).map_err(|e| anyhow!("{e}"))?;
    let total = all.len();
    let shard = a.batch.shard();
    let slice = shard.range(total);
    let is_sweep = total > 1;
    let items = validate_slice(&graph, &overrides, all, slice.clone(), is_sweep)?;
    // Runs (or nodes) that would write the same file would overwrite each
    // other, or race on `--jobs`: refused before anything runs.
    let outputs: Vec<_> =
        items.iter().filter_map(|(_, p, c)| c.as_ref().ok().map(|c| (p.label(), output_files(c, &a.out)))).collect();
    check_outputs(&outputs).map_err(|e| anyhow!("{}: {e}", graph.file.display()))?;
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow!("{}: cannot create output folder: {e}", a.out.display()))?;
    if a.batch.shard.is_some() {
        // A shard's record is its last file and says it finished: one left
        // from an earlier run goes first, so that a rerun killed half-way
        // leaves none and `evflow merge` does not take its files as done.
        remove_record(&a.out)?;
    }
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second Ctrl-C (or a failure to install the handler) falls back to the default.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let timings = if a.no_times { Timings::Leave } else { Timings::Show };
    let n = items.len();
    let done = if is_sweep && a.shared {
        run_shared(items, &a, &stop, total, timings)?
    } else if is_sweep {
        run_sweep(items, &a, &stop, total, timings)
    } else {
        run_single(items, &a, &stop, timings, &shard.to_string(), total)?
    };
    if done.received < n {
        bail!("interrupted after {} of {n} runs", done.received);
    }
    let Done { reports, indices, failures, .. } = done;
    write_results(&a, &graph, &overrides, &reports, is_sweep, timings)?;
    if a.batch.shard.is_some() {
        let record = ShardRecord {
            graph: graph.file.display().to_string(),
            shard,
            total,
            range: slice.clone(),
            indices,
            runs: reports,
            failures: failures.list.clone(),
            sweep: is_sweep,
            timings,
            csv: a.csv.as_deref().map(|p| relative_to(p, &a.out)),
            json: a.json.as_deref().map(|p| relative_to(p, &a.out)),
            sets: overrides.clone(),
            command: std::env::args_os().skip(1).map(|a| a.to_string_lossy().into_owned()).collect(),
        };
        record.write(&a.out)?;
    }
    if !failures.is_empty() {
        bail!("{}", failures.summary(n, "sweep runs").trim_end());
    }
    Ok(())
}

/// Validates every run of the sweep's `slice` before anything is built
/// or written. A run that does not validate is a failure of that run
/// only; when none validates, nothing is written.
fn validate_slice(
    graph: &evflow_engine::Graph,
    overrides: &[evflow_engine::Override],
    all: Vec<Point>,
    slice: std::ops::Range<usize>,
    is_sweep: bool,
) -> Result<Vec<Item>> {
    let registry = evflow_nodes::registry();
    let mut items: Vec<Item> = Vec::with_capacity(slice.len());
    for v in validate(graph, &registry, overrides, all, slice) {
        match v.checked {
            Ok(c) => items.push((v.index, v.point, Ok(c))),
            Err(e) if !is_sweep => bail!("{e}"),
            Err(e) => items.push((v.index, v.point, Err(e.to_string()))),
        }
    }
    // A shard past the last run (`--shard 3/3` of two runs) has none to
    // validate: it runs nothing and writes its empty record.
    if is_sweep && !items.is_empty() && !items.iter().any(|(_, _, c)| c.is_ok()) {
        let mut f = Failures::new();
        for (_, p, c) in &items {
            if let Err(e) = c {
                f.push(p.label(), e);
            }
        }
        bail!("nothing was run: {}", f.summary(items.len(), "sweep runs").trim_end());
    }
    Ok(items)
}

/// Runs a sweep's runs on `--jobs` threads, each printed in sweep order
/// as it comes back.
fn run_sweep(items: Vec<Item>, a: &Args, stop: &AtomicBool, total: usize, timings: Timings) -> Done {
    let mut done = Done::default();
    let labels: Vec<(usize, Point)> = items.iter().map(|(i, p, _)| (*i, p.clone())).collect();
    let bar = progress_bar(items.len(), "runs", a.quiet);
    let work = |_: usize, (_, _, c): Item| -> Result<RunReport, String> {
        let report = run_one(&c?, a, stop, false).map_err(|e| format!("{e:#}"));
        bar.inc(1);
        report
    };
    done.received = for_each_ordered(items, a.batch.jobs(), stop, work, |k, outcome| {
        let (i, point) = &labels[k];
        done.take(*i, point.clone(), outcome.and_then(|r| r), a, total, timings);
    });
    evflow_tools::batch::finish(&bar);
    done
}

/// Runs a sweep's runs as one plan (`--shared`), printed in sweep order;
/// a run that did not validate is a failure of its own. Points that
/// cannot share a plan run as [`run_sweep`] runs them.
fn run_shared(items: Vec<Item>, a: &Args, stop: &AtomicBool, total: usize, timings: Timings) -> Result<Done> {
    let (mut valid, mut checked, mut invalid) = (Vec::new(), Vec::new(), Vec::new());
    for (i, p, c) in items {
        match c {
            Ok(c) => {
                valid.push((i, p));
                checked.push(c);
            }
            Err(e) => invalid.push((i, p, e)),
        }
    }
    let merged = match sweep_shared::merge(&checked) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("--shared: {e}; running them one by one");
            let mut all: Vec<Item> = valid.into_iter().zip(checked).map(|((i, p), c)| (i, p, Ok(c))).collect();
            all.extend(invalid.into_iter().map(|(i, p, e)| (i, p, Err(e))));
            all.sort_by_key(|(i, _, _)| *i);
            return Ok(run_sweep(all, a, stop, total, timings));
        }
    };
    if !a.quiet {
        let copied: Vec<&str> = merged.copied().collect();
        eprintln!(
            "--shared: {} of {} nodes run once for the {} runs; once per run: {}",
            checked[0].nodes.len() - copied.len(),
            checked[0].nodes.len(),
            valid.len(),
            if copied.is_empty() { "none".to_string() } else { copied.join(", ") }
        );
    }
    // A node that fails fails every run it was shared by; an interruption stops them all.
    let report = run_one(&merged.checked, a, stop, true).map_err(|e| format!("{e:#}"));
    if stop.load(Ordering::Relaxed) {
        return Ok(Done::default());
    }
    let mut done = Done::default();
    let mut outcomes: Vec<(usize, Point, Result<RunReport, String>)> = valid
        .into_iter()
        .enumerate()
        .map(|(k, (i, p))| (i, p, report.as_ref().map(|r| merged.report(r, k)).map_err(Clone::clone)))
        .chain(invalid.into_iter().map(|(i, p, e)| (i, p, Err(e))))
        .collect();
    outcomes.sort_by_key(|(i, _, _)| *i);
    for (i, point, outcome) in outcomes {
        done.take(i, point, outcome, a, total, timings);
        done.received += 1;
    }
    Ok(done)
}

/// Runs the one run there is — or, in an empty shard (more shards than
/// runs, normal in a job array), none, which its record says.
fn run_single(
    mut items: Vec<Item>,
    a: &Args,
    stop: &AtomicBool,
    timings: Timings,
    shard: &str,
    total: usize,
) -> Result<Done> {
    let mut done = Done::default();
    if let Some((_, point, c)) = items.pop() {
        let report = run_one(&c.map_err(|e| anyhow!(e))?, a, stop, true)?;
        print_report(&report, a.quiet, timings);
        done.reports.push((point, report));
        done.indices.push(0);
        done.received = 1;
    } else {
        println!("shard {shard}: no run of the {total} falls in this slice; its record says so");
    }
    Ok(done)
}

/// A sweep's table, then the --json results, the graph's plots and the
/// --csv table.
fn write_results(
    a: &Args,
    graph: &evflow_engine::Graph,
    overrides: &[evflow_engine::Override],
    reports: &[(Point, RunReport)],
    is_sweep: bool,
    timings: Timings,
) -> Result<()> {
    if is_sweep {
        print!("{}", sweep_table(reports, timings));
    }
    if let Some(path) = &a.json {
        write(path, &report_json(reports, is_sweep, timings), "results")?;
    }
    // A shard holds part of the sweep: its plots are drawn by `evflow merge`
    // from every run, so that the merge equals one run, plots included.
    if a.batch.shard.is_none() {
        let (lines, errors) = evflow_tools::batch::sweep_plots::draw_plots(graph, reports, overrides, &a.out);
        for l in lines {
            println!("{l}");
        }
        // A figure that cannot be drawn does not undo the runs: say why and go on.
        for e in errors {
            eprintln!("warning: {e}");
        }
    } else if !graph.plots.is_empty() {
        println!("plots: drawn by `evflow merge` from the whole sweep");
    }
    if let Some(path) = &a.csv {
        write(path, &sweep_csv(reports, timings), "table")?;
    }
    Ok(())
}

/// Removes the shard record in `dir`, if there is one.
fn remove_record(dir: &std::path::Path) -> Result<()> {
    let path = dir.join(evflow_tools::batch::shard_record::RECORD);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(anyhow!(
            "{}: cannot remove the record of an earlier run of this shard ({e}); remove it, or give another --out",
            path.display()
        )),
        _ => Ok(()),
    }
}

/// Writes `text` to `path` through a temporary file beside it (an
/// interrupted write leaves no half file; `evflow_engine::atomic_file`).
fn write(path: &std::path::Path, text: &str, what: &str) -> Result<()> {
    evflow_engine::atomic_file::write_atomically(path, text)
        .map_err(|e| anyhow!("{}: cannot write {what}: {e}", path.display()))
}

/// Builds and runs one checked graph; returns its report. With `show_ticks`,
/// a progress bar over the run's ticks appears when it lasts over a second
/// (a sweep shows one bar over its runs instead).
fn run_one(checked: &Checked, a: &Args, stop: &AtomicBool, show_ticks: bool) -> Result<RunReport> {
    let opts = PlanOptions {
        max_block: a.block.max(1),
        seed: a.seed,
        base_dir: None,
        out_dir: Some(a.out.clone()),
        timing: true,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
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
        if show_ticks {
            if !shown && !a.quiet && started.elapsed() > Duration::from_secs(1) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
                shown = true;
            }
            bar.set_length(total);
            bar.set_position(done);
        }
        !stop.load(Ordering::Relaxed)
    };
    let result = run_offline(&mut plan, RunOptions { duration: a.duration, progress: Some(&mut progress) });
    bar.finish_and_clear();
    let report = result.map_err(|e| anyhow!("{e}"))?;
    Ok(report)
}
