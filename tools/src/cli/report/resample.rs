//! `evflow report resample`: error against run time of the re-sampling
//! methods the texture chain can use for 𝓡𝓢 (§6.2) — rubato's sinc
//! resampler at several lengths, its polynomial and FFT resamplers, the
//! windowed-sinc kernel `interp` runs live, and the `resample` node's
//! streaming resampler at each `quality` — on a band-limited multi-tone
//! signal whose re-sampled version is known exactly.

use anyhow::{Context, Result};
use evflow_nodes::texture::rs_precision::Scorer;
use evflow_study::precision::resample::{measure_method, methods, signal, RATIOS};
use evflow_tools::plot::{Plot, Series};
use std::path::PathBuf;

/// Arguments of `evflow report resample`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the PNG figure.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Samples of test signal per run (1 kHz: 10 000 = 10 s of texture).
    #[arg(long, default_value_t = 10_000)]
    samples: usize,
    /// Timed runs per method and ratio (the best is kept).
    #[arg(long, default_value_t = 5)]
    repeats: usize,
}

/// Runs `evflow report resample`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.samples >= 1000, "--samples {}: needs at least 1000", a.samples);
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let signal = signal();
    println!(
        "𝓡𝓢 of {} samples of a 12-tone signal (5 Hz … 0.2·f_s) by v_j/v_u = {}; error: RMS after the best \
         constant delay, relative; time: best of {} runs, per output sample.\n",
        a.samples,
        RATIOS.iter().map(|(p, q)| format!("{p}/{q}")).collect::<Vec<_>>().join(", "),
        a.repeats
    );
    println!("| method | relative RMS error (worst ratio) | time per output sample | delay kept (samples) |");
    println!("|---|---:|---:|---:|");
    let mut families: Vec<(&str, Vec<(f64, f64)>)> = Vec::new();
    let mut scorer = Scorer::default();
    for (family, m) in methods() {
        let r = measure_method(&mut scorer, &signal, family, m, a.samples, a.repeats)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        println!("| {} | {:.2e} | {:.1} ns | {:+.2} |", m.label(), r.worst, r.ns, r.delay);
        match families.iter_mut().find(|(f, _)| *f == family) {
            Some((_, pts)) => pts.push((r.ns, r.worst)),
            None => families.push((family, vec![(r.ns, r.worst)])),
        }
    }
    let plot = Plot {
        title: "Re-sampling (RS, §6.2): error against run time".into(),
        x_label: "time per output sample (ns)".into(),
        y_label: "relative RMS error".into(),
        log_x: true,
        log_y: true,
        series: families.into_iter().map(|(f, p)| Series::line_points(f, p)).collect(),
        ..Default::default()
    };
    println!();
    super::save_png(&plot, &a.out.join("resample-work-precision.png"));
    Ok(())
}
