//! Scene-driven pruning end to end on graph files (docs/pruning.md): the
//! output of a graph is identical with and without the planner's
//! constants, and what fed only a constant is never built — its files
//! never opened.

use evflow_engine::plan::Folding;
use evflow_engine::{load_file, Checked, Override, Plan, PlanOptions};
use std::collections::BTreeMap;
use std::path::Path;

/// What a run produced: every file written (name → bytes), every value
/// reported (node.name → value) and the samples of one output per tick.
#[derive(Debug, PartialEq)]
struct Output {
    files: BTreeMap<String, Vec<u8>>,
    values: BTreeMap<String, f64>,
    samples: Vec<f64>,
}

fn checked(graph: &Path, sets: &[&str]) -> Checked {
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    load_file(graph, &evflow_nodes::registry(), &o).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `seconds` of the graph (at most its `duration`) in blocks of 64 ticks, recording output
/// `watch` (node, port index) each block, into `out`.
fn run(c: &Checked, folding: Folding, out: &Path, watch: (&str, usize), seconds: f64) -> (Output, Plan) {
    let opts = PlanOptions { max_block: 64, out_dir: Some(out.to_path_buf()), timing: false, ..Default::default() };
    let mut plan = Plan::build_with(c, &opts, folding).unwrap_or_else(|e| panic!("{e}"));
    let seconds = plan.duration().map_or(seconds, |d| d.min(seconds));
    let ticks = (seconds * plan.base_rate()).round() as u64;
    let ticks = plan.remaining_ticks().map_or(ticks, |r| r.min(ticks));
    let mut samples = Vec::new();
    let mut done = 0;
    while done < ticks {
        let n = (ticks - done).min(64);
        plan.step(n as usize).unwrap();
        samples.extend_from_slice(plan.output(watch.0, watch.1).unwrap());
        done += n;
    }
    let mut values = BTreeMap::new();
    for (node, s) in plan.finish().unwrap() {
        for (k, v, _) in s.values {
            values.insert(format!("{node}.{k}"), v);
        }
    }
    let mut files = BTreeMap::new();
    for e in std::fs::read_dir(out).unwrap() {
        let p = e.unwrap().path();
        files.insert(p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap());
    }
    (Output { files, values, samples }, plan)
}

fn folded(plan: &Plan) -> Vec<&str> {
    plan.folded().iter().map(|f| f.node.as_str()).collect()
}

#[test]
fn mesh_live_on_the_gaussian_scenes_renders_the_same_without_mesh_edges() {
    let c = checked(Path::new("../graphs/mesh-live.toml"), &[]);
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (pruned, plan) = run(&c, Folding::On, a.path(), ("display", 0), 2.0);
    assert_eq!(folded(&plan), ["edges"]);
    assert!(plan.folded()[0].reason.contains("no convex edge sharper than max_angle = 160° in any of its 5 meshes"));
    let (full, plan) = run(&c, Folding::Off, b.path(), ("display", 0), 2.0);
    assert!(plan.folded().is_empty());
    assert_eq!(pruned.samples.len(), 2000);
    assert_eq!(pruned.samples, full.samples, "the display's force, tick by tick");
    // Every value reported is the same, but the left-out node's own.
    let mut full_values = full.values.clone();
    full_values.retain(|k, _| !k.starts_with("edges."));
    assert_eq!(full.values["edges.crossings"], 0.0);
    assert_eq!(pruned.values, full_values);
    // Frustums have sharp edges: nothing is replaced.
    let c = checked(Path::new("../graphs/mesh-live.toml"), &["shape=frustum"]);
    let (_, plan) = run(&c, Folding::On, a.path(), ("display", 0), 0.1);
    assert!(plan.folded().is_empty() && plan.pruned().is_empty());
}

/// A recorded actuation switched off by a gain of 0 and mixed with a tone,
/// recorded to a file and summarised.
fn recording_graph(dir: &Path, recording: &str) -> std::path::PathBuf {
    let text = format!(
        r#"[graph]
format = 1
name = "switched-off"
rate = 1000.0
duration = 0.5
connections = ["rec.u -> off.in", "off.out -> mix.a", "tone.out -> mix.b", "mix.out -> twice.in", "twice.out -> stats.in", "mix.out -> record.y"]

[nodes.rec]
type = "recording.in"
path = "{recording}"
channels = ["u"]

[nodes.off]
type = "gain"
gain = 0.0

[nodes.tone]
type = "sine"
frequency = 5.0
amplitude = 0.5

[nodes.mix]
type = "add"

[nodes.twice]
type = "gain"
gain = 2.0

[nodes.stats]
type = "stats"

[nodes.record]
type = "recording.out"
path = "mixed"
channels = ["y"]
"#
    );
    let path = dir.join("switched-off.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_recording_behind_a_zero_gain_is_never_opened_and_the_output_is_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = std::fs::canonicalize("../graphs/data/narx-felt-fabric/u-felt-fabric-60g-3cms.wav").unwrap();
    // A missing file: left out before anything is built, so no error.
    let missing = recording_graph(dir.path(), "no-such-recording.wav");
    let (a, b, d) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (pruned, plan) = run(&checked(&missing, &[]), Folding::On, a.path(), ("mix", 0), 1.0);
    assert_eq!(folded(&plan), ["off"]);
    assert_eq!(plan.pruned()[0].node, "rec");
    assert_eq!(plan.pruned()[0].reason, "feeds only `off`, which is replaced by a constant");
    // Unpruned, the missing file is an error naming it.
    let opts = PlanOptions { out_dir: Some(d.path().to_path_buf()), ..Default::default() };
    let e = Plan::build_with(&checked(&missing, &[]), &opts, Folding::Off).err().unwrap().to_string();
    assert!(e.contains("node `rec`") && e.contains("no-such-recording"), "{e}");
    // With a real recording, unpruned: the same samples, files and values.
    let real = recording_graph(dir.path(), &shipped.to_string_lossy());
    let (full, plan) = run(&checked(&real, &[]), Folding::Off, b.path(), ("mix", 0), 1.0);
    assert!(plan.index("rec").is_some());
    assert_eq!(pruned.samples.len(), 500);
    assert_eq!(pruned, full);
    assert!(full.files.contains_key("mixed.wav") && full.values["stats.rms"] > 0.0, "{:?}", full.values);
}

#[test]
fn a_branch_disabled_by_a_swept_variable_is_left_out_at_that_point_only() {
    // mesh-scan's edge branch through a gain bound to a variable, swept 0 and 1.
    let text = std::fs::read_to_string("../graphs/mesh-scan.toml")
        .unwrap()
        .replace(
            "\"edges.intensity -> grain.edge\",",
            "\"edges.intensity -> edge_gain.in\", \"edge_gain.out -> grain.edge\",",
        )
        .replace("\"edges.intensity -> edge_stats.in\",", "")
        .replace("\"edges.intensity -> record.edge\",", "\"edge_gain.out -> record.edge\",")
        .replace("[nodes.edge_stats]\ntype = \"stats\"\n", "")
        .replace("[vars]\n", "[vars]\nedges = 1.0\n")
        .replace("[nodes.grain]", "[nodes.edge_gain]\ntype = \"gain\"\ngain = \"$edges\"\n\n[nodes.grain]")
        + "\n[sweep]\nedges = [0.0, 1.0]\n";
    let dir = tempfile::tempdir().unwrap();
    let graph = dir.path().join("mesh-scan-swept.toml");
    std::fs::write(&graph, text).unwrap();
    for (point, left_out) in [("edges=0.0", true), ("edges=1.0", false)] {
        let c = checked(&graph, &[point]);
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let (pruned, plan) = run(&c, Folding::On, a.path(), ("limit", 0), 3.0);
        if left_out {
            assert_eq!(folded(&plan), ["edge_gain"]);
            let names: Vec<&str> = plan.pruned().iter().map(|p| p.node.as_str()).collect();
            assert_eq!(names, ["edges"], "{:?}", plan.pruned());
            assert!(plan.notes().iter().all(|(n, _)| n != "edges"), "never built");
        } else {
            assert!(plan.folded().is_empty() && plan.pruned().is_empty());
        }
        let (full, _) = run(&c, Folding::Off, b.path(), ("limit", 0), 3.0);
        assert_eq!(pruned.samples, full.samples, "{point}");
        assert_eq!(pruned.files, full.files, "{point}");
        let mut full_values = full.values.clone();
        full_values.retain(|k, _| !left_out || !k.starts_with("edges."));
        assert_eq!(pruned.values, full_values, "{point}");
    }
}
