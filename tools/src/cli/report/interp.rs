//! `evflow report interp`: cross-validation of the interpolation schemes
//! (dissertation Fig. 5.6, 5.9, 6.8) on the simulated lab. Each sample is
//! recorded over a grid; the corners (or the rows) are the trained cells;
//! every untrained condition is interpolated from them by the basic scheme
//! (§5.3.3) and the improved one (Eq. 6.4) and compared with the real
//! recording at that condition by E_s (Eq. 5.2), beside the repeat baseline
//! (a second recording of the same condition). With `--cells recorded` (the
//! default) the cells are the recorded forces themselves (record-and-
//! playback, §6.5.2), compared directly: this isolates the interpolation
//! from the models and the display. `--cells narx|optimized|playback` runs
//! the whole chain instead, on the texture study: the cells are one
//! method's actuation, played on the virtual display, in the dissertation's
//! order and forces first ([`super::interp_cells`]).

use super::lab_recording::{record, Condition};
use anyhow::{anyhow, Context, Result};
use evflow_engine::batch::{for_each_ordered, Failures};
use evflow_nodes::lab::texture::samples::{self, NAMES};
use evflow_nodes::metric::spectral_error::{spectral_rms_error, Band};
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::synth::study::grid_plan::GridPlan;
use evflow_nodes::texture::grid::Grid;
use evflow_nodes::texture::kernel::SincKernel;
use evflow_nodes::texture::scheme::{Geometry, Mix, Scheme};
use evflow_tools::batch::{progress_bar, JobsArg};
use evflow_tools::plot::{Plot, Series};
use std::path::{Path, PathBuf};

/// What the grid cells are.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cells {
    /// The recorded forces at the trained conditions, interpolated and
    /// compared with the recording directly (no models, no display).
    Recorded,
    /// The actuation signals inverse NARX models synthesize at the trained
    /// conditions (each at its Table 5.1 gain), interpolated and played on
    /// the virtual display at the untrained condition
    /// (graphs/texture-cross-validation.toml); forces first with the
    /// nearest trained condition's inverse model.
    Narx,
    /// The optimized synthesis' actuation (through a forward model of each
    /// trained condition, `report textures`' best method), interpolated and
    /// played the same way; forces first optimizes offline through the
    /// nearest trained condition's forward model.
    Optimized,
    /// Record-and-playback's cells (the forces normalized per recording),
    /// interpolated and played the same way.
    Playback,
}

/// Arguments of `evflow report interp`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the table and the PNG figures (and, with synthesized
    /// cells, the models and the grids: `grids/METHOD-SAMPLE`,
    /// `grids/playback-SAMPLE`, `grids/forces-SAMPLE`).
    #[arg(long, default_value = ".")]
    pub(super) out: PathBuf,
    /// Texture samples (default: all seven; the rippled paper uses the grid of Fig. 6.8; `generated-<seed>` for a generated one).
    #[arg(long, value_delimiter = ',')]
    pub(super) samples: Vec<String>,
    /// What the grid cells are: the recorded forces, or one synthesis
    /// method's actuation played on the virtual display (narx, optimized,
    /// playback).
    #[arg(long, value_enum, default_value_t = Cells::Recorded)]
    pub(super) cells: Cells,
    /// Tribometer passes per recording (--cells recorded; the synthesized
    /// cells record one pass, as graphs/synthesize.toml plays).
    #[arg(long, default_value_t = 4)]
    pub(super) passes: u32,
    /// Band of E_s, Hz.
    #[arg(long, value_delimiter = ',', default_value = "2,200")]
    pub(super) band: Vec<f64>,
    /// The recording graph (--cells recorded).
    #[arg(long, default_value = "graphs/record-textures.toml")]
    pub(super) graph: PathBuf,
    /// Gains of the sweep that chooses each cell's gain (synthesized cells, §5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    pub(super) gains: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per inverse model (synthesized cells).
    #[arg(long, default_value_t = 200)]
    pub(super) epochs: u32,
    /// Iterations at most of the optimized synthesis (synthesized cells).
    #[arg(long, default_value_t = 100)]
    pub(super) iterations: usize,
    /// Use the models in this folder (narx-MASSg-SPEEDcms.json and
    /// forward-MASSg-SPEEDcms.json) instead of building them (synthesized cells).
    #[arg(long)]
    pub(super) models: Option<PathBuf>,
    /// The folder of the shipped graphs (synthesized cells).
    #[arg(long, default_value = "graphs")]
    pub(super) graphs: PathBuf,
    /// The lab profile the synthesized cells are recorded, trained and
    /// played on: `nominal`, a name of graphs/lab/*.toml, or a profile file.
    #[arg(long, default_value = "nominal")]
    pub(super) profile: String,
    /// Samples at once (--cells recorded; default: the cores available).
    #[command(flatten)]
    pub(super) jobs: JobsArg,
}

/// Magnitude spectrum (1 Hz bins, Hann, half overlap).
fn spectrum(x: &[f64], rate: f64) -> Result<Vec<f64>> {
    let cfg = SpectrumConfig { rate, nfft: rate.round() as usize, window: Window::Hann, overlap: 0.5 };
    averaged_spectrum(x, cfg)
        .map_err(|e| anyhow!("{e}"))?
        .map(|s| s.magnitude)
        .ok_or_else(|| anyhow!("a signal of {} samples is too short for a spectrum", x.len()))
}

/// One row of the result.
struct Row {
    sample: String,
    load: f64,
    speed: f64,
    repeat: f64,
    basic: f64,
    improved: f64,
}

/// One sample's rows and figures.
fn evaluate(a: &Args, sample: &str, tmp: &Path, band: &Band) -> Result<(Vec<Row>, Vec<Plot>)> {
    let mut plots = Vec::new();
    let p = GridPlan::of(sample);
    let rec = |mass: f64, speed: f64, rep: u32| {
        record(&a.graph, &Condition { sample, mass, speed, passes: a.passes, rep }, tmp)
    };
    let mut cells = Vec::new();
    let mut rate = 0.0;
    for &m in &p.loads {
        let mut row = Vec::new();
        for &v in &p.speeds {
            let (r, x) = rec(m, v, 1)?;
            rate = r;
            row.push(x);
        }
        cells.push(row);
    }
    let grid = Grid::from_signals(p.loads.clone(), p.speeds.clone(), rate, cells);
    let kernel = SincKernel::for_interp(16);
    let geo = Geometry::new(&grid, &kernel, 1_000_000, 0, 0.0).map_err(|e| anyhow!("{sample}: {e}"))?;
    let mut rows = Vec::new();
    for &(m, v) in &p.validate {
        let real = spectrum(&rec(m, v, 1)?.1, rate)?;
        let again = spectrum(&rec(m, v, 2)?.1, rate)?;
        let table = |scheme| Mix::new(&grid, &geo, &kernel, scheme, m, v).table(&grid, &kernel);
        let (tb, ti) = (table(Scheme::Basic), table(Scheme::Improved));
        let (sb, si) = (spectrum(&tb, rate)?, spectrum(&ti, rate)?);
        let es =
            |s: &[f64]| spectral_rms_error(s, &real, band).map_err(|e| anyhow!("{sample} at {m} g, {v} cm/s: {e}"));
        rows.push(Row {
            sample: sample.into(),
            load: m,
            speed: v,
            repeat: es(&again)?,
            basic: es(&sb)?,
            improved: es(&si)?,
        });
        if sample == "rippled-paper" && v == 4.5 || sample == "dotted-sheet" && m == 85.0 && v == 5.0 {
            let pts = |s: &[f64]| -> Vec<(f64, f64)> {
                s.iter()
                    .enumerate()
                    .skip(2)
                    .take(150)
                    .map(|(k, y)| (k as f64 * rate / (2.0 * (s.len() - 1) as f64), *y))
                    .collect()
            };
            plots.push(Plot {
                title: format!("{sample}, {m} g, {v} cm/s: real vs interpolated force spectra (cf. Fig. 5.9, 6.8)"),
                x_label: "frequency (Hz)".into(),
                y_label: "magnitude".into(),
                log_x: false,
                log_y: true,
                series: vec![
                    Series::line("real (recorded)", pts(&real)),
                    Series::line("basic (§5.3.3)", pts(&sb)),
                    Series::line("improved (Eq. 6.4)", pts(&si)),
                ],
            });
        }
    }
    Ok((rows, plots))
}

/// Runs `evflow report interp`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.band.len() == 2 && a.band[0] < a.band[1], "--band needs two frequencies, low,high");
    let samples: Vec<String> =
        if a.samples.is_empty() { NAMES.iter().map(|s| s.to_string()).collect() } else { a.samples.clone() };
    for s in &samples {
        samples::lookup(s).map_err(|e| anyhow::anyhow!("--samples: {e}"))?;
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    if a.cells != Cells::Recorded {
        return super::interp_cells::main(&a, &samples);
    }
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let band = Band::new(1000.0, 1000, a.band[0], a.band[1], false).map_err(|e| anyhow!("--band: {e}"))?;
    let mut plots = Vec::new();
    let mut rows = Vec::new();
    let mut failures = Failures::new();
    // The samples on --jobs threads, their rows and figures in sample order.
    let bar = progress_bar(samples.len(), "samples", false);
    let work = |_: usize, s: &String| {
        let r = evaluate(&a, s, tmp.path(), &band);
        bar.inc(1);
        r
    };
    for_each_ordered(samples.iter().collect(), a.jobs.jobs(), &Default::default(), work, |k, outcome| {
        match outcome.map_err(|p| anyhow!(p)).and_then(|r| r) {
            Ok((r, p)) => {
                rows.extend(r);
                plots.extend(p);
            }
            Err(e) => failures.push(samples[k].clone(), format!("{e:#}")),
        }
    });
    bar.finish_and_clear();
    println!(
        "E_s (Eq. 5.2, {}–{} Hz) against the recording at each untrained condition; cells: recorded forces.\n",
        a.band[0], a.band[1]
    );
    println!("| sample | load (g) | speed (cm/s) | repeat baseline | basic (§5.3.3) | improved (Eq. 6.4) | improved better |");
    println!("|---|---:|---:|---:|---:|---:|---|");
    let (mut wins, mut velocity_cases) = (0, 0);
    for r in &rows {
        let velocity_interpolated = GridPlan::of(&r.sample).velocity_interpolated(r.speed);
        if velocity_interpolated {
            velocity_cases += 1;
            wins += usize::from(r.improved < r.basic);
        }
        println!(
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {} |",
            r.sample,
            r.load,
            r.speed,
            r.repeat,
            r.basic,
            r.improved,
            if !velocity_interpolated {
                "— (no velocity step)"
            } else if r.improved < r.basic {
                "yes"
            } else {
                "**no**"
            }
        );
    }
    let mean = |f: fn(&Row) -> f64| rows.iter().map(f).sum::<f64>() / rows.len().max(1) as f64;
    println!(
        "\nmean E_s: repeat {:.3}, basic {:.3}, improved {:.3}; the improved scheme is better on {wins} of {velocity_cases} velocity-interpolated conditions.",
        mean(|r| r.repeat),
        mean(|r| r.basic),
        mean(|r| r.improved)
    );
    for (i, plot) in plots.iter().enumerate() {
        super::save_png(plot, &a.out.join(format!("interp-spectra-{}.png", i + 1)));
    }
    anyhow::ensure!(failures.is_empty(), "{}", failures.summary(samples.len(), "samples").trim_end());
    Ok(())
}
