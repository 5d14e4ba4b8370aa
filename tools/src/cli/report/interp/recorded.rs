//! `evflow report interp` with the recorded forces as cells (the
//! default), and the command's entry: other cells go to [`super::cells`].

use super::{Args, Cells};
use anyhow::{anyhow, Context, Result};
use evflow_engine::batch::{for_each_ordered, Failures};
use evflow_nodes::lab::texture::samples::{self, NAMES};
use evflow_nodes::metric::spectral_error::{spectral_rms_error, Band};
use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::texture::grid::Grid;
use evflow_nodes::texture::kernel::SincKernel;
use evflow_nodes::texture::scheme::{Geometry, Mix, Scheme};
use evflow_study::grid_plan::GridPlan;
use evflow_study::recordings::{record, Condition};
use evflow_tools::batch::progress_bar;
use evflow_tools::plot::{Plot, Series};
use std::path::Path;

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
                ..Default::default()
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
        return super::cells::main(&a, &samples);
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
    evflow_tools::batch::finish(&bar);
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
        super::super::save_png(plot, &a.out.join(format!("interp-spectra-{}.png", i + 1)));
    }
    anyhow::ensure!(failures.is_empty(), "{}", failures.summary(samples.len(), "samples").trim_end());
    Ok(())
}
