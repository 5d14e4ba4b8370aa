//! `evflow library build --out DIR`: the model library (issue 17, point 3)
//! — parse, call `evflow_study::library`, print. docs/scale.md describes it.
//! `evflow library from-recordings`: the same layout from a lab's own
//! recordings (`super::from_recordings`, docs/rig.md).

use anyhow::{ensure, Context, Result};
use evflow_nodes::lab::texture::{generated, samples};
use evflow_study::library::{build, Plan};
use evflow_study::setup::{Cond, Profile};
use evflow_tools::batch::{progress_bar, BatchArgs};
use std::path::PathBuf;

/// Arguments of `evflow library`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    which: Which,
}

#[derive(clap::Subcommand, Debug)]
enum Which {
    /// Build (or complete) a library: for every texture sample × every
    /// condition of the grid, the inverse NARX model of the condition and
    /// each method's actuation cell at its Table 5.1 gain, the recorded
    /// force itself (`forces-SAMPLE`) and the forward models, with
    /// index.json (texture, condition, model file, training scores, E_s).
    /// A rerun skips what is done and redoes what an interruption left
    /// half written. The live synthesis (graphs/texture-live.toml,
    /// texture-serial.toml, texture-live-recorded.toml) renders the forces:
    /// point its `textures` at `DIR/forces-SAMPLE` (or `--set library=DIR`);
    /// the actuation cells `narx-`, `optimized-`, `playback-SAMPLE` are for
    /// the chains that play cells (graphs/texture-live-quality.toml).
    ///
    /// Example: cargo run --release -p evflow -- library build --out library
    Build(BuildArgs),
    /// A library from a lab's own recordings, as the sensor measured them
    /// (docs/rig.md): forces-SAMPLE, forward and inverse models per
    /// condition, index.json — what the live chains play.
    ///
    /// Example: evflow library from-recordings --excitation /lab/excitation --textures /lab/textures --out /lab/library
    FromRecordings(super::from_recordings::Args),
}

/// Arguments of `evflow library build`.
#[derive(clap::Args, Debug)]
struct BuildArgs {
    /// The library folder (created; an existing library is completed).
    #[arg(long)]
    out: PathBuf,
    /// Texture samples: names of the simulated lab's samples or
    /// `generated-<seed>` (default: the lab's seven).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Add the generated samples generated-1 … generated-N after --samples
    /// (or after the lab's seven when --samples is not given).
    #[arg(long, default_value_t = 0)]
    generated: u64,
    /// Stylus masses of the grid, g.
    #[arg(long, value_delimiter = ',', default_value = "60,85,110")]
    masses: Vec<f64>,
    /// Scanning speeds of the grid, cm/s.
    #[arg(long, value_delimiter = ',', default_value = "3,5,7")]
    speeds: Vec<f64>,
    /// Lab profile: `nominal`, a name of graphs/lab/*.toml, or a profile file.
    #[arg(long, default_value = "nominal")]
    profile: String,
    /// Gains of each cell's sweep (§5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    gains: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per inverse model.
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Iterations at most of the optimized synthesis.
    #[arg(long, default_value_t = 100)]
    iterations: usize,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    #[command(flatten)]
    batch: BatchArgs,
}

/// Runs `evflow library`.
pub fn main(a: Args) -> Result<()> {
    let b = match a.which {
        Which::Build(b) => b,
        Which::FromRecordings(f) => return super::from_recordings::main(f),
    };
    let mut samples: Vec<String> =
        if b.samples.is_empty() { samples::NAMES.iter().map(|s| s.to_string()).collect() } else { b.samples.clone() };
    for s in &samples {
        if let Err(e) = samples::lookup(s) {
            anyhow::bail!("--samples: {e}");
        }
    }
    samples.extend((1..=b.generated).map(generated::name));
    let mut seen = std::collections::HashSet::new();
    if let Some(d) = samples.iter().find(|s| !seen.insert(s.as_str())) {
        anyhow::bail!("--samples/--generated: sample `{d}` given twice");
    }
    let mut conds = Vec::new();
    for m in &b.masses {
        for v in &b.speeds {
            conds.push(Cond::parse(&format!("{m}:{v}"))?);
        }
    }
    ensure!(!conds.is_empty(), "--masses and --speeds: at least one of each");
    ensure!(
        !b.gains.is_empty() && b.gains.iter().all(|g| g.is_finite() && *g > 0.0),
        "--gains: positive numbers, at least one"
    );
    let profile = Profile::resolve(&b.profile, &b.graphs)?;
    let graphs = std::fs::canonicalize(&b.graphs).with_context(|| format!("--graphs {}", b.graphs.display()))?;
    std::fs::create_dir_all(&b.out).with_context(|| format!("{}: cannot create", b.out.display()))?;
    let dir = std::fs::canonicalize(&b.out)?;
    let plan = Plan {
        dir,
        graphs,
        profile,
        samples,
        conds,
        gains: b.gains.clone(),
        epochs: b.epochs,
        iterations: b.iterations,
        jobs: b.batch.jobs(),
        shard: b.batch.shard(),
        record_time: true,
    };
    let total = plan.shard.range(plan.conds.len()).len() * (1 + plan.samples.len());
    let bar = progress_bar(total, "items", false);
    let outcome = build(&plan, &|label| {
        bar.inc(1);
        bar.set_message(label.to_string());
    })?;
    evflow_tools::batch::finish(&bar);
    println!(
        "library {}: {} items built, {} already there, {} failed, of {}; index {}",
        b.out.display(),
        outcome.built,
        outcome.skipped,
        outcome.failures.len(),
        outcome.total,
        b.out.join("index.json").display()
    );
    anyhow::ensure!(outcome.failures.is_empty(), "{}", outcome.failures.summary(outcome.total, "items").trim_end());
    Ok(())
}
