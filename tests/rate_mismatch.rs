//! The validator's rate-mismatch help is a ready fix: for each kind of
//! step, the node table and connections it suggests, pasted into the graph
//! file as written, make a graph that validates and runs with the node
//! library's real `decimate`, `hold` and `resample`.

use evflow_engine::graph::parse_graph;
use evflow_engine::{check, run_offline, Plan, PlanOptions, RunOptions};
use std::path::Path;

/// A 10 Hz sine at `a_hz` and a 3 Hz sine at `b_hz` added (`add` runs at
/// the rate of `a`), reported by `stats`.
fn graph(a_hz: f64, b_hz: f64) -> String {
    format!(
        r#"[graph]
format = 1
name = "mismatch"
rate = 1000.0
duration = 2.0
connections = [
  "a.out -> sum.a",
  "b.out -> sum.b",
  "sum.out -> level.in",
]

[nodes.a]
type = "sine"
rate = {a_hz:?}
frequency = 10.0

[nodes.b]
type = "sine"
rate = {b_hz:?}
frequency = 3.0

[nodes.sum]
type = "add"

[nodes.level]
type = "stats"
"#
    )
}

/// Applies a rate-mismatch help to the graph text: the connection replaced
/// by the two suggested ones, the node table appended.
fn paste(text: &str, help: &str) -> String {
    let lines: Vec<&str> = help.lines().map(str::trim).collect();
    let add = lines.iter().position(|l| l.ends_with("Add")).expect("an `Add` line");
    let with = lines.iter().position(|l| l.starts_with("and in `connections` replace")).expect("a replace line");
    let table = lines[add + 1..with].join("\n");
    let old = lines[with].split('"').nth(1).expect("the connection to replace");
    let new = lines[with + 1..].join("\n  ");
    let text = text.replace(&format!("\"{old}\","), &new);
    format!("{text}\n{table}\n")
}

fn check_and_run(text: &str) -> Result<(), String> {
    let reg = evflow_nodes::registry();
    let g = parse_graph(Path::new("mismatch.toml"), text).map_err(|e| e.to_string())?;
    let checked = check(&g, &reg, &[]).map_err(|e| e.to_string())?;
    let mut plan = Plan::build(&checked, &PlanOptions::default()).map_err(|e| e.to_string())?;
    let report = run_offline(&mut plan, RunOptions::default()).map_err(|e| e.to_string())?;
    let rms = report.summaries.iter().find(|(n, _)| n == "level").and_then(|(_, s)| s.get("rms"));
    assert!(rms.is_some_and(|r| r > 0.5), "{report:?}");
    Ok(())
}

#[test]
fn each_suggestion_pasted_as_written_makes_a_graph_that_runs() {
    for (a_hz, b_hz, node) in [(1000.0, 10_000.0, "decimate"), (1000.0, 40.0, "hold"), (100.0, 40.0, "resample")] {
        let text = graph(a_hz, b_hz);
        let err = check_and_run(&text).unwrap_err();
        assert!(err.contains("rate mismatch") && err.contains(&format!("insert a `{node}` node")), "{err}");
        let help = err.split("help: ").nth(1).expect("a help");
        let fixed = paste(&text, help);
        check_and_run(&fixed).unwrap_or_else(|e| panic!("{a_hz}/{b_hz}: {e}\n--- pasted graph:\n{fixed}"));
        assert!(fixed.contains(&format!("type = \"{node}\"")), "{fixed}");
    }
}
