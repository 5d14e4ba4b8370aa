//! What the batch commands (`run --sweep`, `report`, `replay` of many
//! sessions) share on the command line: `--jobs`, `--shard`, and the one
//! progress bar of a batch; and, in submodules, the computations of batches
//! that commands, tests and benchmarks share: a sweep's tables, a shard's
//! record, and the merge of shards. The pool itself is engine code
//! (`evflow_engine::batch`).

pub mod merge;
pub mod record_json;
pub mod shard_record;
pub mod sweep_plots;
pub mod sweep_runs;
pub mod tables;

use evflow_engine::batch::{default_jobs, Shard};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

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

/// One progress bar for a whole batch of `total` items, on stderr (hidden
/// when `quiet`, and by indicatif when stderr is not a terminal).
pub fn progress_bar(total: usize, what: &str, quiet: bool) -> ProgressBar {
    let target = if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() };
    let bar = ProgressBar::with_draw_target(Some(total as u64), target);
    let template = format!("{{bar:30}} {{pos}}/{{len}} {what}, {{elapsed}} (eta {{eta}}) {{msg}}");
    bar.set_style(ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()));
    bar
}
