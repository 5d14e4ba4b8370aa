//! `evflow report freqvel`: the frequency–velocity relation of dissertation
//! §6.3 (Fig. 6.6) for every texture sample — each is recorded on the
//! simulated tribometer (`graphs/record-textures.toml`) at several speeds,
//! the constant-speed segments are kept (§5.1.1), and the frequency of the
//! main spectral component is fitted against the speed (slope, intercept,
//! R²). A table and a PNG.

use anyhow::{anyhow, Context, Result};
use evflow_engine::batch::{for_each_ordered, Failures};
use evflow_nodes::lab::texture::samples::{self, NAMES};
use evflow_nodes::texture::freqvel::relation;
use evflow_study::recordings::{record, Condition};
use evflow_tools::batch::{progress_bar, JobsArg};
use evflow_tools::plot::{Plot, Series};
use std::path::PathBuf;

/// Arguments of `evflow report freqvel`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the PNG figure.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Texture samples (default: all seven; `generated-<seed>` for a generated one).
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
    #[command(flatten)]
    jobs: JobsArg,
}

/// Runs `evflow report freqvel`.
pub fn main(a: Args) -> Result<()> {
    anyhow::ensure!(a.band.len() == 2 && a.band[0] < a.band[1], "--band needs two frequencies, low,high");
    anyhow::ensure!(a.speeds.len() >= 2, "--speeds needs at least two speeds");
    let samples: Vec<String> =
        if a.samples.is_empty() { NAMES.iter().map(|s| s.to_string()).collect() } else { a.samples.clone() };
    for s in &samples {
        samples::lookup(s).map_err(|e| anyhow::anyhow!("--samples: {e}"))?;
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
    let mut failures = Failures::new();
    // Each sample's recordings on --jobs threads; its row printed in sample order.
    let bar = progress_bar(samples.len(), "samples", false);
    let work = |_: usize, s: &String| {
        let recs = a
            .speeds
            .iter()
            .map(|&v| {
                let c = Condition { sample: s, mass: a.mass, speed: v, passes: a.passes, rep: 1 };
                record(&a.graph, &c, tmp.path()).map(|r| (v, r)).map_err(anyhow::Error::from)
            })
            .collect::<Result<Vec<_>>>();
        bar.inc(1);
        let recs = recs?;
        let rate = recs[0].1 .0;
        let signals: Vec<(f64, &[f64])> = recs.iter().map(|(v, (_, x))| (*v, x.as_slice())).collect();
        Ok::<_, anyhow::Error>(relation(&signals, rate, a.band[0], a.band[1]))
    };
    for_each_ordered(samples.iter().collect(), a.jobs.jobs(), &Default::default(), work, |k, outcome| {
        let s = &samples[k];
        match outcome.map_err(|p| anyhow!(p)).and_then(|r| r) {
            Ok(Ok(r)) => {
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
            Ok(Err(e)) => println!("| {s} | {e} |"),
            Err(e) => {
                println!("| {s} | failed |");
                failures.push(s.clone(), format!("{e:#}"));
            }
        }
    });
    evflow_tools::batch::finish(&bar);
    let plot = Plot {
        title: format!("Main component frequency against scanning speed ({} g; cf. Fig. 6.6)", a.mass),
        x_label: "scanning speed (cm/s)".into(),
        y_label: "main component (Hz)".into(),
        log_x: false,
        log_y: true,
        series,
        ..Default::default()
    };
    println!();
    super::save_png(&plot, &a.out.join("freqvel.png"));
    anyhow::ensure!(failures.is_empty(), "{}", failures.summary(samples.len(), "samples").trim_end());
    Ok(())
}
