//! Every shipped graph runs as-is on the simulated lab, and runs
//! deterministically: two runs with the same seed write identical bytes.

use evflow_engine::{load_file, run_offline, Plan, PlanOptions, RunOptions};
use std::collections::BTreeMap;
use std::path::Path;

/// Files written by a run (name → bytes) and values reported (node, name, value).
type RunOutput = (BTreeMap<String, Vec<u8>>, Vec<(String, String, f64)>);

/// Runs a graph into `out` and returns every file written, by name, with its
/// bytes, plus the reported values.
fn run(graph: &Path, out: &Path) -> RunOutput {
    let checked = load_file(graph, &evflow_nodes::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions { out_dir: Some(out.to_path_buf()), ..Default::default() };
    let mut plan = Plan::build(&checked, &opts).unwrap_or_else(|e| panic!("{e}"));
    // Endless graphs run for their own `duration`; cap long ones for the suite.
    let duration = plan.duration().map(|d| d.min(5.0));
    let report = run_offline(&mut plan, RunOptions { duration, progress: None }).unwrap_or_else(|e| panic!("{e}"));
    let mut files = BTreeMap::new();
    collect(out, out, &mut files);
    let values = report
        .summaries
        .iter()
        .flat_map(|(n, s)| s.values.iter().map(move |(k, v, _)| (n.clone(), k.clone(), *v)))
        .collect();
    (files, values)
}

/// Every file under `dir` (subfolders too), by its path relative to `root`.
fn collect(root: &Path, dir: &Path, files: &mut BTreeMap<String, Vec<u8>>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            collect(root, &p, files);
        } else {
            let name = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
            files.insert(name, std::fs::read(&p).unwrap());
        }
    }
}

#[test]
fn every_shipped_graph_runs_and_is_deterministic() {
    let graphs = evflow_tests::shipped_graphs();
    assert!(!graphs.is_empty(), "graphs/ holds no graph");
    for (path, _) in graphs {
        let a = tempfile::tempdir().unwrap();
        let b = tempfile::tempdir().unwrap();
        let (fa, va) = run(&path, a.path());
        let (fb, vb) = run(&path, b.path());
        assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>(), "{}", path.display());
        for (name, bytes) in &fa {
            assert!(fb[name] == *bytes, "{}: {name} differs between two runs", path.display());
        }
        assert_eq!(va.len(), vb.len());
        for (x, y) in va.iter().zip(&vb) {
            assert_eq!(x.0, y.0);
            assert!(x.2.to_bits() == y.2.to_bits(), "{}: {} {} differs: {} vs {}", path.display(), x.0, x.1, x.2, y.2);
        }
    }
}

#[test]
fn every_shipped_graph_round_trips_through_save() {
    for (path, text) in evflow_tests::shipped_graphs() {
        let g = evflow_engine::graph::parse_graph(&path, &text).unwrap_or_else(|e| panic!("{e}"));
        let saved = g.to_toml();
        let g2 = evflow_engine::graph::parse_graph(&path, &saved).unwrap_or_else(|e| panic!("{e}\n{saved}"));
        assert_eq!(g.without_locations(), g2.without_locations(), "{}", path.display());
    }
}

#[test]
fn every_run_of_every_shipped_sweep_validates() {
    use evflow_engine::sweep::points;
    for (path, text) in evflow_tests::shipped_graphs() {
        let g = evflow_engine::graph::parse_graph(&path, &text).unwrap_or_else(|e| panic!("{e}"));
        let sweep = evflow_engine::sweep_files::expand(&g, &[], &evflow_nodes::recording::sweep_fields::sweep_fields)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for p in points(&sweep, &[], &[]) {
            if let Err(e) = evflow_engine::check(&g, &evflow_nodes::registry(), &p.overrides()) {
                panic!("{}: sweep run {}: {e}", path.display(), p.label());
            }
        }
    }
}
