//! A lab's own recordings through the shipped chains (issue 14, point 4):
//! the test records PRBS excitations and a texture at 10 kHz itself (on the
//! simulated lab, as a rig would, force low-passed at 500 Hz), then runs
//! `graphs/model-build-recordings.toml` over that folder — one model per
//! recording, each at the condition its sidecar states — and
//! `graphs/synthesize-recordings.toml` over the texture, which must find
//! the model of the texture's condition and write its cell.

use evflow_engine::RunOptions;
use evflow_engine::{check, graph::parse_graph, run_offline, sweep, sweep_files, Override, Plan, PlanOptions};
use evflow_nodes::recording::format::Recording;
use evflow_nodes::recording::sweep_fields::sweep_fields;
use std::path::Path;

/// Records the simulated lab at 10 kHz: `u` (a PRBS of order 20 clocked at
/// 1 kHz, or zero for a texture-like recording with the display off),
/// `force` low-passed at 500 Hz, `velocity`; one pass.
fn record(out: &Path, name: &str, mass: f64, speed: f64, seed: u64) {
    let text = format!(
        r#"[graph]
format = 1
rate = 10000.0
seed = {seed}
connections = [
    "excite.out -> display.u",
    "tribometer.load -> display.load",
    "tribometer.velocity -> display.velocity",
    "display.force -> sensor.surface_force",
    "tribometer.velocity -> sensor.velocity",
    "sensor.force -> lowpass.in",
    "excite.out -> record.u",
    "lowpass.out -> record.force",
    "tribometer.velocity -> record.velocity",
]
[nodes.excite]
type = "prbs"
rate = 10000.0
order = 20
clock = 10
[nodes.tribometer]
type = "sim.tribometer"
rate = 10000.0
speed = {speed}
mass = {mass}
passes = 1
[nodes.display]
type = "sim.display"
[nodes.sensor]
type = "sim.forcesensor"
[nodes.lowpass]
type = "butterworth"
kind = "lowpass"
order = 4
cutoff = 500.0
[nodes.record]
type = "recording.out"
path = "{name}"
channels = ["u", "force", "velocity"]
units = ["1", "N", "m/s"]
load_g = {mass}
velocity_cm_s = {speed}
material = "lab-sample"
"#
    );
    let g = parse_graph(&out.join("make.toml"), &text).unwrap_or_else(|e| panic!("{e}"));
    let c = check(&g, &evflow_nodes::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
    let mut plan = Plan::build(&c, &PlanOptions { out_dir: Some(out.to_path_buf()), ..Default::default() }).unwrap();
    run_offline(&mut plan, RunOptions::default()).unwrap();
}

/// Runs every point of a shipped graph's sweep with `overrides`, writing into `out`.
fn run_sweep(graph: &str, overrides: &[(&str, &str)], out: &Path) -> usize {
    let path = evflow_tests::root().join("graphs").join(graph);
    let g = parse_graph(&path, &std::fs::read_to_string(&path).unwrap()).unwrap_or_else(|e| panic!("{e}"));
    // As `--set k=v` reads them: TOML syntax, bare words (paths) as text.
    let o: Vec<Override> = overrides.iter().map(|(k, v)| Override::parse(&format!("{k}={v}")).unwrap()).collect();
    let axes = sweep_files::expand(&g, &o, &sweep_fields).unwrap_or_else(|e| panic!("{e}"));
    let points = sweep::points(&axes, &[], &o);
    for p in &points {
        let mut all = o.clone();
        all.extend(p.overrides());
        let c = check(&g, &evflow_nodes::registry(), &all).unwrap_or_else(|e| panic!("{}: {e}", p.label()));
        let mut plan = Plan::build(&c, &PlanOptions { out_dir: Some(out.to_path_buf()), ..Default::default() })
            .unwrap_or_else(|e| panic!("{}: {e}", p.label()));
        run_offline(&mut plan, RunOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", p.label()));
    }
    points.len()
}

#[test]
fn ten_khz_recordings_train_models_and_synthesize_cells() {
    let dir = tempfile::tempdir().unwrap();
    let (prbs, textures, models, cells) =
        (dir.path().join("prbs"), dir.path().join("textures"), dir.path().join("models"), dir.path().join("cells"));
    for d in [&prbs, &textures, &models, &cells] {
        std::fs::create_dir(d).unwrap();
    }
    record(&prbs, "a-85g-5cms", 85.0, 5.0, 1);
    record(&prbs, "b-60g-4cms", 60.0, 4.0, 2);
    record(&textures, "sample-60g-4cms-r1", 60.0, 4.0, 3);
    assert_eq!(Recording::open(&prbs.join("a-85g-5cms.json")).unwrap().rate(), 10_000.0);

    let runs =
        run_sweep("model-build-recordings.toml", &[("recordings", prbs.to_str().unwrap()), ("epochs", "5")], &models);
    assert_eq!(runs, 2);
    for (name, mass, speed) in [("narx-85g-5cms.json", 85.0, 5.0), ("narx-60g-4cms.json", 60.0, 4.0)] {
        let m = evflow_nodes::narx::model::Model::load(&models.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        // The model runs at the graph's 1 kHz, not the recording's 10 kHz,
        // and carries the sidecar's condition.
        assert_eq!(m.rate_hz, 1000.0, "{name}");
        assert_eq!((m.condition.mass_g, m.condition.speed_cm_s), (Some(mass), Some(speed)), "{name}");
    }

    let runs = run_sweep(
        "synthesize-recordings.toml",
        &[("textures", textures.to_str().unwrap()), ("models", models.to_str().unwrap())],
        &cells,
    );
    assert_eq!(runs, 1);
    let cell = Recording::open(&cells.join("narx-lab-sample/u-lab-sample-60g-4cms.json")).unwrap();
    let texture = Recording::open(&textures.join("sample-60g-4cms-r1.json")).unwrap();
    assert_eq!(cell.rate(), 1000.0);
    assert_eq!(cell.meta().condition.load_g, Some(60.0));
    assert_eq!(cell.meta().condition.material.as_deref(), Some("lab-sample"));
    // One cell sample per 10 texture samples (± the resampler's edges).
    let ratio = cell.frames() as f64 / texture.frames() as f64;
    assert!((ratio - 0.1).abs() < 0.002, "{} cell frames for {} texture frames", cell.frames(), texture.frames());
    let u = cell.channel("u").unwrap();
    assert!(u.iter().all(|v| v.is_finite()), "non-finite actuation");
    assert!(u.iter().any(|v| v.abs() > 0.1), "the cell is silent");
}

#[test]
fn a_sidecar_field_cannot_write_outside_the_output_folder() {
    // Issue 27, point 2: a recording whose `material` climbs out of the
    // output folder (`x/../../../../tmp/ESCAPED`) reaches the cell's path
    // through `${material}`; the sink refuses it, naming its parameter, and
    // nothing is written outside `out`.
    let dir = tempfile::tempdir().unwrap();
    let (tex, out) = (dir.path().join("tex"), dir.path().join("a/b/out"));
    std::fs::create_dir_all(&tex).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    let from = evflow_tests::root().join("graphs/data/textures/plastic-sheet-85g-5cms-r1");
    std::fs::copy(from.with_extension("wav"), tex.join("evil-85g-5cms-r1.wav")).unwrap();
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(from.with_extension("json")).unwrap()).unwrap();
    meta["condition"]["material"] = serde_json::json!("x/../../../../ESCAPED");
    std::fs::write(tex.join("evil-85g-5cms-r1.json"), meta.to_string()).unwrap();
    let path = evflow_tests::root().join("graphs/synthesize-recordings.toml");
    let g = parse_graph(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let models = evflow_tests::root().join("graphs/data/models");
    let o: Vec<Override> = [format!("textures={}", tex.display()), format!("models={}", models.display())]
        .iter()
        .map(|s| Override::parse(s).unwrap())
        .collect();
    let axes = sweep_files::expand(&g, &o, &sweep_fields).unwrap();
    let points = sweep::points(&axes, &[], &o);
    assert_eq!(points.len(), 1);
    let mut all = o.clone();
    all.extend(points[0].overrides());
    let c = check(&g, &evflow_nodes::registry(), &all).unwrap();
    let e = Plan::build(&c, &PlanOptions { out_dir: Some(out.clone()), ..Default::default() }).err().expect("refused");
    let e = e.to_string();
    assert!(e.contains("`path`") && e.contains("outside the output folder"), "{e}");
    // Nothing escaped: the only files under the temporary folder are the recording's.
    let mut found = Vec::new();
    let mut stack = vec![dir.path().to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                found.push(p);
            }
        }
    }
    assert!(found.iter().all(|p| p.starts_with(&tex)), "{found:?}");
}

#[test]
fn a_model_is_scored_on_a_second_recording_it_was_not_trained_on() {
    // Issue 27, point 11: a second excitation per condition, in a folder of
    // its own, scored through the model trained on the first.
    let dir = tempfile::tempdir().unwrap();
    let (prbs, validate, models) = (dir.path().join("prbs"), dir.path().join("validate"), dir.path().join("models"));
    for d in [&prbs, &validate, &models] {
        std::fs::create_dir(d).unwrap();
    }
    record(&prbs, "a-85g-5cms", 85.0, 5.0, 1);
    record(&validate, "b-85g-5cms", 85.0, 5.0, 7);
    assert_eq!(run_sweep("model-build-recordings.toml", &[("recordings", prbs.to_str().unwrap())], &models), 1);
    let path = evflow_tests::root().join("graphs/model-validate-recordings.toml");
    let g = parse_graph(&path, &std::fs::read_to_string(&path).unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let o: Vec<Override> = [("validation", &validate), ("models", &models)]
        .iter()
        .map(|(k, v)| Override::parse(&format!("{k}={}", v.display())).unwrap())
        .collect();
    let axes = sweep_files::expand(&g, &o, &sweep_fields).unwrap_or_else(|e| panic!("{e}"));
    let points = sweep::points(&axes, &[], &o);
    assert_eq!(points.len(), 1);
    let mut all = o.clone();
    all.extend(points[0].overrides());
    let c = check(&g, &evflow_nodes::registry(), &all).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let mut plan = Plan::build(&c, &PlanOptions { out_dir: Some(out), ..Default::default() }).unwrap();
    let r = run_offline(&mut plan, RunOptions::default()).unwrap();
    let v = |k: &str| r.value("score", k).unwrap_or_else(|| panic!("no score.{k}"));
    // Another PRBS than the one trained on, well above chance; with the
    // force replaced by noise, near chance.
    let (held_out, noise) = (v("transition_agreement"), v("noise_force_transition_agreement"));
    assert!(held_out > 0.6 && held_out > noise + 0.05, "held out {held_out}, noise force {noise}");
    assert!(v("samples") > 1000.0, "{}", v("samples"));
}
