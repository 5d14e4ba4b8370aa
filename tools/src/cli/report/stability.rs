//! `evflow report stability`: the stability suite (study/src/stability):
//! extreme and stiff cases over every node type and every shipped graph
//! family; prints the table, writes table.md and rows.csv, exits 1 when a
//! case fails.

use anyhow::{Context, Result};
use evflow_study::stability::{self, table, Size};
use evflow_tools::batch::JobsArg;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evflow report stability`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for table.md and rows.csv.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// `ci`: short runs, parameters at their limits (the CI suite); `full`:
    /// longer runs, one step inside every limit, the hour-long live run.
    #[arg(long, default_value = "full")]
    size: Size,
    /// Run only the cases whose name contains this text.
    #[arg(long, default_value = "")]
    only: String,
    /// The shipped graphs' folder.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    #[command(flatten)]
    /// `--jobs`: cases (and the shipped graphs of a family) run side by
    /// side; the rows are the same for any number.
    jobs: JobsArg,
}

/// Runs `evflow report stability`.
pub fn main(a: Args) -> Result<()> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    anyhow::ensure!(a.graphs.is_dir(), "{}: no such folder (the shipped graphs; --graphs DIR)", a.graphs.display());
    let work = tempfile::tempdir().context("a temporary folder for the fixtures")?;
    let env = stability::prepare(work.path(), &a.graphs, a.size)?;
    let started = Instant::now();
    let rows = stability::run(&env, &a.only, a.jobs.jobs(), &mut |r| {
        if !r.verdict.passed() {
            eprintln!("FAIL {}: {}", r.case, r.verdict.text());
        } else if r.seconds > 10.0 {
            eprintln!("slow {}: {:.0} s", r.case, r.seconds);
        }
    });
    anyhow::ensure!(!rows.is_empty(), "no case matches `{}`", a.only);
    let md = table::markdown(&rows);
    print!("{md}");
    for (name, text) in [("table.md", md.as_str()), ("rows.csv", table::csv(&rows).as_str())] {
        let path = a.out.join(name);
        std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))?;
        println!("wrote {}", path.display());
    }
    println!("{} (size {}, {:.1} s)", table::summary(&rows), a.size.name(), started.elapsed().as_secs_f64());
    let failed = stability::failures(&rows);
    anyhow::ensure!(failed == 0, "{failed} stability case(s) failed");
    Ok(())
}
