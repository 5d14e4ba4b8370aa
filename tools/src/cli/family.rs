//! `evflow family`: writes the display family (docs/simulated-lab.md §6.2)
//! as lab profile files, one per display, and its table.

use anyhow::{Context, Result};
use evflow_nodes::lab::family;
use std::path::{Path, PathBuf};

/// Arguments of `evflow family`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The folder for the profiles (`tuning-01.toml` …, `held-out-01.toml` …) and `family.md`.
    /// The shipped family is `graphs/lab/family`, which this command writes as it is.
    #[arg(long)]
    out: PathBuf,
}

/// Writes `text` to `path` through a new temporary file beside it (never
/// following a link planted at the temporary name), then renames it.
fn write(path: &Path, text: &str) -> Result<()> {
    evflow_engine::atomic_file::write_atomically(path, text)
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Runs `evflow family`.
pub fn main(a: Args) -> Result<()> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create the folder", a.out.display()))?;
    let members = family::members().map_err(anyhow::Error::msg)?;
    for m in &members {
        write(&a.out.join(format!("{}.toml", m.name)), &family::profile_file(m))?;
    }
    let text = format!(
        "# The display family\n\nWritten by `evflow family --out {}` (seed {}): {} tuning and {} held-out displays \
         drawn from the ranges of docs/simulated-lab.md §6.2. Defaults are chosen on the tuning set; the figures \
         the docs quote are measured on the held-out set.\n\n{}",
        a.out.display(),
        family::SEED,
        family::TUNING,
        family::HELD_OUT,
        family::table(&members)
    );
    write(&a.out.join("family.md"), &text)?;
    println!("wrote {} display profiles and family.md to {}", members.len(), a.out.display());
    Ok(())
}
