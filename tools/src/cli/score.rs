//! `evflow score`: a recorded stroke's score (docs/score.md). The study is
//! library code (`evflow_study::score`); this command parses, calls,
//! prints and draws.

use anyhow::{Context, Result};
use evflow_study::score::models::ForwardDisplay;
use evflow_study::score::{self, inputs, report, Display, ScoreConfig, Step};
use evflow_study::setup::Profile;
use std::path::{Path, PathBuf};

/// Arguments of `evflow score`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The recorded stroke: channels `ir_x` (the IR frame's touch position,
    /// m) and `load_cell` (the finger's load, N) at the frame's rate (40 Hz
    /// on the dissertation's rig), at least 2 s — what
    /// graphs/record-stroke.toml writes (`stroke`) and the live chain
    /// (graphs/texture-live-recorded.toml) renders for. The shipped one is
    /// graphs/data/strokes/person.
    stroke: PathBuf,
    /// The chain's actuation for that stroke: channels `u` (after the gain
    /// and `limit`, 1 = 50 V) and `target` (the force the chain aimed at,
    /// N) at the chain's rate (1 kHz) — what graphs/texture-live-recorded.toml
    /// writes (`actuation-SAMPLE`). It lasts as long as the stroke.
    #[arg(long, value_name = "FILE")]
    actuation: PathBuf,
    /// The real force along the same path: channels `velocity` (the
    /// finger's true signed velocity, m/s), `load` (its true load, N) and
    /// `force` (the real surface's friction force, N, as measured: it is
    /// high-passed at 10 Hz here), and if present `position` (m, then checked
    /// against the stroke's IR frame), at the actuation's rate and as many
    /// samples. On the simulated lab, graphs/record-stroke.toml's
    /// `STROKE-truth` (its `sample` sets the material); on a rig, the real
    /// material scanned along the same path. [default: STROKE-truth]
    #[arg(long, value_name = "FILE")]
    real: Option<PathBuf>,
    /// The display the actuation is played on: `nominal`, a profile of
    /// graphs/lab (`stiff`, `display-b`, `family/held-out-07`, …) or a
    /// profile file. The floors are optimized through its twin.
    #[arg(long, default_value = "nominal", value_name = "NAME|FILE")]
    profile: String,
    /// Play on the display made of forward models instead of a lab
    /// profile: forward-*.json files or a library folder (its
    /// models/forward-*.json, e.g. graphs/data, the nominal lab's), blended
    /// at the finger's true load (g) and speed (cm/s) like `synth.live`
    /// blends them. The floors are optimized through the same models.
    #[arg(long, value_delimiter = ',', value_name = "FILES|DIR", conflicts_with = "profile")]
    models: Vec<PathBuf>,
    /// The lab texture sample whose base friction μ₀·N·tanh(v/0.5 mm/s) the
    /// display floor takes off the real force, leaving the texture's own
    /// modulation [default: the real recording's `material` when it names a
    /// lab sample; otherwise a base friction fitted to the real force].
    #[arg(long, value_name = "SAMPLE")]
    sample: Option<String>,
    /// The gain sweep every actuation is played over (× gain, then |u| ≤ 1):
    /// the chain's, each floor's. `report live`'s by default; gain 1 (the
    /// actuation as recorded) is always added.
    #[arg(long, value_delimiter = ',', default_value = "0.4,0.6,0.8,1.0,1.2")]
    gains: Vec<f64>,
    /// Optimizer iterations per start of each floor (`report live`'s by default).
    #[arg(long, default_value_t = 100, value_name = "N")]
    floor_iterations: usize,
    /// Leave out the target's and the stroke's floors (seconds instead of a minute).
    #[arg(long)]
    no_floors: bool,
    /// Folder for score.md, score.json, spectra.png and the played files (work/).
    #[arg(long, default_value = "score", value_name = "DIR")]
    out: PathBuf,
    /// The folder of the shipped graphs (for the lab profiles).
    #[arg(long, default_value = "graphs", value_name = "DIR")]
    graphs: PathBuf,
    /// Leave out the PNG figure.
    #[arg(long)]
    no_plot: bool,
}

/// What the floors mean on the display made of forward models.
const MODELS_FLOORS: &str =
    "\nOn a display made of forward models the floors know the display exactly: it has no friction \
     and no noise of its own, so a floor can render the real force almost perfectly. Ratios to them are not \
     comparable with a lab profile's or a rig's: this display compares actuations with each other \
     (docs/score.md).\n";

/// `STROKE-truth` beside `stroke`.
fn truth_of(stroke: &Path) -> PathBuf {
    let name = stroke.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let stem = name.strip_suffix(".wav").or_else(|| name.strip_suffix(".json")).unwrap_or(&name);
    stroke.with_file_name(format!("{stem}-truth"))
}

/// Writes `text` to `path` through a temporary file beside it.
fn save(path: &Path, text: &str) -> Result<()> {
    evflow_engine::atomic_file::write_atomically(path, text)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Runs `evflow score`.
pub fn main(a: Args) -> Result<()> {
    let real = a.real.clone().unwrap_or_else(|| truth_of(&a.stroke));
    let inputs = inputs::read(&a.stroke, &a.actuation, &real, a.sample.as_deref())?;
    let display = if a.models.is_empty() {
        let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
        Display::Lab(Profile::resolve(&a.profile, &graphs).context("--profile")?)
    } else {
        Display::Models(ForwardDisplay::load(&a.models).context("--models")?)
    };
    if let Display::Models(d) = &display {
        for f in &d.left_out {
            eprintln!("{}: off the grid of the other models; left out", f.display());
        }
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let models = matches!(display, Display::Models(_));
    let mut gains = a.gains.clone();
    if !gains.contains(&1.0) {
        gains.push(1.0);
        gains.sort_by(f64::total_cmp);
    }
    let cfg = ScoreConfig {
        display,
        work: a.out.join("work"),
        gains,
        floors: !a.no_floors,
        floor_iterations: a.floor_iterations,
    };
    eprintln!(
        "scoring {} ({:.3} s, material {}) on {}",
        inputs.name(),
        inputs.seconds(),
        if inputs.material.is_empty() { "not recorded" } else { &inputs.material },
        cfg.display.name()
    );
    let iterations = a.floor_iterations;
    let s = score::score(&inputs, &cfg, &mut |step| match step {
        Step::Playing(what, n) => eprintln!("  playing {what} ({n} run{})", if n == 1 { "" } else { "s" }),
        Step::Optimizing(what, n) => {
            eprintln!("  optimizing {what} through the twin: {n} starts × {iterations} iterations")
        }
        Step::Optimized(what, secs) => eprintln!("  optimized {what} in {secs:.1} s"),
    })?;
    let mut md = report::markdown(&s);
    if models && cfg.floors {
        md.push_str(MODELS_FLOORS);
    }
    print!("\n{md}\n");
    save(&a.out.join("score.md"), &md)?;
    save(&a.out.join("score.json"), &serde_json::to_string_pretty(&s)?)?;
    if !a.no_plot {
        let png = a.out.join("spectra.png");
        match evflow_tools::plot::write_png(&report::figure(&s), &png) {
            Ok(w) => {
                println!("wrote {}{}", w.path.display(), if w.labelled { "" } else { " (no font found: unlabelled)" })
            }
            Err(e) => eprintln!("warning: {e}"),
        }
    }
    Ok(())
}
