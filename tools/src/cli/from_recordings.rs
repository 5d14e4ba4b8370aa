//! `evflow library from-recordings`: a model library from a lab's own
//! recordings — parse, call
//! `evflow_study::from_recordings`, print. docs/rig.md describes it.

use anyhow::{Context, Result};
use evflow_study::from_recordings::{build, items, survey::survey, Inputs};
use evflow_tools::batch::{progress_bar, JobsArg};
use std::path::PathBuf;

/// Arguments of `evflow library from-recordings`.
// The fields' comments are `--help` text, where `[N]` is a unit, not a link.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(clap::Args, Debug)]
#[command(after_long_help = AFTER)]
pub struct Args {
    /// Folder of excitation recordings of the display, one per condition
    /// (NAME.json + NAME.wav, docs/recording-format.md): channels `u` [1]
    /// (the actuation as sent to the amplifier, in [−1, 1]; a multilevel
    /// sequence identifies the forward model best), `force` [N] (the
    /// lateral force as the sensor measured it, offset and all) and
    /// `velocity` [m/s] (signed, +x forward); condition `load_g` and
    /// `velocity_cm_s` in the sidecar.
    #[arg(long, value_name = "DIR")]
    excitation: PathBuf,
    /// Folder of texture recordings: channels `force` [N] (as measured,
    /// offset and all) and `velocity` [m/s]; condition `load_g`,
    /// `velocity_cm_s` and `material` (the texture's name, which names its
    /// forces-MATERIAL folder). Each at a condition the excitation covers;
    /// each texture's conditions a full load × speed grid. Several
    /// recordings of one texture and condition (repetitions): the first by
    /// name makes the cell.
    #[arg(long, value_name = "DIR")]
    textures: PathBuf,
    /// The library folder to create (absent or empty; never overwritten).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Levenberg–Marquardt epochs at most per inverse NARX model (early
    /// stopping usually ends sooner).
    #[arg(long, default_value_t = 200)]
    epochs: u32,
    /// The folder of the shipped graphs.
    #[arg(long, default_value = "graphs")]
    graphs: PathBuf,
    #[command(flatten)]
    jobs: JobsArg,
}

const AFTER: &str = "\
Rates: 1 kHz or 10 kHz (any whole multiple of 1 kHz), one rate per folder, all channels of a
recording on one clock; at 10 kHz `u` holds each 1 kHz value for ten samples. Everything is
taken to 1 kHz: a texture's force and velocity by `resample`; an excitation at 1 kHz as it is,
at k kHz its `u` sample for sample (every k-th) and its force and velocity by `resample`'s
stream, shifted back by its latency (u keeps its band up to 500 Hz, where the Nyquist-rate
carrier lives: a resampled u leaves the forward model's carrier gain unidentified). Samples
must be finite. Both stroke directions may be recorded: the force's offset (friction, the
sensor's bias per direction) is removed by the 10 Hz high-pass.

What is written into --out:
  forces-MATERIAL/u-MATERIAL-LOADg-SPEEDcms.{wav,json}
      per texture and condition: the force resampled to 1 kHz, high-passed at 10 Hz
      (graphs/forces-recordings.toml), over the recording's longest forward constant-speed
      stretch (velocity within 2 % of +velocity_cm_s, after 100 ms); channel `u`, unit N, gain 1.
      Backward passes are left out: the forward models describe forward passes, and the live
      chains play the cell both ways.
  models/forward-LOADg-SPEEDcms.json
      per excitation: the forward model (graphs/forward-build-recordings.toml on the 1 kHz
      recording, its resamplers passing it through), what synth.live renders through. A binary
      excitation or a carrier gain ≤ 0 is noted (synth.live plays nothing there).
  models/narx-LOADg-SPEEDcms.json
      per excitation: the inverse NARX model (graphs/model-build-recordings.toml), for the cells
      chains (graphs/synthesize-recordings.toml --set models=LIB/models).
  index.json
      the model library's index (as `library build` writes; E_s fields null: nothing was played).

Everything is checked before anything is built; the library is built in LIB/.partial and moved
into place when complete. Play it:
  evflow run graphs/texture-live-recorded.toml --set library=LIB --set sample=MATERIAL \\
      --set 'forward_models=[\"LIB/models/forward-…json\", …]' --out played
(the command prints the exact line).";

/// Runs `evflow library from-recordings`.
pub fn main(a: Args) -> Result<()> {
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    anyhow::ensure!(a.epochs >= 1, "--epochs: at least 1");
    eprintln!("checking {} and {} …", a.excitation.display(), a.textures.display());
    let s = survey(&a.excitation, &a.textures)?;
    let inputs = Inputs {
        excitation: a.excitation.clone(),
        textures: a.textures.clone(),
        out: a.out.clone(),
        graphs,
        epochs: a.epochs,
        jobs: a.jobs.jobs(),
    };
    let bar = progress_bar(items(&s), "items", false);
    let outcome = build(&inputs, &s, &|label| {
        bar.inc(1);
        bar.set_message(label.to_string());
    });
    evflow_tools::batch::finish(&bar);
    let o = outcome?;
    let conds: Vec<String> = o.conditions.iter().map(|c| c.label()).collect();
    println!(
        "library {}: models at {} condition(s) ({}), {} texture(s) ({}), {} forces cell(s); index {}",
        o.dir.display(),
        o.conditions.len(),
        conds.join("; "),
        o.samples.len(),
        o.samples.join(", "),
        o.cells,
        o.dir.join("index.json").display()
    );
    for n in &o.notes {
        println!("note: {n}");
    }
    // Absolute: a graph reads relative paths from its own folder.
    let abs = |p: &std::path::Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let models: Vec<String> = o.forward_models.iter().map(|p| format!("\"{}\"", abs(p).display())).collect();
    println!("play it on a recorded stroke:");
    println!(
        "  evflow run graphs/texture-live-recorded.toml --set library={} --set sample={} \\\n      --set 'forward_models=[{}]' --out played",
        abs(&o.dir).display(),
        o.samples.first().map_or("MATERIAL", String::as_str),
        models.join(", ")
    );
    Ok(())
}
