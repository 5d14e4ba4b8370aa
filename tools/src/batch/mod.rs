//! What the batch commands (`run --sweep`, `report`, `replay` of many
//! sessions) share on the command line: `--jobs`, `--shard`, and the one
//! progress bar of a batch; and, in submodules, the computations of batches
//! that commands, tests and benchmarks share: a sweep's tables, a shard's
//! record, and the merge of shards. The pool itself is engine code
//! (`evflow_engine::batch`).

pub mod log_lines;
pub mod merge;
pub mod record_json;
pub mod shard_record;
pub mod sweep_plots;
pub mod sweep_runs;
pub mod tables;

use evflow_engine::batch::{default_jobs, Shard};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// `--jobs`, for batches that cannot be sharded.
#[derive(clap::Args, Debug, Clone)]
pub struct JobsArg {
    /// Independent runs at once (default: the cores available). Results,
    /// files and what is printed are the same for any number.
    #[arg(long, short = 'j', value_name = "N")]
    pub jobs: Option<usize>,
}

impl JobsArg {
    /// The number of jobs: `--jobs`, else the cores available; at least 1.
    pub fn jobs(&self) -> usize {
        self.jobs.unwrap_or_else(default_jobs).max(1)
    }
}

/// `--jobs` and `--shard`.
#[derive(clap::Args, Debug, Clone)]
pub struct BatchArgs {
    #[command(flatten)]
    /// `--jobs`.
    pub jobs: JobsArg,
    /// Run only the K-th of N contiguous slices of the batch (`3/8`), for
    /// a cluster's job array; `evflow merge` joins the slices' outputs.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
}

fn parse_shard(s: &str) -> Result<Shard, String> {
    Shard::parse(s).map_err(|e| e.to_string())
}

impl BatchArgs {
    /// The number of jobs: `--jobs`, else the cores available; at least 1.
    pub fn jobs(&self) -> usize {
        self.jobs.jobs()
    }

    /// The slice to run (all of it without `--shard`).
    pub fn shard(&self) -> Shard {
        self.shard.unwrap_or(Shard::ALL)
    }
}

/// One progress bar for a whole batch of `total` items, on stderr: a
/// redrawn bar on a terminal, plain lines at least once a minute in a log
/// ([`log_lines`]), nothing when `quiet`.
pub fn progress_bar(total: usize, what: &str, quiet: bool) -> ProgressBar {
    let terminal = std::io::stderr().is_terminal();
    let target = if quiet {
        ProgressDrawTarget::hidden()
    } else if terminal {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::term_like_with_hz(Box::new(log_lines::LogLines::new(std::io::stderr())), 4)
    };
    let bar = ProgressBar::with_draw_target(Some(total as u64), target);
    let template = if terminal {
        format!("{{bar:30}} {{pos}}/{{len}} {what}, {{elapsed}} (eta {{eta}}) {{msg}}")
    } else {
        log_lines::TEMPLATE.replace("{what}", what)
    };
    bar.set_style(ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()));
    if !quiet && !terminal {
        bar.enable_steady_tick(log_lines::REDRAW);
    }
    bar
}

/// Ends a batch's [`progress_bar`]: the bar is cleared from a terminal; a
/// log gets the line of the last item.
pub fn finish(bar: &ProgressBar) {
    if !bar.is_hidden() && !std::io::stderr().is_terminal() {
        bar.abandon();
    } else {
        bar.finish_and_clear();
    }
}
