//! `evflow report resample`: error against run time of the re-sampling
//! methods the texture chain can use for 𝓡𝓢 (§6.2) — rubato's sinc
//! resampler at several lengths, its polynomial and FFT resamplers, the
//! windowed-sinc kernel `interp` runs live, and the `resample` node's
//! streaming resampler at each `quality` — on a band-limited multi-tone
//! signal whose re-sampled version is known exactly.

use anyhow::{Context, Result};
use evflow_nodes::rate::resampler::Quality;
use evflow_nodes::texture::rs::RsMethod;
use evflow_nodes::texture::rs_precision::{measure, tones};
use evflow_tools::plot::{Plot, Series};
use rubato::PolynomialDegree;
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

/// Velocity ratios v_j/v_u of a 3–7 cm/s grid (p/q of 𝓡𝓢).
const RATIOS: [(f64, f64); 4] = [(3.0, 3.5), (5.0, 4.5), (7.0, 5.5), (3.0, 6.5)];

fn methods() -> Vec<(&'static str, RsMethod)> {
    let mut v = Vec::new();
    for n in [16, 32, 64, 128, 256] {
        v.push(("rubato sinc", RsMethod::RubatoSinc(n)));
    }
    for d in [PolynomialDegree::Linear, PolynomialDegree::Cubic, PolynomialDegree::Quintic, PolynomialDegree::Septic] {
        v.push(("rubato polynomial", RsMethod::RubatoPoly(d)));
    }
    v.push(("rubato FFT", RsMethod::RubatoFft));
    for w in [4, 8, 16, 32] {
        v.push(("interp kernel (live)", RsMethod::Kernel(w)));
    }
    for q in Quality::ALL {
        v.push(("resample node (streaming)", RsMethod::Node(q)));
    }
    v
}

/// Runs `evflow report resample`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.samples >= 1000, "--samples {}: needs at least 1000", a.samples);
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    // Content up to 0.2 × the rate stays below the new Nyquist frequency at every ratio (≥ 0.46).
    let signal = tones(12, 0.2, 11);
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
    for (family, m) in methods() {
        let (mut worst, mut ns, mut delay) = (0.0f64, 0.0f64, 0.0f64);
        for &(p, q) in &RATIOS {
            let r =
                measure(&signal, a.samples, p, q, m, a.repeats).map_err(|e| anyhow::anyhow!("{}: {e}", m.label()))?;
            worst = worst.max(r.error);
            ns += r.seconds * 1e9 / r.samples.max(1) as f64 / RATIOS.len() as f64;
            if r.delay.abs() > delay.abs() {
                delay = r.delay;
            }
        }
        println!("| {} | {:.2e} | {:.1} ns | {:+.2} |", m.label(), worst, ns, delay);
        match families.iter_mut().find(|(f, _)| *f == family) {
            Some((_, pts)) => pts.push((ns, worst)),
            None => families.push((family, vec![(ns, worst)])),
        }
    }
    let plot = Plot {
        title: "Re-sampling (RS, §6.2): error against run time".into(),
        x_label: "time per output sample (ns)".into(),
        y_label: "relative RMS error".into(),
        log_x: true,
        log_y: true,
        series: families.into_iter().map(|(f, p)| Series::line_points(f, p)).collect(),
    };
    println!();
    super::save_png(&plot, &a.out.join("resample-work-precision.png"));
    Ok(())
}
