//! The shipped mesh graph end to end: `graphs/mesh-scan.toml` scans a
//! frustum scene and renders it through the whole chain on the simulated lab.

use evflow_engine::{check, graph::parse_graph, Override, Plan, PlanOptions};
use std::path::{Path, PathBuf};

fn graph_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/mesh-scan.toml")
}

fn plan(text: &str, sets: &[&str], out: &Path) -> Plan {
    let g = parse_graph(&graph_path(), text).unwrap_or_else(|e| panic!("{e}"));
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let checked = check(&g, &evflow_nodes::registry(), &overrides).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions { out_dir: Some(out.to_path_buf()), ..Default::default() };
    Plan::build(&checked, &opts).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs tick by tick, collecting (x, y, intensity, edge intensity, force).
fn run(plan: &mut Plan) -> Vec<[f64; 5]> {
    let mut rows = Vec::new();
    while plan.remaining_ticks().unwrap_or(0) > 0 {
        plan.step(1).unwrap();
        let get = |n: &str, k: usize| plan.output(n, k).map_or(0.0, |v| v[0]);
        rows.push([get("finger", 0), get("finger", 1), get("surface", 0), get("edges", 0), get("display", 0)]);
    }
    rows
}

#[test]
fn frustum_scene_renders_holes_edges_and_force() {
    let text = std::fs::read_to_string(graph_path()).unwrap();
    let out = tempfile::tempdir().unwrap();
    let mut p = plan(&text, &[], out.path());
    let rows = run(&mut p);
    assert!(rows.len() > 9000);
    for r in &rows {
        assert!(r.iter().all(|v| v.is_finite()));
        assert!((0.3..=1.0).contains(&r[2]));
    }
    // Line 2 runs along +x at y = 3 cm across the top-left hole (centre −3, 3):
    // into the hole the wall descends (assists: I = 0.3), out of it the wall
    // climbs (resists: I = 1.0) — §4.1 with the calibrated F_max ≈ 1.06 √N
    // below the wall's F^sq = √2.
    let on_line = |x0: f64, x1: f64| {
        rows.iter().filter(move |r| (r[1] - 0.03).abs() < 1e-9 && r[0] > x0 && r[0] < x1).map(|r| r[2])
    };
    assert!(on_line(-0.042, -0.038).all(|i| i == 0.3));
    assert!(on_line(-0.022, -0.018).all(|i| i == 1.0));
    assert!(on_line(-0.042, -0.038).count() > 50);
    // Edges: the hole rims are convex (θ = 180° − atan 2); crossings tick.
    let ticks: Vec<_> = rows.iter().filter(|r| r[3] > 0.0).collect();
    assert!(ticks.len() >= 4, "{}", ticks.len());
    assert!(ticks.iter().all(|r| (0.3..=1.0).contains(&r[3])));
    // The display's friction follows the intensity: more force where I = 1.
    let mean = |f: &dyn Fn(&[f64; 5]) -> bool| {
        let v: Vec<f64> = rows.iter().filter(|r| f(r)).map(|r| r[4]).collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let hi = mean(&|r| r[2] == 1.0);
    let lo = mean(&|r| r[2] == 0.3);
    assert!(hi > lo + 0.02, "force at I = 1: {hi}, at I = 0.3: {lo}");
    let s = p.finish().unwrap();
    let edges = &s.iter().find(|(n, _)| n == "edges").unwrap().1;
    assert!((edges.get("theta_min").unwrap() - (180.0 - (0.2f64).acos().to_degrees())).abs() < 1e-9);
}

#[test]
fn without_the_edge_branch_mesh_edges_is_pruned() {
    // A Gaussian scene has no sharp edges: drop the edge branch's sinks and
    // the grain's edge input, and the plan leaves mesh.edges out unbuilt.
    let text = std::fs::read_to_string(graph_path()).unwrap();
    let text = text
        .replace("    \"edges.intensity -> grain.edge\",\n", "")
        .replace("    \"edges.intensity -> edge_stats.in\",\n", "")
        .replace("    \"edges.intensity -> record.edge\",\n", "")
        .replace(
            "channels = [\"u\", \"intensity\", \"edge\", \"force\"]",
            "channels = [\"u\", \"intensity\", \"force\"]",
        )
        .replace("units = [\"1\", \"1\", \"1\", \"N\"]", "units = [\"1\", \"1\", \"N\"]")
        .replace("edges = [\"edge\"]", "")
        .replace("[nodes.edge_stats]\ntype = \"stats\"\n", "");
    let out = tempfile::tempdir().unwrap();
    let mut p = plan(&text, &["shape=\"gaussian\"", "lines=1"], out.path());
    assert!(p.index("edges").is_none());
    assert!(p.pruned().iter().any(|x| format!("{x:?}").contains("edges")));
    assert!(p.index("surface").is_some());
    let rows = run(&mut p);
    assert!(rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
}
