//! `evflow report textures`: dissertation Fig. 5.7/5.8 and Table 5.1, and
//! beyond them — every synthesis method on every lab profile, scored the
//! same way (docs/synthesis.md). The study itself is library code
//! (`evflow_study`); this command parses, calls, prints and
//! draws.

use anyhow::{anyhow, Context, Result};
use evflow_nodes::lab::texture::samples::{self, NAMES};
use evflow_nodes::recording::format::Recording;
use evflow_study::cells::write_actuation;
use evflow_study::row::{Method, Row};
use evflow_study::run::{run_on, Progress, Study, StudyConfig};
use evflow_study::saved::{SavedStudy, RECORD};
use evflow_study::scope::Scope;
use evflow_study::setup::Cond;
use evflow_study::shard_file::StudyRecord;
use evflow_study::spectrum::gated;
use evflow_study::tables::textures::Timings;
use evflow_study::tables::textures::{csv, markdown};
use evflow_tools::batch::{progress_bar, BatchArgs};
use evflow_tools::plot::{Plot, Series};
use std::path::{Path, PathBuf};

/// Arguments of `evflow report textures`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the Markdown tables (textures.md), rows.csv, the PNG
    /// spectra and the work files (models, recordings, runs).
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Texture samples (default: the six of §5.3, TS1–TS6; `generated-<seed>` for a generated one).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Trained conditions as MASS:SPEED in g and cm/s (default: the corners of Fig. 5.6).
    #[arg(long, value_delimiter = ',', default_value = "60:3,60:5,110:3,110:5")]
    conditions: Vec<String>,
    /// Lab profiles: `nominal`, names of graphs/lab/*.toml, or profile files.
    #[arg(long, value_delimiter = ',', default_value = "nominal,display-b,stiff")]
    profiles: Vec<String>,
    /// Run on the display family instead of --profiles (docs/simulated-lab.md
    /// §6.2): `tuning` (where defaults are chosen), `held-out` (where figures
    /// are quoted) or `all`.
    #[arg(long, conflicts_with = "profiles")]
    displays: Option<super::Displays>,
    /// Gains of the sweep (§5.3.2), applied to every method alike.
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    gains: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per inverse model (early stopping usually ends sooner).
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Iterations at most of the optimized synthesis.
    #[arg(long, default_value_t = 100)]
    iterations: usize,
    /// The optimized synthesis' objective: `expected` (the spectra the
    /// display is expected to deliver, its noise included), `time` (the
    /// waveform) or `spectral` (E_s² without noise).
    #[arg(long, default_value = "expected")]
    objective: String,
    /// Leave out the achievable floor (optimization through the display itself).
    #[arg(long)]
    no_floor: bool,
    /// Leave out the inverse model on multilevel excitation.
    #[arg(long)]
    no_multilevel: bool,
    /// Leave out the PNG spectra.
    #[arg(long)]
    no_plots: bool,
    /// Also write each texture's grid of actuation signals U_ij (the trained
    /// cells at their Table 5.1 gains) here, one folder per method and
    /// texture — `optimized-SAMPLE`, `narx-SAMPLE`, `playback-SAMPLE` — for
    /// an `interp` that plays cells (graphs/texture-render-quality.toml's
    /// `grid`; the live synthesis renders forces, not cells). Nominal profile
    /// only. (`report interp --cells optimized` writes the same cells
    /// together with the cross-validation; the shipped grids come from it.)
    #[arg(long)]
    grid: Option<PathBuf>,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    /// Leave the times out of the tables (synthesis and training seconds,
    /// the report's wall time) and out of the model files, so that two
    /// runs, or shards merged and one run, can be compared byte for byte.
    #[arg(long)]
    no_times: bool,
    /// `--jobs`, and `--shard K/N`: run only the K-th of N slices of the
    /// (profile, condition) cells — their models and rows — and save them
    /// in textures-shard.json for `evflow merge OUT SHARDS…`, which writes
    /// textures.md and rows.csv as one run would (docs/scale.md).
    #[command(flatten)]
    batch: BatchArgs,
}

/// Runs `evflow report textures`.
pub fn main(a: Args) -> Result<()> {
    let samples: Vec<String> = if a.samples.is_empty() {
        NAMES.iter().filter(|s| **s != "rippled-paper").map(|s| s.to_string()).collect()
    } else {
        a.samples.clone()
    };
    for s in &samples {
        samples::lookup(s).map_err(|e| anyhow::anyhow!("--samples: {e}"))?;
    }
    let conds = a.conditions.iter().map(|s| Cond::parse(s)).collect::<Result<Vec<_>, _>>()?;
    let shard = a.batch.shard();
    if a.grid.is_some() && a.batch.shard.is_some() {
        anyhow::bail!(
            "--grid with --shard: a texture's grid needs every condition, which the shards split; \
             run `report interp --cells optimized` or the report unsharded for the grids"
        );
    }
    let timings = if a.no_times { Timings::Leave } else { Timings::Show };
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    let base = std::fs::canonicalize(&a.out)?;
    let work = base.join("work");
    let scope = Scope {
        profiles: a.displays.map_or_else(|| a.profiles.clone(), |d| d.profiles()),
        samples,
        conds,
        gains: a.gains.clone(),
        epochs: a.epochs,
        iterations: a.iterations,
        multilevel: !a.no_multilevel,
        floor: !a.no_floor,
        objective: a.objective.clone(),
        times: !a.no_times,
    };
    let cfg = StudyConfig::new(scope, graphs, work, shard)?;
    let cells = cfg.cells().len();
    let bar = progress_bar(cells + cells * cfg.scope.samples.len(), "steps", false);
    let study = run_on(&cfg, a.batch.jobs(), &mut |p| {
        bar.inc(1);
        match p {
            Progress::Models(profile, c) => bar.set_message(format!("{}: models at {}", profile.name, c.label())),
            Progress::Row(profile, s, c, _, _) => bar.set_message(format!("{}: {s} at {}", profile.name, c.label())),
        }
    })?;
    evflow_tools::batch::finish(&bar);
    if a.batch.shard.is_some() {
        SavedStudy::of(&study, &cfg, &base).write(&base)?;
        println!(
            "shard {shard}: {} of {} (profile, condition) cells, {} rows; saved {}. \
             Join the shards with `evflow merge OUT SHARD_FOLDERS…`.",
            cells,
            cfg.all_cells().len(),
            study.rows.len(),
            a.out.join(RECORD).display()
        );
    } else {
        let md = markdown(&study, &cfg, timings);
        print!("{md}");
        super::save_markdown(&a.out.join("textures.md"), &md)?;
        let rows_csv = a.out.join("rows.csv");
        std::fs::write(&rows_csv, csv(&study, timings))
            .with_context(|| format!("{}: cannot write", rows_csv.display()))?;
        println!("wrote {}", rows_csv.display());
    }
    if !a.no_plots {
        save_spectra(&study, &a.out);
    }
    if let Some(g) = &a.grid {
        write_grids(&study, g)?;
        println!("wrote the grids under {}", g.display());
    }
    if !study.failures.is_empty() {
        let f = evflow_engine::batch::Failures { list: study.failures };
        anyhow::bail!("{}", f.summary(cells + cells * cfg.scope.samples.len(), "steps").trim_end());
    }
    Ok(())
}

/// Each row's spectra as a PNG in `out` (a figure that cannot be drawn
/// is a warning).
fn save_spectra(study: &Study, out: &Path) {
    for r in &study.rows {
        let name = format!("textures-{}-{}-{}.png", r.profile, r.sample, r.cond.tag());
        match spectra_plot(r) {
            Ok(p) => super::save_png(&p, &out.join(name)),
            Err(e) => eprintln!("warning: {name}: {e}"),
        }
    }
}

/// Each nominal row's grid of actuation signals U_ij (the trained cells
/// at their Table 5.1 gains) under `g`, one folder per method and texture.
fn write_grids(study: &Study, g: &Path) -> Result<()> {
    for r in study.rows.iter().filter(|r| r.profile == "nominal") {
        for (m, channel, folder) in [
            (Method::Optimized, "optimized_u", "optimized"),
            (Method::NarxBinary, "u", "narx"),
            (Method::Playback, "playback_u", "playback"),
        ] {
            let Some(res) = r.method(m) else { continue };
            let gain = res.chosen.table51.gain;
            write_actuation(
                &r.recording(gain),
                channel,
                &g.join(format!("{folder}-{}", r.sample)),
                &r.sample,
                &r.cond,
                gain,
                m.carrier(),
            )?;
        }
    }
    Ok(())
}

/// Spectra of the real force and of each method's virtual force at its Table 5.1 gain.
fn spectra_plot(r: &Row) -> Result<Plot> {
    let pts = |s: &[f64]| -> Vec<(f64, f64)> {
        s.iter().enumerate().skip(2).take(199).map(|(k, y)| (k as f64, *y)).collect()
    };
    let read = |gain: f64| -> Result<Recording> { Recording::open(&r.recording(gain)).map_err(|e| anyhow!("{e}")) };
    let base = read(r.methods.first().map_or(1.0, |m| m.chosen.table51.gain))?;
    let ch = |rec: &Recording, n: &str| -> Result<Vec<f64>> {
        rec.channel(n).map(|c| c.to_vec()).ok_or_else(|| anyhow!("no `{n}` channel"))
    };
    let gate = ch(&base, "steady")?;
    let mut series =
        vec![Series::line("real (repetition 2)", pts(&gated(&ch(&base, "real_force")?, &gate, base.rate())?))];
    for m in &r.methods {
        let rec = read(m.chosen.table51.gain)?;
        let channel = format!("{}_force", m.method.chain());
        if let Ok(f) = ch(&rec, &channel) {
            let label =
                format!("{} (gain {}, E_s {:.2})", m.method.label(), m.chosen.table51.gain, m.chosen.table51.welch);
            series.push(Series::line(label, pts(&gated(&f, &gate, rec.rate())?)));
        }
    }
    Ok(Plot {
        title: format!("{}, {}, {}: real vs virtual force (cf. Fig. 5.8)", r.profile, r.sample, r.cond.label()),
        x_label: "frequency (Hz)".into(),
        y_label: "magnitude".into(),
        log_x: false,
        log_y: true,
        series,
        ..Default::default()
    })
}
