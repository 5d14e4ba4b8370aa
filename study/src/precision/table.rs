//! The summary of `evflow report precision`: one row per curve — the
//! shipped default, its error and cost, the cheapest setting within 10 % of
//! the best error, the reference — as Markdown and CSV.

use super::curve::Curve;
use crate::figure::{Plot, Series};

/// One computation's summary.
#[derive(Debug, Clone)]
pub struct Row {
    /// What is computed.
    pub computation: String,
    /// The knob.
    pub knob: String,
    /// The shipped default's setting.
    pub default: String,
    /// Its error (NaN if the default was not measured).
    pub default_error: f64,
    /// Its cost, s per unit.
    pub default_cost: f64,
    /// The cheapest setting within 10 % of the best error.
    pub cheapest: String,
    /// Its error.
    pub cheapest_error: f64,
    /// Its cost, s per unit.
    pub cheapest_cost: f64,
    /// The best error of any setting.
    pub best_error: f64,
    /// What the error is.
    pub error_unit: String,
    /// What one unit of cost is.
    pub cost_unit: String,
    /// The reference.
    pub reference: String,
    /// The reference's own error.
    pub reference_error: f64,
}

impl Row {
    /// The summary of `c`.
    pub fn of(c: &Curve) -> Self {
        let d = c.default_point();
        let ch = c.cheapest();
        Row {
            computation: c.computation.clone(),
            knob: c.knob.clone(),
            default: c.default.clone(),
            default_error: d.map_or(f64::NAN, |p| p.error),
            default_cost: d.map_or(f64::NAN, |p| p.cost),
            cheapest: ch.map_or_else(String::new, |p| p.setting.clone()),
            cheapest_error: ch.map_or(f64::NAN, |p| p.error),
            cheapest_cost: ch.map_or(f64::NAN, |p| p.cost),
            best_error: c.best_error().unwrap_or(f64::NAN),
            error_unit: c.error_unit.clone(),
            cost_unit: c.cost_unit.clone(),
            reference: c.reference.clone(),
            reference_error: c.reference_error,
        }
    }
}

/// A duration in s as the table prints it (ns, µs, ms or s).
pub fn time(s: f64) -> String {
    if !s.is_finite() {
        "–".into()
    } else if s < 1e-6 {
        format!("{:.1} ns", s * 1e9)
    } else if s < 1e-3 {
        format!("{:.2} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

fn err(e: f64) -> String {
    if e.is_finite() {
        format!("{e:.2e}")
    } else {
        "–".into()
    }
}

/// The Markdown table of `rows`.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| computation | knob | shipped default | its error | its cost | cheapest within 10 % of the best error | its error | its cost | best error | error | cost per | reference (its own error) |\n\
         |---|---|---|---:|---:|---|---:|---:|---:|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) |\n",
            r.computation,
            r.knob,
            r.default,
            err(r.default_error),
            time(r.default_cost),
            r.cheapest,
            err(r.cheapest_error),
            time(r.cheapest_cost),
            err(r.best_error),
            r.error_unit,
            r.cost_unit,
            r.reference,
            err(r.reference_error),
        );
    }
    s
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV of every curve's points (one line per setting).
pub fn csv(curves: &[Curve]) -> String {
    let mut s =
        String::from("curve,series,setting,error,cost_s,work,default,on_front,error_unit,cost_unit,reference\n");
    for c in curves {
        let front = super::curve::front(&c.points, super::curve::CostBy::Time);
        for (i, p) in c.points.iter().enumerate() {
            s += &format!(
                "{},{},{},{:e},{:e},{:e},{},{},{},{},{}\n",
                csv_field(&c.name),
                csv_field(&p.series),
                csv_field(&p.setting),
                p.error,
                p.cost,
                p.work,
                p.setting == c.default,
                front.contains(&i),
                csv_field(&c.error_unit),
                csv_field(&c.cost_unit),
                csv_field(&c.reference),
            );
        }
    }
    s
}

/// The curve's work-precision figure (log-log): a line per series, the
/// baseline when there is one, the shipped default marked.
pub fn figure(c: &Curve) -> Plot {
    let mut series: Vec<Series> = c
        .series()
        .into_iter()
        .map(|(name, pts)| Series::line_points(name, pts.iter().map(|p| (p.cost, p.error)).collect()))
        .collect();
    if let Some(b) = c.baseline {
        let costs = c.points.iter().map(|p| p.cost).filter(|x| x.is_finite() && *x > 0.0);
        let (lo, hi) = costs.fold((f64::INFINITY, 0.0_f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
        if lo <= hi {
            series.push(Series::line_points("left out (baseline)", vec![(lo, b), (hi, b)]));
        }
    }
    if let Some(d) = c.default_point() {
        series.push(Series::points(format!("shipped default: {}", d.setting), vec![(d.cost, d.error)]));
    }
    Plot {
        title: format!("{}: error against run time", c.computation),
        x_label: format!("run time per {}, s", c.cost_unit),
        // The reference is long: table.md names it beside every row.
        y_label: c.error_unit.clone(),
        log_x: true,
        log_y: true,
        series,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::precision::WorkPoint;

    #[test]
    fn a_row_and_its_table() {
        let pt =
            |s: &str, e: f64, c: f64| WorkPoint { setting: s.into(), series: "x".into(), error: e, cost: c, work: c };
        let c = Curve {
            name: "n".into(),
            computation: "thing".into(),
            knob: "k".into(),
            error_unit: "rel".into(),
            cost_unit: "sample".into(),
            reference: "exact".into(),
            reference_error: 0.0,
            baseline: None,
            default: "b".into(),
            points: vec![pt("a", 1e-2, 1e-8), pt("b", 1e-4, 1e-7), pt("c, fine", 0.95e-4, 1e-6)],
        };
        let r = Row::of(&c);
        assert_eq!((r.default_error, r.cheapest.as_str(), r.best_error), (1e-4, "b", 0.95e-4));
        let md = markdown(&[r]);
        assert!(md.contains("| thing | k | b | 1.00e-4 | 100.0 ns | b | 1.00e-4 | 100.0 ns | 9.50e-5 |"), "{md}");
        let csv = csv(&[c]);
        assert_eq!(csv.lines().count(), 4);
        assert!(csv.contains("n,x,\"c, fine\",9.5e-5,1e-6,1e-6,false,true,"), "{csv}");
        assert_eq!(time(2.5e-3), "2.50 ms");
    }
}
