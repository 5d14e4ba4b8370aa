//! The tables of a run or a sweep, as `evflow run` prints and writes them
//! and `evflow merge` rebuilds them: the aligned text table, the CSV, the
//! JSON results, and numbers for people.

use evflow_engine::check::interpolate::text_of;
use evflow_engine::sweep::Point;
use evflow_engine::RunReport;

/// A value for people: integers as integers, others with six significant digits.
pub fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.0}")
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:.5e}")
    } else {
        let digits = (5 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
        format!("{v:.digits$}")
    }
}

/// ` unit` after a value for people, or nothing for a dimensionless value
/// or one whose unit could not be followed (`?`).
pub fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() || unit == "1" || unit == evflow_engine::check::units::UNKNOWN {
        String::new()
    } else {
        format!(" {unit}")
    }
}

pub use evflow_study::tables::Timings;

/// One run as JSON.
fn run_json(r: &RunReport, timings: Timings) -> serde_json::Value {
    let summaries: serde_json::Map<String, serde_json::Value> = r
        .summaries
        .iter()
        .map(|(node, s)| {
            let values: serde_json::Map<String, serde_json::Value> =
                s.values.iter().map(|(k, v, _)| (k.clone(), serde_json::json!(v))).collect();
            (node.clone(), serde_json::json!({ "values": values, "lines": s.lines }))
        })
        .collect();
    let times: Vec<serde_json::Value> = r
        .times
        .iter()
        .map(|t| serde_json::json!({ "node": t.node, "type": t.kind, "seconds": t.elapsed.as_secs_f64() }))
        .collect();
    match timings {
        Timings::Show => serde_json::json!({
            "ticks": r.ticks,
            "base_rate": r.base_rate,
            "seconds": r.elapsed.as_secs_f64(),
            "summaries": summaries,
            "times": times,
        }),
        Timings::Leave => serde_json::json!({ "ticks": r.ticks, "base_rate": r.base_rate, "summaries": summaries }),
    }
}

/// The results as JSON: one run's object, or for a sweep a list of
/// `{ "vars": {…}, "run": {…} }`.
pub fn report_json(runs: &[(Point, RunReport)], sweep: bool, timings: Timings) -> String {
    let v = if sweep {
        serde_json::Value::Array(
            runs.iter()
                .map(|(p, r)| {
                    let vars: serde_json::Map<String, serde_json::Value> =
                        p.values.iter().map(|(k, v)| (k.clone(), serde_json::json!(text_of(v)))).collect();
                    serde_json::json!({ "vars": vars, "run": run_json(r, timings) })
                })
                .collect(),
        )
    } else {
        runs.first().map(|(_, r)| run_json(r, timings)).unwrap_or(serde_json::Value::Null)
    };
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The `node.value` columns reported by any run, in first-seen order.
fn columns(runs: &[(Point, RunReport)]) -> Vec<(String, String)> {
    let mut cols: Vec<(String, String)> = Vec::new();
    for (_, r) in runs {
        for (node, s) in &r.summaries {
            for (k, _, _) in &s.values {
                if !cols.iter().any(|(n, c)| n == node && c == k) {
                    cols.push((node.clone(), k.clone()));
                }
            }
        }
    }
    cols
}

/// A sweep as an aligned text table: the swept variables, then every
/// reported value, then the run time (with [`Timings::Show`]).
pub fn sweep_table(runs: &[(Point, RunReport)], timings: Timings) -> String {
    let cols = columns(runs);
    let mut head: Vec<String> =
        runs.first().map(|(p, _)| p.values.iter().map(|(k, _)| k.clone()).collect()).unwrap_or_default();
    head.extend(cols.iter().map(|(n, c)| format!("{n}.{c}")));
    if timings == Timings::Show {
        head.push("seconds".into());
    }
    let mut rows = vec![head];
    for (p, r) in runs {
        let mut row: Vec<String> = p.values.iter().map(|(_, v)| text_of(v)).collect();
        row.extend(cols.iter().map(|(n, c)| r.value(n, c).map(number).unwrap_or_else(|| "-".into())));
        if timings == Timings::Show {
            row.push(format!("{:.3}", r.elapsed.as_secs_f64()));
        }
        rows.push(row);
    }
    let widths: Vec<usize> =
        (0..rows[0].len()).map(|j| rows.iter().map(|r| r[j].chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for (i, row) in rows.iter().enumerate() {
        let cells: Vec<String> = row.iter().zip(&widths).map(|(c, w)| format!("{c:>w$}")).collect();
        s.push_str(cells.join("  ").trim_end());
        s.push('\n');
        if i == 0 {
            s.push_str(&widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>().join("  "));
            s.push('\n');
        }
    }
    s
}

/// A sweep as CSV (full precision), with (for [`Timings::Show`]) the run
/// time and every node's run time in seconds (`NODE.time` columns) after
/// the reported values.
pub fn sweep_csv(runs: &[(Point, RunReport)], timings: Timings) -> String {
    let cols = columns(runs);
    let quote =
        |t: &str| if t.contains([',', '"', '\n']) { format!("\"{}\"", t.replace('"', "\"\"")) } else { t.to_string() };
    let mut head: Vec<String> =
        runs.first().map(|(p, _)| p.values.iter().map(|(k, _)| quote(k)).collect()).unwrap_or_default();
    head.extend(cols.iter().map(|(n, c)| quote(&format!("{n}.{c}"))));
    // Run time of every node, for work-precision tables.
    let nodes: Vec<String> = match timings {
        Timings::Show => {
            head.push("seconds".into());
            runs.first().map(|(_, r)| r.times.iter().map(|t| t.node.clone()).collect()).unwrap_or_default()
        }
        Timings::Leave => Vec::new(),
    };
    head.extend(nodes.iter().map(|n| quote(&format!("{n}.time"))));
    let mut s = head.join(",") + "\n";
    for (p, r) in runs {
        let mut row: Vec<String> = p.values.iter().map(|(_, v)| quote(&text_of(v))).collect();
        row.extend(cols.iter().map(|(n, c)| r.value(n, c).map(|v| format!("{v}")).unwrap_or_default()));
        if timings == Timings::Show {
            row.push(format!("{}", r.elapsed.as_secs_f64()));
        }
        for n in &nodes {
            let t = r.times.iter().find(|t| &t.node == n).map(|t| t.elapsed.as_secs_f64());
            row.push(t.map(|t| format!("{t}")).unwrap_or_default());
        }
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::graph::parse_cli_value;
    use evflow_engine::Summary;
    use std::time::Duration;

    fn run(label: &str, values: &[(&str, f64)]) -> (Point, RunReport) {
        let point = Point { values: vec![("name".into(), parse_cli_value(label))] };
        let summary =
            Summary { values: values.iter().map(|(k, v)| (k.to_string(), *v, "V".into())).collect(), lines: vec![] };
        let report = RunReport {
            ticks: 10,
            base_rate: 1000.0,
            elapsed: Duration::from_millis(1500),
            times: vec![],
            summaries: vec![("p".into(), summary)],
            left_out: vec![],
        };
        (point, report)
    }

    #[test]
    fn numbers_for_people() {
        assert_eq!(number(3.0), "3");
        assert_eq!(number(-1e15), "-1.00000e15");
        assert_eq!(number(0.5), "0.500000");
        assert_eq!(number(123.456789), "123.457");
        assert_eq!(number(2.5e-4), "2.50000e-4");
        assert_eq!(number(0.0), "0");
    }

    #[test]
    fn csv_quotes_and_keeps_full_precision_and_missing_columns() {
        let runs = [run("\"a,b\"", &[("x", 0.1 + 0.2)]), run("\"c\"", &[("y", 1.0)])];
        let csv = sweep_csv(&runs, Timings::Leave);
        assert_eq!(csv, "name,p.x,p.y\n\"a,b\",0.30000000000000004,\nc,,1\n");
        let timed = sweep_csv(&runs, Timings::Show);
        assert!(timed.starts_with("name,p.x,p.y,seconds\n") && timed.contains(",1.5\n"), "{timed}");
    }

    #[test]
    fn text_table_marks_missing_values() {
        let runs = [run("1", &[("x", 2.0)]), run("22", &[])];
        assert_eq!(sweep_table(&runs, Timings::Leave), "name  p.x\n----  ---\n   1    2\n  22    -\n");
    }

    #[test]
    fn json_of_one_run_or_a_sweep() {
        let runs = [run("1", &[("x", 2.0)])];
        let one: serde_json::Value = serde_json::from_str(&report_json(&runs, false, Timings::Leave)).unwrap();
        assert_eq!(
            one,
            serde_json::json!({ "ticks": 10, "base_rate": 1000.0, "summaries": { "p": { "values": { "x": 2.0 }, "lines": [] } } })
        );
        let sweep: serde_json::Value = serde_json::from_str(&report_json(&runs, true, Timings::Show)).unwrap();
        assert_eq!(sweep[0]["vars"]["name"], "1");
        assert_eq!(sweep[0]["run"]["seconds"], 1.5);
    }
}
