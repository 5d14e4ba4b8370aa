//! `evflow merge OUT SHARD_DIRS...`: joins the outputs of the shards of a
//! sweep (`evflow run --shard K/N`), of a model library (`evflow library
//! build --shard K/N`) or of a report (`evflow report textures|live|narx
//! --shard K/N`) into what one run would have written. The merge is
//! library code (`evflow_tools::batch::merge`); this parses, calls and prints.
//!
//! Missing shards refuse the merge, each named with the commands that
//! rerun it; with `--partial` the shards there are merge, the output is
//! marked partial (`PARTIAL.txt`) and the program exits with
//! [`PARTIAL_EXIT`] ([`Partial`]).

use anyhow::{bail, Result};
use evflow_tools::batch::merge::{merge, Coverage, Merged, PARTIAL_NOTE};
use std::path::PathBuf;

/// The exit status of a merge with `--partial` that left shards out
/// (1 stays for failures: a refused merge, or failed runs in the shards).
pub const PARTIAL_EXIT: u8 = 3;

/// The error a partial merge ends with; the program then exits with
/// [`PARTIAL_EXIT`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Partial(String);

/// Arguments of `evflow merge`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The folder to merge into (created; files already there are replaced).
    out: PathBuf,
    /// The shards' output folders (`--out` of each `evflow run --shard`), in any order.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Merge the shards there are when some are missing (a task killed,
    /// cancelled or not yet rerun): the output gets PARTIAL.txt, naming the
    /// missing shards and how to rerun them, and the program exits with
    /// status 3. Without it a missing shard refuses the merge.
    #[arg(long)]
    partial: bool,
}

/// Runs `evflow merge`.
pub fn main(a: Args) -> Result<()> {
    let coverage = if a.partial { Coverage::Partial } else { Coverage::All };
    let outcome = merge(&a.out, &a.shards, coverage)?;
    if let Some(gaps) = &outcome.partial {
        println!("partial: {}", gaps.summary());
    }
    let printed = print(outcome.merged);
    match outcome.partial {
        Some(gaps) if printed.is_ok() => Err(Partial(format!(
            "partial merge into {}: {} ({} says so)\n{}",
            a.out.display(),
            gaps.summary(),
            a.out.join(PARTIAL_NOTE).display(),
            gaps.details().trim_end()
        ))
        .into()),
        Some(gaps) => printed.map_err(|e| e.context(format!("partial merge: {}", gaps.summary()))),
        None => printed,
    }
}

/// Prints what the merge did; an error when runs or steps failed in the shards.
fn print(merged: Merged) -> Result<()> {
    match merged {
        #[cfg(feature = "synth")]
        Merged::Library(m) => {
            println!(
                "merged {} library shards: {} entries, {} files; index {}",
                m.shards,
                m.entries,
                m.files,
                m.index.display()
            );
        }
        #[cfg(feature = "synth")]
        Merged::Study(m) => {
            print!("{}", m.markdown);
            for line in &m.written {
                println!("{line}");
            }
            // A figure that cannot be drawn does not undo the merge: say why and go on.
            for w in &m.warnings {
                eprintln!("warning: {w}");
            }
            println!("{}", m.summary);
            if !m.failures.is_empty() {
                bail!("{}", m.failures.summary(m.steps, "steps").trim_end());
            }
        }
        Merged::Sweep(m) => {
            for table in &m.tables {
                println!("wrote {}", table.display());
            }
            for l in &m.plots.0 {
                println!("{l}");
            }
            // A figure that cannot be drawn does not undo the merge: say why and go on.
            for e in &m.plots.1 {
                eprintln!("warning: {e}");
            }
            println!(
                "merged {} shards of {}: {} of {} runs, {} files the graphs wrote",
                m.shards, m.graph, m.runs, m.total, m.files
            );
            if !m.failures.is_empty() {
                bail!("{}", m.failures.summary(m.total, "sweep runs").trim_end());
            }
        }
    }
    Ok(())
}
