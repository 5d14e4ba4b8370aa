//! Draws a graph's `[[plot]]` figures from the results of its runs: `evflow
//! run` after a sweep, and `evflow merge` after joining a sweep's shards (a
//! plot of the whole sweep is drawn from every run, never by a shard).

use crate::fit::{polyfit, square_law, PolyFit};
use crate::floor_fit::{square_over_floor, FloorFit};
use crate::plot::{write_png, Plot, Series};
use evflow_engine::check::interpolate::text_of;
use evflow_engine::graph::{Fit, Graph, PlotDecl};
use evflow_engine::sweep::Point;
use evflow_engine::{Override, RunReport, Value};
use std::path::Path;

/// A quantity of one run: a variable, a reported value, a node's run time
/// or the run's total time. `None` when the run does not have it.
fn quantity(q: &str, point: &Point, sets: &[Override], graph: &Graph, r: &RunReport) -> Option<f64> {
    if q == "seconds" {
        return Some(r.elapsed.as_secs_f64());
    }
    if let Some(v) = var(q, point, sets, graph) {
        return v.as_f64();
    }
    let (node, name) = q.split_once('.')?;
    if name == "time" {
        if let Some(t) = r.times.iter().find(|t| t.node == node) {
            return Some(t.elapsed.as_secs_f64());
        }
    }
    r.value(node, name)
}

/// The unit a sink gave a reported value (none for plain numbers).
fn unit(q: &str, runs: &[(Point, RunReport)]) -> Option<String> {
    let (node, name) = q.split_once('.')?;
    runs.iter()
        .flat_map(|(_, r)| r.summaries.iter().filter(|(n, _)| n == node))
        .flat_map(|(_, s)| s.values.iter().filter(|(k, _, _)| k == name))
        .map(|(_, _, u)| u.clone())
        .find(|u| !u.is_empty() && u != "1" && u != evflow_engine::check::units::UNKNOWN)
}

/// A variable's value in one run: swept, set on the command line, or declared.
fn var(name: &str, point: &Point, sets: &[Override], graph: &Graph) -> Option<Value> {
    point
        .values
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.clone())
        .or_else(|| sets.iter().find(|o| o.key == name).map(|o| o.value.clone()))
        .or_else(|| graph.vars.iter().find(|v| v.name == name).map(|v| v.value.clone()))
}

/// A curve fitted to a series.
enum Curve {
    /// A polynomial (linear, quadratic, the square law).
    Poly(PolyFit),
    /// The square law over a measured floor.
    Floor(FloorFit),
}

impl Curve {
    fn eval(&self, x: f64) -> f64 {
        match self {
            Curve::Poly(f) => f.eval(x),
            Curve::Floor(f) => f.eval(x),
        }
    }
    fn formula(&self) -> String {
        match self {
            Curve::Poly(f) => f.formula(),
            Curve::Floor(f) => f.formula(),
        }
    }
    fn r2(&self) -> f64 {
        match self {
            Curve::Poly(f) => f.r2,
            Curve::Floor(f) => f.r2,
        }
    }
}

/// The fit `fit` through `pts`: `None` for no fit, an error saying why a
/// fit could not be made.
fn fit_curve(fit: Fit, pts: &[(f64, f64)]) -> Option<Result<Curve, String>> {
    let poly = |f: Option<PolyFit>, d: usize| {
        f.map(Curve::Poly).ok_or_else(|| format!("too few distinct points for a degree-{d} fit"))
    };
    match fit {
        Fit::None => None,
        Fit::Linear => Some(poly(polyfit(pts, 1), 1)),
        Fit::Quadratic => Some(poly(polyfit(pts, 2), 2)),
        Fit::Square => Some(poly(square_law(pts), 2)),
        Fit::SquareOverFloor => Some(square_over_floor(pts).map(Curve::Floor).map_err(|e| e.to_string())),
    }
}

/// A value for a legend: four significant digits (exponent form far from 1).
fn short(v: f64) -> String {
    let mag = if v == 0.0 { 0.0 } else { v.abs().log10().floor() };
    if !(-4.0..6.0).contains(&mag) {
        return format!("{v:.3e}");
    }
    let decimals = (3.0 - mag).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// Draws every plot of `graph` into `out`; returns lines for people (files
/// written, fits with R²) and errors for plots that could not be drawn.
pub fn draw_plots(
    graph: &Graph,
    runs: &[(Point, RunReport)],
    sets: &[Override],
    out: &Path,
) -> (Vec<String>, Vec<String>) {
    let mut lines = Vec::new();
    let mut errors = Vec::new();
    for p in &graph.plots {
        match draw(p, graph, runs, sets, out) {
            Ok(mut l) => lines.append(&mut l),
            Err(e) => errors.push(e),
        }
    }
    (lines, errors)
}

fn draw(
    p: &PlotDecl,
    graph: &Graph,
    runs: &[(Point, RunReport)],
    sets: &[Override],
    out: &Path,
) -> Result<Vec<String>, String> {
    // Series: one per y quantity and value of the `series` variable.
    let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (point, r) in runs {
        let x = quantity(&p.x, point, sets, graph, r);
        let split = if p.series.is_empty() {
            String::new()
        } else {
            var(&p.series, point, sets, graph).map(|v| text_of(&v)).unwrap_or_default()
        };
        for y in &p.y {
            let name = match (p.y.len() > 1, split.is_empty()) {
                (true, true) => y.clone(),
                (true, false) => format!("{y}, {}={split}", p.series),
                (false, false) => format!("{}={split}", p.series),
                (false, true) => y.clone(),
            };
            let (Some(xv), Some(yv)) = (x, quantity(y, point, sets, graph, r)) else { continue };
            match groups.iter_mut().find(|(n, _)| *n == name) {
                Some((_, pts)) => pts.push((xv, yv)),
                None => groups.push((name, vec![(xv, yv)])),
            }
        }
    }
    if groups.is_empty() {
        return Err(format!("plot {}: no run reported `{}` and {}", p.file, p.x, p.y.join(", ")));
    }
    let mut lines = Vec::new();
    let mut series = Vec::new();
    let y_unit = |name: &str| {
        p.y.iter()
            .find(|y| name.starts_with(y.as_str()))
            .and_then(|y| unit(y, runs))
            .map_or(String::new(), |u| format!(" {u}"))
    };
    for (name, mut pts) in groups {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        match fit_curve(p.fit, &pts) {
            Some(Ok(f)) => {
                lines.push(format!(
                    "plot {}: {name}: {} fit {}, R² = {:.5}",
                    p.file,
                    p.fit.name(),
                    f.formula(),
                    f.r2()
                ));
                // A floor fit draws from x = 0, where the floor is measured.
                let (lo, hi) = (pts[0].0, pts[pts.len() - 1].0);
                let curve: Vec<(f64, f64)> =
                    (0..=100).map(|k| lo + (hi - lo) * k as f64 / 100.0).map(|x| (x, f.eval(x))).collect();
                series.push(Series::points(name.clone(), pts));
                series.push(Series::line(format!("{name}, {} fit (R² = {:.4})", p.fit.name(), f.r2()), curve));
                if let Curve::Floor(ff) = &f {
                    series.push(Series::line(
                        format!("floor: {name} at {} = 0, {}{}", p.x, short(ff.floor), y_unit(&name)),
                        vec![(lo, ff.floor), (hi, ff.floor)],
                    ));
                }
            }
            Some(Err(why)) => {
                lines.push(format!("plot {}: {name}: no {} fit: {why}", p.file, p.fit.name()));
                series.push(Series::line_points(name, pts));
            }
            None => series.push(Series::line_points(name, pts)),
        }
    }
    let labelled = |q: &String| match unit(q, runs) {
        Some(u) => format!("{q} ({u})"),
        None if q == "seconds" || q.ends_with(".time") => format!("{q} (s)"),
        None => q.clone(),
    };
    let plot = Plot {
        title: if p.title.is_empty() { graph.name.clone() } else { p.title.clone() },
        x_label: labelled(&p.x),
        y_label: p.y.iter().map(labelled).collect::<Vec<_>>().join(", "),
        log_x: p.log_x,
        log_y: p.log_y,
        series,
        ..Default::default()
    };
    let written = write_png(&plot, &out.join(&p.file)).map_err(|e| e.to_string())?;
    let note = if written.labelled { "" } else { " (no font found: drawn without text; see tools/src/plot/mod.rs)" };
    lines.push(format!("wrote {}{note}", written.path.display()));
    Ok(lines)
}
