//! `evflow report narx`: error against run time of the inverse NARX model
//! (issue 6, point 10). The study is library code
//! (`evflow_study::narx`, its table `evflow_study::tables::narx`); this
//! parses, calls, prints and writes narx.md and the figure, or, with
//! `--shard K/N`, the shard's record for `evflow merge`
//! (`evflow_study::narx::saved`).

use anyhow::{anyhow, bail, Context, Result};
use evflow_engine::batch::Failures;
use evflow_nodes::lab::texture::samples::NAMES;
use evflow_study::narx::run::{self as narx_study, NarxConfig};
use evflow_study::narx::saved::{NarxRecord, NARX_RECORD};
use evflow_study::narx::scope::NarxScope;
use evflow_study::narx::setting::{Setting, DEFAULT_SETTINGS};
use evflow_study::setup::Cond;
use evflow_study::shard_file::StudyRecord;
use evflow_study::tables::narx::{figure, markdown, Table};
use evflow_tools::batch::merge::narx::{NARX_FIGURE, NARX_TABLE};
use evflow_tools::batch::{progress_bar, BatchArgs};
use std::path::PathBuf;

/// Arguments of `evflow report narx`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the Markdown table (narx.md), the models (the condition's
    /// default inverse and forward models under `models/base`, each
    /// setting's under `models/SETTING/seed-N`) and the PNG. With --shard:
    /// the shard's models and its record narx-shard.json, for `evflow merge`.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// The condition the models are trained and scored at, MASS:SPEED (g, cm/s).
    #[arg(long, default_value = "60:5")]
    condition: String,
    /// Network settings as NAME=HIDDEN/FEEDBACK/INPUT/TRAINER, hidden layers
    /// joined by `-` (e.g. `small=5/1/10/lm`). Default: nine settings around
    /// the default network (15-10-5, taps 1/10, LM).
    #[arg(long, value_delimiter = ',')]
    settings: Vec<String>,
    /// Texture samples scored (default: the six of §5.3; `generated-<seed>` for a generated one).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Gains of the sweep (§5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    gains: Vec<f64>,
    /// Models per setting, trained from different initial weights (seeds
    /// 1 … N); E_s and time are their means, so one lucky start does not
    /// decide the comparison. A seed whose model fails to train or score is
    /// left out of its setting's means (column seeds).
    #[arg(long, default_value_t = 5)]
    seeds: u32,
    /// Epochs at most per model.
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Iterations at most of the optimized synthesis (computed once per
    /// texture, played beside the NARX chain).
    #[arg(long, default_value_t = 100)]
    iterations: usize,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    /// Leave the training times out: the models do not record them, the
    /// time column shows –, the Pareto front (which needs them) and the
    /// figure (which plots them) are left out; narx.md is then the same on
    /// every run, and a merge of shards is byte for byte one run's.
    #[arg(long)]
    no_times: bool,
    // `--jobs N`: (setting, seed) items at once (and textures prepared at
    // once). `--shard K/N`: train and score only the K-th of N contiguous
    // slices of the (setting, seed) items (each shard also builds the
    // default models and prepares the textures); `evflow merge OUT DIR…`
    // joins the shards' folders. The subcommand's help says so.
    #[command(flatten)]
    batch: BatchArgs,
}

/// Runs `evflow report narx`.
pub fn main(a: Args) -> Result<()> {
    let condition = Cond::parse(&a.condition).map_err(|e| anyhow!("--condition: {e}"))?;
    let given: Vec<&str> =
        if a.settings.is_empty() { DEFAULT_SETTINGS.to_vec() } else { a.settings.iter().map(String::as_str).collect() };
    let settings =
        given.iter().map(|s| Setting::parse(s).map_err(|e| anyhow!("--settings: {e}"))).collect::<Result<Vec<_>>>()?;
    let samples: Vec<String> = if a.samples.is_empty() {
        NAMES.iter().filter(|s| **s != "rippled-paper").map(|s| s.to_string()).collect()
    } else {
        a.samples.clone()
    };
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let out = std::fs::canonicalize(&a.out).with_context(|| format!("{}: cannot open", a.out.display()))?;
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let shard = a.batch.shard();
    let scope = NarxScope {
        condition,
        settings,
        samples,
        gains: a.gains.clone(),
        seeds: a.seeds,
        epochs: a.epochs,
        iterations: a.iterations,
        times: !a.no_times,
    };
    scope.check().map_err(|e| anyhow!("--{e}"))?;
    let cfg =
        NarxConfig { scope, graphs, out: out.clone(), work: tmp.path().to_path_buf(), jobs: a.batch.jobs(), shard };
    let range = cfg.range();
    eprintln!(
        "building the default inverse model and the forward model at {}, recording {} textures …",
        condition.label(),
        cfg.scope.samples.len()
    );
    let bar = progress_bar(range.len(), "models", false);
    let study = narx_study::run(&cfg, &mut |item| {
        bar.inc(1);
        bar.set_message(narx_study::item_label(&cfg.scope.settings, item));
    })?;
    evflow_tools::batch::finish(&bar);
    if a.batch.shard.is_some() {
        NarxRecord::of(&study, &cfg).write(&out)?;
        println!(
            "shard {shard}: (setting, seed) items {}–{} of {}; wrote {}",
            range.start + 1,
            range.end,
            cfg.scope.total(),
            out.join(NARX_RECORD).display()
        );
        println!("join the {} shards' folders with: evflow merge OUT DIR1 … DIR{}", shard.n, shard.n);
    } else {
        let left_out: Vec<String> = study.left_out.iter().map(|(s, _)| s.clone()).collect();
        let md = markdown(&Table {
            condition,
            textures: &study.textures,
            left_out: &left_out,
            gains: &cfg.scope.gains,
            seeds: cfg.scope.seeds,
            times: !a.no_times,
            scored: &study.scored,
        });
        print!("{md}");
        super::save_markdown(&out.join(NARX_TABLE), &md)?;
        if !a.no_times {
            super::save_png(&figure(&condition, &study.scored), &out.join(NARX_FIGURE));
        }
    }
    if !study.failures.is_empty() {
        let f = Failures { list: study.failures };
        bail!("{}", f.summary(cfg.scope.samples.len() + range.len(), "steps").trim_end());
    }
    Ok(())
}
