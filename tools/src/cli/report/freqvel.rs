//! `evflow report freqvel`: the frequency–velocity relation of dissertation
//! §6.3 (Fig. 6.6) for every texture sample — each is recorded on the
//! simulated tribometer (`graphs/record-textures.toml`) at several speeds,
//! the constant-speed segments are kept (§5.1.1), and the frequency of the
//! main spectral component is fitted against the speed (slope, intercept,
//! R²). A table and a PNG.

use anyhow::{anyhow, Context, Result};
use evflow_engine::{run_offline, Plan, PlanOptions, RunOptions};
use evflow_nodes::lab::texture::samples::NAMES;
use evflow_nodes::recording::format::Recording;
use evflow_nodes::texture::freqvel::relation;
use evflow_tools::plot::{write_png, Plot, Series};
use std::path::{Path, PathBuf};

/// Arguments of `evflow report freqvel`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the PNG figure.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Texture samples (default: all seven).
    #[arg(long, value_delimiter = ',')]
    samples: Vec<String>,
    /// Scanning speeds, cm/s (Fig. 6.6: 3, 4, 5, 6, 7).
    #[arg(long, value_delimiter = ',', default_value = "3,4,5,6,7")]
    speeds: Vec<f64>,
    /// Stylus mass, g.
    #[arg(long, default_value_t = 85.0)]
    mass: f64,
    /// Tribometer passes per recording.
    #[arg(long, default_value_t = 4)]
    passes: u32,
    /// Band searched for the main component, Hz.
    #[arg(long, value_delimiter = ',', default_value = "2,200")]
    band: Vec<f64>,
    /// The recording graph.
    #[arg(long, default_value = "graphs/record-textures.toml")]
    graph: PathBuf,
}

/// Records one sample at one speed and returns its constant-speed force.
fn record(a: &Args, sample: &str, speed: f64, dir: &Path) -> Result<(f64, Vec<f64>)> {
    let sets = [
        format!("sample=\"{sample}\""),
        format!("speed={speed}"),
        format!("mass={}", a.mass),
        format!("passes={}", a.passes),
        "rep=1".to_string(),
    ];
    let overrides = sets
        .iter()
        .map(|s| evflow_engine::Override::parse(s).map_err(|e| anyhow!("{e}")))
        .collect::<Result<Vec<_>>>()?;
    let registry = evflow_nodes::registry();
    let mut checked = evflow_engine::load_file(&a.graph, &registry, &overrides).map_err(|e| anyhow!("{e}"))?;
    checked.graph.sweep.clear();
    let out = dir.join(format!("{sample}-{speed}"));
    std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
    let opts = PlanOptions { max_block: 1024, seed: None, base_dir: None, out_dir: Some(out.clone()), timing: false };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| anyhow!("{e}"))?;
    run_offline(&mut plan, RunOptions { duration: None, progress: None }).map_err(|e| anyhow!("{e}"))?;
    let wav = std::fs::read_dir(&out)
        .with_context(|| format!("{}: no recording", out.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "wav"))
        .ok_or_else(|| anyhow!("{}: the graph wrote no recording", out.display()))?;
    let rec = Recording::open(&wav).map_err(|e| anyhow!("{e}"))?;
    let (force, velocity) = (
        rec.channel("force").ok_or_else(|| anyhow!("{}: no `force` channel", wav.display()))?,
        rec.channel("velocity").ok_or_else(|| anyhow!("{}: no `velocity` channel", wav.display()))?,
    );
    // Constant-speed segments (§5.1.1): runs within 2 % of the set speed,
    // less their first 100 ms (the high-pass filter's response to the
    // reversal), each less its mean (the friction's sign flips between
    // passes) and faded in and out over 50 ms so that the joins add no
    // steps, concatenated.
    let settle = (0.1 * rec.rate()) as usize;
    let mut kept = Vec::new();
    let mut run: Vec<f64> = Vec::new();
    let flush = |run: &mut Vec<f64>, kept: &mut Vec<f64>| {
        if run.len() > 2 * settle {
            let seg = &run[settle..];
            let mean = seg.iter().sum::<f64>() / seg.len() as f64;
            let fade = settle / 2;
            let n = seg.len();
            kept.extend(seg.iter().enumerate().map(|(i, f)| {
                let edge = i.min(n - 1 - i);
                let w = if edge < fade {
                    0.5 - 0.5 * (std::f64::consts::PI * edge as f64 / fade as f64).cos()
                } else {
                    1.0
                };
                w * (f - mean)
            }));
        }
        run.clear();
    };
    for (f, v) in force.iter().zip(velocity) {
        if (v.abs() * 100.0 - speed).abs() <= 0.02 * speed {
            run.push(*f);
        } else {
            flush(&mut run, &mut kept);
        }
    }
    flush(&mut run, &mut kept);
    Ok((rec.rate(), kept))
}

/// Runs `evflow report freqvel`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.band.len() == 2 && a.band[0] < a.band[1], "--band needs two frequencies, low,high");
    anyhow::ensure!(a.speeds.len() >= 2, "--speeds needs at least two speeds");
    let samples: Vec<String> =
        if a.samples.is_empty() { NAMES.iter().map(|s| s.to_string()).collect() } else { a.samples.clone() };
    for s in &samples {
        anyhow::ensure!(NAMES.contains(&s.as_str()), "--samples: unknown sample `{s}` (one of {})", NAMES.join(", "));
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    println!(
        "Main spectral component against scanning speed, {} g, {} passes per recording, constant-speed segments, band {}–{} Hz.\n",
        a.mass, a.passes, a.band[0], a.band[1]
    );
    print!("| sample |");
    for v in &a.speeds {
        print!(" {v} cm/s |");
    }
    println!(" slope (Hz per cm/s) | intercept (Hz) | R² |");
    println!("|---|{}---:|---:|---:|", "---:|".repeat(a.speeds.len()));
    let mut series = Vec::new();
    for s in &samples {
        eprintln!("recording {s} …");
        let recs =
            a.speeds.iter().map(|&v| record(&a, s, v, tmp.path()).map(|r| (v, r))).collect::<Result<Vec<_>>>()?;
        let rate = recs[0].1 .0;
        let signals: Vec<(f64, &[f64])> = recs.iter().map(|(v, (_, x))| (*v, x.as_slice())).collect();
        match relation(&signals, rate, a.band[0], a.band[1]) {
            Ok(r) => {
                print!("| {s} |");
                for (_, f) in &r.points {
                    print!(" {f:.1} Hz |");
                }
                println!(" {:.3} | {:.2} | {:.4} |", r.fit.slope, r.fit.intercept, r.fit.r2);
                series.push(Series::points(s.clone(), r.points.clone()));
                let (lo, hi) = (a.speeds[0], a.speeds[a.speeds.len() - 1]);
                series.push(Series::line(
                    format!("{s} fit (R² {:.3})", r.fit.r2),
                    vec![(lo, r.fit.slope * lo + r.fit.intercept), (hi, r.fit.slope * hi + r.fit.intercept)],
                ));
            }
            Err(e) => println!("| {s} | {e} |"),
        }
    }
    let plot = Plot {
        title: format!("Main component frequency against scanning speed ({} g; cf. Fig. 6.6)", a.mass),
        x_label: "scanning speed (cm/s)".into(),
        y_label: "main component (Hz)".into(),
        log_x: false,
        log_y: true,
        series,
    };
    println!();
    match write_png(&plot, &a.out.join("freqvel.png")) {
        Ok(w) => println!("wrote {}{}", w.path.display(), if w.labelled { "" } else { " (no font found: unlabelled)" }),
        Err(e) => eprintln!("warning: {e}"),
    }
    Ok(())
}
