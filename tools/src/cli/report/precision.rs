//! `evflow report precision`: every computation with a tolerance or a
//! discretization in one report — a log-log work-precision PNG each (the
//! shipped default marked), table.md (the summary) and rows.csv (every
//! setting). The curves come from `evflow_study::precision`.

use anyhow::{Context, Result};
use evflow_study::precision::{self, table, Size};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evflow report precision`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for table.md, rows.csv and the PNG figures.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// `ci` (few settings, short signals: seconds) or `full`.
    #[arg(long, default_value = "full")]
    size: String,
    /// Run one computation only (lab, butterworth, decimate, resample, interp-kernel, foaw, mesh-gradient,
    /// volterra-memory, optimize, narx, live-texture, live-mesh).
    #[arg(long)]
    only: Option<String>,
    /// The folder of the shipped graphs (lab-work-precision.toml, synthesize-optimized.toml, model-build.toml,
    /// texture-live-quality.toml, mesh-live.toml … and the model library data/).
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
}

/// Runs `evflow report precision`.
pub fn main(a: Args) -> Result<()> {
    let size = Size::from_word(&a.size).with_context(|| format!("--size {}: expected ci or full", a.size))?;
    let names = match &a.only {
        Some(n) if precision::names().contains(&n.as_str()) => vec![n.as_str()],
        Some(n) => anyhow::bail!("--only: {}", precision::PrecisionError::Unknown(n.clone())),
        None => precision::names(),
    };
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let started = Instant::now();
    let mut curves = Vec::new();
    // One computation that fails does not lose the others: it is named at
    // the end and the exit code is 1.
    let mut failures = evflow_engine::batch::Failures::new();
    let total = names.len();
    for name in names {
        let t = Instant::now();
        match precision::run(name, &a.graphs, size) {
            Ok(cs) => {
                println!("{name}: {} curve(s) in {:.1} s", cs.len(), t.elapsed().as_secs_f64());
                curves.extend(cs);
            }
            Err(e) => {
                eprintln!("{name}: failed: {e}");
                failures.push(name.to_string(), e.to_string());
            }
        }
    }
    let rows: Vec<table::Row> = curves.iter().map(table::Row::of).collect();
    let md = table::markdown(&rows);
    println!("\n{md}");
    for (file, text) in [("table.md", md), ("rows.csv", table::csv(&curves))] {
        let path = a.out.join(file);
        std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))?;
        println!("wrote {}", path.display());
    }
    for c in &curves {
        super::save_png(&table::figure(c), &a.out.join(format!("precision-{}.png", c.name)));
    }
    println!("report precision ({}) in {:.1} s", a.size, started.elapsed().as_secs_f64());
    if !failures.is_empty() {
        anyhow::bail!("{}", failures.summary(total, "computations").trim_end());
    }
    Ok(())
}
