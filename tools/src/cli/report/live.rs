//! `evflow report live`: every live texture chain under virtual users on
//! every lab profile, held to the stroke's achievable floor (docs/texture.md
//! §9). The study is library code (`evflow_study::live`);
//! this command parses, calls, prints and draws.

use anyhow::{Context, Result};
use evflow_nodes::lab::texture::samples;
use evflow_study::live::row::Chain;
use evflow_study::live::run::{run, LiveConfig, Progress};
use evflow_study::live::saved::{LiveRecord, RECORD};
use evflow_study::live::scope::{LiveScope, LiveSettings, User};
use evflow_study::shard_file::StudyRecord;
use evflow_study::tables::live::{csv, figures, markdown};
use evflow_tools::batch::{progress_bar, BatchArgs};
use std::path::PathBuf;

/// Arguments of `evflow report live`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for live.md, rows.csv, the PNG figures and the work files
    /// (each profile's model library, every run).
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Lab profiles: `nominal`, names of graphs/lab/*.toml, or profile files.
    #[arg(long, value_delimiter = ',', default_value = "nominal,stiff,display-b,relaxing,resonant")]
    profiles: Vec<String>,
    /// Run on the display family instead of --profiles (docs/simulated-lab.md §6.2):
    /// `tuning` (where the defaults are chosen), `held-out` (where figures are
    /// quoted) or `all`. With it, the chains default to the live synthesis alone
    /// and the users to `person` (the family's targets are the person's).
    #[arg(long, conflicts_with = "profiles")]
    displays: Option<super::Displays>,
    /// The chains played beside nothing: any of playback, narx, optimized, ff,
    /// live (default: all of them, or live alone with --displays). With live
    /// alone, each profile's library is the live synthesis' own (forward models
    /// and forces), built in a fraction of the time.
    #[arg(long, value_delimiter = ',')]
    chains: Vec<String>,
    /// Texture samples (default: the six of §5.3).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Virtual users by name (default: all of person, slow-heavy,
    /// fast-light, short-strokes — docs/texture.md §9 gives their ranges;
    /// `person` alone with --displays).
    #[arg(long, value_delimiter = ',')]
    users: Vec<String>,
    /// Overall gains of the sweep, applied to every chain alike (each
    /// chain's actuation is then bounded to |u| ≤ 1 by `limit`).
    #[arg(long, value_delimiter = ',', default_value = "0.4,0.6,0.8,1.0,1.2")]
    gains: Vec<f64>,
    /// Seconds of strokes per user.
    #[arg(long, default_value_t = 8.0)]
    seconds: f64,
    /// Leave out the stroke's achievable floor (optimization through the display's twin).
    #[arg(long)]
    no_floor: bool,
    /// Iterations per start of the stroke's floor.
    #[arg(long, default_value_t = 100)]
    floor_iterations: usize,
    /// The live synthesis: samples the target is read ahead (the horizon is one more).
    #[arg(long, default_value_t = LiveSettings::default().lookahead)]
    lookahead: usize,
    /// The live synthesis: optimizer iterations per tick.
    #[arg(long, default_value_t = LiveSettings::default().iterations)]
    live_iterations: usize,
    /// The live synthesis: carrier offset, in units of the least that renders every trough.
    #[arg(long, default_value_t = LiveSettings::default().offset)]
    offset: f64,
    /// Trained masses of each profile's grid, g.
    #[arg(long, value_delimiter = ',', default_value = "60,110")]
    masses: Vec<f64>,
    /// Trained speeds of each profile's grid, cm/s.
    #[arg(long, value_delimiter = ',', default_value = "3,7")]
    speeds: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per inverse model.
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Iterations at most of the optimized synthesis (the optimized cells).
    #[arg(long, default_value_t = 100)]
    iterations: usize,
    /// Leave out the PNG figures.
    #[arg(long)]
    no_plots: bool,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    /// `--jobs`, and `--shard K/N`: run only the K-th of N slices of the
    /// (profile, sample, user) items and save them in live-shard.json for
    /// `evflow merge OUT SHARDS…`, which writes live.md and rows.csv as one
    /// run would (docs/scale.md).
    #[command(flatten)]
    batch: BatchArgs,
}

/// Runs `evflow report live`.
pub fn main(a: Args) -> Result<()> {
    let mut scope = LiveScope::defaults();
    scope.profiles = a.profiles.clone();
    if let Some(set) = a.displays {
        scope.profiles = set.profiles();
        scope.chains = vec![Chain::Live];
        scope.users.retain(|u| u.name == "person");
    }
    if !a.chains.is_empty() {
        scope.chains = a
            .chains
            .iter()
            .map(|n| {
                Chain::ALL
                    .into_iter()
                    .find(|c| c.prefix() == n || (n == "forces-first" && *c == Chain::ForcesFirst))
                    .ok_or_else(|| {
                        let names: Vec<&str> = Chain::ALL.iter().map(|c| c.prefix()).collect();
                        anyhow::anyhow!("--chains: no chain named `{n}` (the chains are {})", names.join(", "))
                    })
            })
            .collect::<Result<_>>()?;
    }
    if !a.samples.is_empty() {
        for s in &a.samples {
            samples::lookup(s).map_err(|e| anyhow::anyhow!("--samples: {e}"))?;
        }
        scope.samples = a.samples.clone();
    }
    if !a.users.is_empty() {
        let all = User::defaults();
        scope.users = a
            .users
            .iter()
            .map(|n| {
                all.iter().find(|u| u.name == *n).cloned().ok_or_else(|| {
                    let names: Vec<&str> = all.iter().map(|u| u.name.as_str()).collect();
                    anyhow::anyhow!("--users: no user named `{n}` (the users are {})", names.join(", "))
                })
            })
            .collect::<Result<_>>()?;
    }
    scope.gains = a.gains.clone();
    scope.seconds = a.seconds;
    scope.floor = !a.no_floor;
    scope.floor_iterations = a.floor_iterations;
    scope.live = LiveSettings { lookahead: a.lookahead, iterations: a.live_iterations, offset: a.offset };
    scope.masses = a.masses.clone();
    scope.speeds = a.speeds.clone();
    scope.epochs = a.epochs;
    scope.iterations = a.iterations;
    scope.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    let base = std::fs::canonicalize(&a.out)?;
    let cfg = LiveConfig { scope, graphs, work: base.join("work"), shard: a.batch.shard(), jobs: a.batch.jobs() };
    let items = cfg.items();
    let mut libraries: Vec<usize> = items.iter().map(|i| i.profile).collect();
    libraries.dedup();
    let bar = progress_bar(libraries.len() + items.len(), "steps", false);
    let study = run(&cfg, &mut |p| {
        bar.inc(1);
        match p {
            Progress::Library(profile) => bar.set_message(format!("{profile}: library")),
            Progress::Row(profile, sample, user) => bar.set_message(format!("{profile}: {sample} under {user}")),
        }
    })?;
    evflow_tools::batch::finish(&bar);
    if a.batch.shard.is_some() {
        LiveRecord::of(&study, &cfg, &base).write(&base)?;
        println!(
            "shard {}: {} of {} items, {} rows; saved {}. Join the shards with `evflow merge OUT SHARD_FOLDERS…`.",
            cfg.shard,
            items.len(),
            cfg.all_items().len(),
            study.rows.len(),
            a.out.join(RECORD).display()
        );
    } else {
        let md = markdown(&study, &cfg.scope);
        print!("{md}");
        super::save_markdown(&a.out.join("live.md"), &md)?;
        let rows_csv = a.out.join("rows.csv");
        std::fs::write(&rows_csv, csv(&study)).with_context(|| format!("{}: cannot write", rows_csv.display()))?;
        println!("wrote {}", rows_csv.display());
        if !a.no_plots {
            for (name, plot) in figures(&study, &cfg.scope) {
                super::save_png(&plot, &a.out.join(name));
            }
        }
    }
    if !study.failures.is_empty() {
        let f = evflow_engine::batch::Failures { list: study.failures };
        anyhow::bail!("{}", f.summary(libraries.len() + items.len(), "steps").trim_end());
    }
    Ok(())
}
