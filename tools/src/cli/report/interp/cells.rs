//! `evflow report interp --cells narx|optimized|playback`: the
//! cross-validation of Fig. 5.6, 5.9 and 6.8 through the whole chain, in
//! both orders (the actuations interpolated; the forces interpolated, then
//! synthesized). The study module runs it
//! (`evflow_study::crossval`); this file parses, calls,
//! prints the table ([`super::cells_table`]) and draws the spectra.

use super::cells_table::table;
use super::{Args, Cells};
use anyhow::{anyhow, bail, Context, Result};
use evflow_nodes::recording::format::Recording;
use evflow_study::crossval::{self, CrossvalConfig, Run};
use evflow_study::row::Method;
use evflow_study::setup::Profile;
use evflow_study::spectrum::gated;
use evflow_study::xval::GRAPH;
use evflow_tools::plot::{Plot, Series};
use std::path::Path;
use std::time::Instant;

/// The optimized synthesis' objective (`synth.optimize`), as `report
/// textures` uses by default.
const OBJECTIVE: &str = "expected";

/// The method whose cells form the grid.
fn method_of(cells: Cells) -> Result<Method> {
    Ok(match cells {
        Cells::Narx => Method::NarxBinary,
        Cells::Optimized => Method::Optimized,
        Cells::Playback => Method::Playback,
        Cells::Recorded => bail!("--cells recorded has no synthesis"),
    })
}

/// Spectra of the real force and of the display's force under each scheme
/// (and forces first, improved), over the constant-speed stretch.
fn spectra_plot(run: &Run, method: Method) -> Result<Plot> {
    let open = |p: &Path| Recording::open(p).map_err(|e| anyhow!("{e}"));
    let ch = |rec: &Recording, n: &str, p: &Path| -> Result<Vec<f64>> {
        rec.channel(n).map(|c| c.to_vec()).ok_or_else(|| anyhow!("{}: no `{n}` channel", p.display()))
    };
    let pts = |x: &[f64], gate: &[f64], rate: f64| -> Result<Vec<(f64, f64)>> {
        let s = gated(x, gate, rate)?;
        Ok(s.iter().enumerate().skip(2).take(199).map(|(f, y)| (f as f64, *y)).collect())
    };
    let mut series = Vec::new();
    for (k, s) in run.schemes.iter().enumerate() {
        let rec = open(&s.recording)?;
        let gate = ch(&rec, "steady", &s.recording)?;
        if k == 0 {
            series.push(Series::line(
                "real (repetition 2)",
                pts(&ch(&rec, "real_force", &s.recording)?, &gate, rec.rate())?,
            ));
        }
        let name = ["basic (§5.3.3)", "improved (Eq. 6.4)"][k];
        let force = ch(&rec, "narx_force", &s.recording)?;
        series.push(Series::line(format!("{name}, E_s {:.2}", s.scores.cells), pts(&force, &gate, rec.rate())?));
        if let (1, Some((es, _, path, channel))) = (k, &s.ff) {
            let ff = open(path)?;
            let (f, g) = (ch(&ff, channel, path)?, ch(&ff, "steady", path)?);
            series.push(Series::line(format!("forces first, improved, E_s {es:.2}"), pts(&f, &g, ff.rate())?));
        }
    }
    Ok(Plot {
        title: format!("{}, {}: interpolated cells ({}) on the display", run.sample, run.cond.label(), method.label()),
        x_label: "frequency (Hz)".into(),
        y_label: "magnitude".into(),
        log_x: false,
        log_y: true,
        series,
        ..Default::default()
    })
}

/// Runs `evflow report interp --cells narx|optimized|playback` for `samples`.
pub(super) fn main(a: &Args, samples: &[String]) -> Result<()> {
    let method = method_of(a.cells)?;
    let graphs = std::fs::canonicalize(&a.graphs).with_context(|| format!("--graphs {}", a.graphs.display()))?;
    for g in [
        "model-build.toml",
        "forward-build.toml",
        "record-textures.toml",
        "synthesize.toml",
        "synthesize-optimized.toml",
        "play-actuation.toml",
        GRAPH,
    ] {
        anyhow::ensure!(
            graphs.join(g).is_file(),
            "--graphs: {} has no {g} (run from the repository root)",
            graphs.display()
        );
    }
    let profile = Profile::resolve(&a.profile, &graphs).map_err(|e| anyhow!("--profile: {e}"))?;
    let started = Instant::now();
    let out = std::fs::canonicalize(&a.out).with_context(|| format!("{}: cannot open", a.out.display()))?;
    let tmp = tempfile::tempdir().context("cannot create a temporary folder")?;
    let cfg = CrossvalConfig {
        graphs: &graphs,
        samples,
        method,
        gains: &a.gains,
        iterations: a.iterations,
        objective: OBJECTIVE,
        epochs: a.epochs,
        band: [a.band[0], a.band[1]],
        given_models: a.models.as_deref(),
        models_out: &out.join("models"),
        grids: &out.join("grids"),
        work: tmp.path(),
        profile: &profile,
    };
    let found = crossval::run(&cfg, &mut |step, steps, what| eprintln!("[{step}/{steps}] {what} …"))
        .map_err(|e| anyhow!("{e}"))?;
    let md = table(a, method, &found.periods, &found.cells, &found.rows, started.elapsed().as_secs_f64());
    print!("{md}");
    let prefix = crossval::grid_of(method).1;
    super::super::save_markdown(&out.join(format!("interp-{prefix}.md")), &md)?;
    for (_, run) in &found.rows {
        let name = format!("interp-{prefix}-{}-{}.png", run.sample, run.cond.tag());
        super::super::save_png(&spectra_plot(run, method)?, &out.join(name));
    }
    Ok(())
}
