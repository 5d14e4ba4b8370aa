//! `narx.grid`: every model runs closed loop all along; the output is the
//! nearest model's, chosen at each update and crossfaded on a change. After
//! a fade it is bit for bit what that model alone gives.

use evflow_engine::harness::Single;
use evflow_nodes::narx::fit::{fit, FitConfig};
use evflow_nodes::narx::{grid, node};
use std::path::Path;

/// Two small models that read the same force oppositely (u = sign x and
/// u = −sign x), at 60 g, 3 cm/s and 110 g, 7 cm/s, written into `dir`.
fn models(dir: &Path) {
    let x: Vec<f64> = (0..3000).map(|i| (i as f64 * 0.037).sin() + 0.3 * (i as f64 * 0.11).cos()).collect();
    for (k, (m, v)) in [(60.0, 3.0), (110.0, 7.0)].into_iter().enumerate() {
        let s = if k == 0 { 1.0 } else { -1.0 };
        let u: Vec<f64> = x.iter().map(|f| if s * f > 0.0 { 1.0 } else { -1.0 }).collect();
        let cfg = FitConfig {
            hidden: vec![5],
            feedback: 1,
            input: 3,
            lookahead: Some(1),
            options: evflow_nodes::narx::train::Options { max_epochs: 20, ..Default::default() },
            ..FitConfig::default()
        };
        let mut model = fit(&x, &u, &cfg, &mut |_| {}).expect("model");
        model.condition.mass_g = Some(m);
        model.condition.speed_cm_s = Some(v);
        model.save(&dir.join(format!("m{k}.json"))).expect("saved");
    }
}

fn force(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.8 * (i as f64 * 0.05).sin() + 0.2 * (i as f64 * 0.31).sin()).collect()
}

/// `narx.grid` over m0, m1 with the user's load and velocity; outputs u and model.
fn grid(dir: &Path, f: Vec<f64>, load: Vec<f64>, vel: Vec<f64>, block: usize) -> Result<Vec<Vec<f64>>, String> {
    let n = f.len() as u64;
    Single::new(&grid::SPEC, "models = [\"m0.json\", \"m1.json\"]\nupdate_rate = 10.0\ncrossfade = 10.0")
        .input("force", f, 1000.0)
        .input("load", load, 1000.0)
        .input("velocity", vel, 1000.0)
        .outputs(["u", "model"])
        .ticks(n)
        .block(block)
        .base_dir(dir)
        .run()
}

fn alone(dir: &Path, model: &str, f: Vec<f64>) -> Vec<f64> {
    let n = f.len() as u64;
    let params = format!("model = \"{model}\"");
    Single::new(&node::SPEC, &params)
        .input("force", f, 1000.0)
        .output("u")
        .ticks(n)
        .base_dir(dir)
        .run()
        .unwrap()
        .remove(0)
}

#[test]
fn the_nearest_model_is_heard_and_a_change_crossfades_at_the_next_update() {
    let dir = tempfile::tempdir().unwrap();
    models(dir.path());
    let n = 1000;
    // Near 60 g, 3 cm/s, then from sample 450 near 110 g, 7 cm/s (velocity negative: a reversal).
    let load: Vec<f64> = (0..n).map(|i| if i < 450 { 65.0 } else { 105.0 }).collect();
    let vel: Vec<f64> = (0..n).map(|i| if i < 450 { 3.5 } else { -6.5 }).collect();
    let out = grid(dir.path(), force(n), load.clone(), vel.clone(), 1).unwrap();
    let (u, model) = (&out[0], &out[1]);
    let (a, b) = (alone(dir.path(), "m0.json", force(n)), alone(dir.path(), "m1.json", force(n)));
    assert!(a.iter().zip(&b).filter(|(x, y)| x != y).count() > 100, "the two models differ");
    // The choice changes at the update after the condition did (10 Hz: sample 500).
    assert_eq!(&u[..500], &a[..500], "model 0 until the update");
    assert!(model[..500].iter().all(|&k| k == 0.0) && model[500..].iter().all(|&k| k == 1.0));
    // A 10-sample linear crossfade, then model 1 exactly (it ran all along).
    for j in 0..10 {
        let w = (j + 1) as f64 / 11.0;
        let want = (1.0 - w) * a[500 + j] + w * b[500 + j];
        assert!((u[500 + j] - want).abs() < 1e-12, "fade sample {j}");
    }
    assert_eq!(&u[510..], &b[510..], "model 1 after the fade");
    // The same at any block size.
    assert_eq!(grid(dir.path(), force(n), load, vel, 37).unwrap(), out);
}

#[test]
fn models_without_a_place_in_the_grid_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    models(dir.path());
    let params = |models: &str| format!("models = [{models}]");
    let run = |p: &str| {
        Single::new(&grid::SPEC, p)
            .input("force", vec![0.0; 10], 1000.0)
            .input("load", vec![85.0; 10], 1000.0)
            .input("velocity", vec![5.0; 10], 1000.0)
            .output("u")
            .ticks(10)
            .block(1)
            .base_dir(dir.path())
            .run()
            .unwrap_err()
    };
    let e = run(&params("\"m0.json\", \"m0.json\""));
    assert!(e.contains("m0.json") && e.contains("60 g, 3 cm/s is also the condition"), "{e}");
    let mut plain = evflow_nodes::narx::model::Model::load(&dir.path().join("m0.json")).unwrap();
    plain.condition.mass_g = None;
    plain.save(&dir.path().join("plain.json")).unwrap();
    let e = run(&params("\"m0.json\", \"plain.json\""));
    assert!(e.contains("plain.json") && e.contains("no mass_g and speed_cm_s"), "{e}");
    let e = run(&params("\"m0.json\", \"missing.json\""));
    assert!(e.contains("missing.json"), "{e}");
    let e = run(&params(""));
    assert!(e.contains("models"), "{e}");
}
