//! `evflow report textures`: the table of dissertation Fig. 5.7/5.8 and
//! Table 5.1 on the simulated lab. For every trained condition an inverse
//! NARX model is built (`graphs/model-build.toml`); for every texture and
//! condition two repetitions are recorded (`graphs/record-textures.toml`),
//! and `graphs/synthesize.toml` is run over the gain sweep: NARX synthesis
//! played on the virtual display, the record-and-playback baseline and the
//! repeat baseline, each scored by E_s against the second repetition. The
//! gain is the one whose peak power density matches the real one (§5.3.2).

use super::lab_recording::recording_in;
use super::synthesis::{
    check_graphs, gated_spectrum, models, synth_dir, synthesize_condition, write_cell, Built, Cond, Scored,
};
use anyhow::{anyhow, ensure, Context, Result};
use evflow_nodes::lab::texture::samples::NAMES;
use evflow_nodes::narx::model::Model;
use evflow_tools::plot::{Plot, Series};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `evflow report textures`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the Markdown table (textures.md), the models and the PNG spectra.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Texture samples (default: the six of §5.3, TS1–TS6).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Trained conditions as MASS:SPEED in g and cm/s (default: the corners of Fig. 5.6).
    #[arg(long, value_delimiter = ',', default_value = "60:3,60:5,110:3,110:5")]
    conditions: Vec<String>,
    /// Gains of the sweep (§5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    gains: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per model (early stopping usually ends sooner).
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// Use the models in this folder (narx-MASSg-SPEEDcms.json) instead of training them.
    #[arg(long)]
    models: Option<PathBuf>,
    /// Also write each texture's grid of synthesized actuation signals U_ij
    /// (the trained cells, at their chosen gains) here, one folder per
    /// texture (narx-SAMPLE), for `interp` (graphs/texture-live.toml's
    /// `grid`); and the record-and-playback actuation at its chosen gains
    /// (playback-SAMPLE).
    #[arg(long)]
    grid: Option<PathBuf>,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
}

/// One (texture, condition) row.
struct Row {
    sample: String,
    cond: Cond,
    repeat: f64,
    floor: f64,
    narx: Scored,
    playback: Scored,
}

fn spectra_plot(sample: &str, c: &Cond, narx: &Scored, dir: &Path) -> Result<Plot> {
    let rec = recording_in(dir)?;
    let ch = |n: &str| rec.channel(n).ok_or_else(|| anyhow!("{}: no `{n}` channel", dir.display()));
    let gate = ch("steady")?;
    let (real, virt, play) = (
        gated_spectrum(ch("real_force")?, gate, rec.rate())?,
        gated_spectrum(ch("narx_force")?, gate, rec.rate())?,
        gated_spectrum(ch("playback_force")?, gate, rec.rate())?,
    );
    let pts = |s: &[f64]| -> Vec<(f64, f64)> {
        s.iter().enumerate().skip(2).take(199).map(|(k, y)| (k as f64, *y)).collect()
    };
    Ok(Plot {
        title: format!("{sample}, {}: real vs virtual force (cf. Fig. 5.8), NARX gain {}", c.label(), narx.gain),
        x_label: "frequency (Hz)".into(),
        y_label: "magnitude".into(),
        log_x: false,
        log_y: true,
        series: vec![
            Series::line("real (repetition 2)", pts(&real)),
            Series::line(format!("NARX synthesis (E_s {:.2})", narx.es), pts(&virt)),
            Series::line("record-and-playback", pts(&play)),
        ],
    })
}

/// Runs `evflow report textures`.
pub fn main(a: Args) -> Result<()> {
    let samples: Vec<String> = if a.samples.is_empty() {
        NAMES.iter().filter(|s| **s != "rippled-paper").map(|s| s.to_string()).collect()
    } else {
        a.samples.clone()
    };
    for s in &samples {
        ensure!(NAMES.contains(&s.as_str()), "--samples: unknown sample `{s}` (one of {})", NAMES.join(", "));
    }
    let conds = a.conditions.iter().map(|s| Cond::parse(s)).collect::<Result<Vec<_>>>()?;
    ensure!(!a.gains.is_empty() && a.gains.iter().all(|g| g.is_finite() && *g > 0.0), "--gains: positive numbers");
    check_graphs(&a.graphs, &["model-build.toml", "record-textures.toml", "synthesize.toml"])?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let model_dir = a.out.join("models");
    std::fs::create_dir_all(&model_dir).with_context(|| format!("{}: cannot create", model_dir.display()))?;
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let started = Instant::now();

    let built = models(a.models.as_deref(), &a.graphs, a.epochs, &conds, &model_dir)?;
    let textures = tmp.path().join("textures");
    std::fs::create_dir_all(&textures)?;
    let mut rows = Vec::new();
    let mut plots = Vec::new();
    let total = samples.len() * conds.len();
    for (si, s) in samples.iter().enumerate() {
        for (ci, (c, m)) in conds.iter().zip(&built).enumerate() {
            eprintln!(
                "[{}/{total}] {s} at {}: recording, synthesizing over {} gains …",
                si * conds.len() + ci + 1,
                c.label(),
                a.gains.len()
            );
            let syn = synthesize_condition(&a.graphs, s, c, &m.path, &a.gains, &textures, tmp.path())?;
            let dir = synth_dir(tmp.path(), s, c, syn.narx.gain);
            if let Some(g) = &a.grid {
                write_cell(&dir, "u", &g.join(format!("narx-{s}")), s, c, syn.narx.gain)?;
                let played = synth_dir(tmp.path(), s, c, syn.playback.gain);
                write_cell(&played, "playback_u", &g.join(format!("playback-{s}")), s, c, syn.playback.gain)?;
            }
            plots.push((format!("textures-{s}-{}g-{}cms.png", c.mass, c.speed), spectra_plot(s, c, &syn.narx, &dir)?));
            rows.push(Row {
                sample: s.clone(),
                cond: *c,
                repeat: syn.repeat,
                floor: syn.floor,
                narx: syn.narx,
                playback: syn.playback,
            });
        }
    }
    let md = table(&rows, &conds, &built, &samples, started.elapsed().as_secs_f64());
    print!("{md}");
    super::save_markdown(&a.out.join("textures.md"), &md)?;
    for (name, plot) in &plots {
        super::save_png(plot, &a.out.join(name));
    }
    Ok(())
}

fn table(rows: &[Row], conds: &[Cond], built: &[Built], samples: &[String], seconds: f64) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "## Inverse models (graphs/model-build.toml)\n");
    let _ = writeln!(
        md,
        "| condition | samples | epochs | training time (s) | closed-loop transition agreement | with noise as force |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|");
    for (c, b) in conds.iter().zip(built) {
        match Model::load(&b.path) {
            Ok(m) => {
                let t = &m.training;
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {:.2} | {:.3} | {:.3} |{}",
                    c.label(),
                    t.samples,
                    t.epochs,
                    t.seconds,
                    t.closed_loop.as_ref().map_or(f64::NAN, |c| c.transition_agreement),
                    t.closed_loop_noise_force.as_ref().map_or(f64::NAN, |c| c.transition_agreement),
                    if b.trained { "" } else { " (given)" }
                );
            }
            Err(e) => {
                let _ = writeln!(md, "| {} | {e} | | | | |", c.label());
            }
        }
    }
    let _ = writeln!(
        md,
        "\n## Virtual against real texture forces (Fig. 5.7/5.8, Table 5.1)\n\nE_s (Eq. 5.2, 2–200 Hz, constant-speed stretch) against the second repetition of the real recording. \
         Gains: the sweep value whose peak power density is nearest the real one (§5.3.2). \
         Display floor: repetition 1 plus the display's own force with no actuation — the best any actuation \
         can score on this display.\n"
    );
    let _ = writeln!(md, "| texture | condition | repeat baseline | display floor | NARX E_s | NARX gain | record-and-playback E_s | its gain | NARX / baseline | NARX / floor | NARX below playback |");
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.3} | {} | {:.3} | {} | {:.1}× | {:.1}× | {} |",
            r.sample,
            r.cond.label(),
            r.repeat,
            r.floor,
            r.narx.es,
            r.narx.gain,
            r.playback.es,
            r.playback.gain,
            r.narx.es / r.repeat,
            r.narx.es / r.floor,
            if r.narx.es < r.playback.es { "yes" } else { "**no**" }
        );
    }
    let mean = |it: &mut dyn Iterator<Item = &Row>, f: fn(&Row) -> f64| {
        let v: Vec<f64> = it.map(f).collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let _ = writeln!(
        md,
        "\n| mean over | repeat baseline | display floor | NARX | record-and-playback |\n|---|---:|---:|---:|---:|"
    );
    for s in samples {
        let sel = || rows.iter().filter(move |r| &r.sample == s);
        let _ = writeln!(
            md,
            "| {s} | {:.3} | {:.3} | {:.3} | {:.3} |",
            mean(&mut sel(), |r| r.repeat),
            mean(&mut sel(), |r| r.floor),
            mean(&mut sel(), |r| r.narx.es),
            mean(&mut sel(), |r| r.playback.es)
        );
    }
    for c in conds {
        let sel = || rows.iter().filter(move |r| r.cond.mass == c.mass && r.cond.speed == c.speed);
        let _ = writeln!(
            md,
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            c.label(),
            mean(&mut sel(), |r| r.repeat),
            mean(&mut sel(), |r| r.floor),
            mean(&mut sel(), |r| r.narx.es),
            mean(&mut sel(), |r| r.playback.es)
        );
    }
    let below = rows.iter().filter(|r| r.narx.es < r.playback.es).count();
    let within = rows.iter().filter(|r| r.narx.es <= 1.5 * r.repeat).count();
    let within_floor = rows.iter().filter(|r| r.narx.es <= 1.5 * r.floor).count();
    let floor_within = rows.iter().filter(|r| r.floor <= 1.5 * r.repeat).count();
    let textures_below = samples
        .iter()
        .filter(|s| {
            let sel = || rows.iter().filter(|r| &&r.sample == s);
            mean(&mut sel(), |r| r.narx.es) < mean(&mut sel(), |r| r.playback.es)
        })
        .count();
    let _ = writeln!(
        md,
        "\nNARX below record-and-playback: {below} of {} rows, {textures_below} of {} textures on average. \
         NARX within 1.5× of the repeat baseline: {within} of {} rows; within 1.5× of the display floor: \
         {within_floor} of {} rows. The display floor itself is within 1.5× of the repeat baseline on \
         {floor_within} of {} rows. Whole report: {seconds:.0} s.",
        rows.len(),
        samples.len(),
        rows.len(),
        rows.len(),
        rows.len()
    );
    md
}
