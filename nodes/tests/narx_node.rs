//! The `narx.train` and `narx` nodes through the engine: training writes a
//! model the inference node runs; the closed loop stays bounded on inputs
//! far from the training data (issue point 11); data that cannot be learned
//! from and bad model files are refused with clear errors.

use evflow_engine::harness::Single;
use evflow_nodes::narx::labdata::{prbs, rbs, Lab};
use evflow_nodes::narx::model::Model;
use evflow_nodes::narx::{node, train_node};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

const TRAIN_PARAMS: &str = "path = \"m.json\"\nhidden = [12, 6]\nfeedback = 1\ninput = 10\nepochs = 40\n\
                            mass_g = 85.0\nspeed_cm_s = 5.0\nprogress = false\nseed = 3";

fn train<'a>(dir: &'a Path, params: &'a str, x: Vec<f64>, y: Vec<f64>) -> Single<'a> {
    let n = x.len() as u64;
    Single::new(&train_node::SPEC, params).input("x", x, 1000.0).input("y", y, 1000.0).ticks(n).block(512).base_dir(dir)
}

fn infer<'a>(dir: &'a Path, params: &'a str, force: Vec<f64>, rate: f64, block: usize) -> Single<'a> {
    let n = force.len() as u64;
    Single::new(&node::SPEC, params)
        .input("force", force, rate)
        .output("u")
        .base_rate(rate)
        .ticks(n)
        .block(block)
        .base_dir(dir)
}

/// A model trained by the node on the lab (RBS, 6000 samples), in a folder
/// kept for the whole test run.
fn trained() -> &'static (PathBuf, evflow_engine::Summary) {
    static M: OnceLock<(PathBuf, evflow_engine::Summary)> = OnceLock::new();
    M.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let u = rbs(6000, 1);
        let x = Lab::default().force(&u);
        let summary = train(&dir, TRAIN_PARAMS, x, u).summary().unwrap();
        (dir, summary)
    })
}

#[test]
fn the_train_node_writes_a_model_the_narx_node_runs() {
    let (dir, summary) = trained();
    eprintln!("{summary:?}");
    for key in ["train_mse", "validation_mse", "sign_agreement", "transition_agreement", "rms", "epochs", "seconds"] {
        assert!(summary.get(key).is_some(), "{key} missing from {summary:?}");
    }
    assert!(summary.get("transition_agreement").unwrap() > 0.75, "{summary:?}");
    assert!((summary.get("noise_force_transition_agreement").unwrap() - 0.5).abs() < 0.1, "{summary:?}");
    assert!(summary.lines.iter().any(|l| l.starts_with("wrote m.json")), "{summary:?}");
    assert!(!summary.lines.iter().any(|l| l.contains("WARNING")), "{summary:?}");
    let model = Model::load(&dir.join("m.json")).unwrap();
    assert_eq!(model.rate_hz, 1000.0);
    assert_eq!((model.condition.mass_g, model.condition.speed_cm_s), (Some(85.0), Some(5.0)));
    assert_eq!(model.architecture.hidden, vec![12, 6]);
    assert_eq!(model.training.seed, 3);
    // The node's output is the closed loop's, delayed by the look-ahead d.
    let d = model.delays.latency();
    assert!(d > 0);
    let v = prbs(11, 2000);
    let force = Lab { seed: 99, ..Lab::default() }.force(&v);
    let want = model.closed_loop().unwrap().run(&force);
    for block in [1, 64, 4096] {
        let got = infer(dir, "model = \"m.json\"", force.clone(), 1000.0, block).run().unwrap().remove(0);
        assert_eq!(got.len(), force.len());
        for t in d..got.len() {
            assert_eq!(got[t].to_bits(), want[t - d].to_bits(), "block {block}, tick {t}");
        }
    }
}

#[test]
fn the_closed_loop_stays_bounded_far_from_the_training_data() {
    let (dir, _) = trained();
    let model = Model::load(&dir.join("m.json")).unwrap();
    let (lo, hi) = (model.normalization.y.min, model.normalization.y.max);
    let v = rbs(3000, 5);
    let f = Lab { seed: 42, ..Lab::default() }.force(&v);
    let peak = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let cases: Vec<(&str, Vec<f64>)> = vec![
        ("×10 amplitude", f.iter().map(|x| 10.0 * x).collect()),
        ("DC step to 10× the peak", (0..3000).map(|i| if i < 500 { 0.0 } else { 10.0 * peak }).collect()),
        ("silence", vec![0.0; 3000]),
        ("±1e6 alternating", (0..3000).map(|i| if i % 2 == 0 { 1e6 } else { -1e6 }).collect()),
        (
            "NaN and infinity bursts",
            f.iter()
                .enumerate()
                .map(|(i, x)| match i % 100 {
                    0..=9 => f64::NAN,
                    10 => f64::INFINITY,
                    _ => *x,
                })
                .collect(),
        ),
        ("1e300", vec![1e300; 3000]),
    ];
    for (name, x) in cases {
        let mut cl = model.closed_loop().unwrap();
        let u = cl.run(&x);
        assert!(u.iter().all(|v| v.is_finite() && *v >= lo && *v <= hi), "{name}: out of [{lo}, {hi}]");
        // Silence and a constant settle: the loop does not oscillate forever between the rails.
        if name == "silence" || name == "1e300" {
            let tail = &u[2000..];
            let spread = tail.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
                - tail.iter().fold(f64::INFINITY, |m, v| m.min(*v));
            eprintln!("{name}: settles within {spread:.3e} (last value {:.4})", tail[tail.len() - 1]);
        }
    }
    // Through the node, clamping is counted and reported.
    let x: Vec<f64> = (0..1000).map(|i| if i % 2 == 0 { 1e3 } else { -1e3 }).collect();
    let s = infer(dir, "model = \"m.json\"", x, 1000.0, 64).summary().unwrap();
    assert!(s.get("clamped").is_some() && s.get("diverged").is_some(), "{s:?}");
}

#[test]
fn training_refuses_data_it_cannot_learn_from() {
    let dir = tempfile::tempdir().unwrap();
    let u = rbs(3000, 1);
    let x = Lab::default().force(&u);
    let cases: Vec<(&str, Vec<f64>, Vec<f64>, &str)> = vec![
        ("constant force", vec![0.25; 3000], u.clone(), "the force x is constant (0.25) over all 3000 samples"),
        ("display off", x.clone(), vec![0.0; 3000], "the actuation y is constant (0) over all 3000 samples"),
        ("too short", x[..300].to_vec(), u[..300].to_vec(), "the recording is too short: 300 samples"),
    ];
    for (name, x, y, want) in cases {
        let e = train(dir.path(), TRAIN_PARAMS, x, y).summary().unwrap_err();
        eprintln!("{name}: {e}");
        assert!(e.contains(want), "{name}: want `{want}` in: {e}");
        assert!(!dir.path().join("m.json").exists() && !dir.path().join("m.json.tmp").exists(), "{name}");
    }
    // Skipped samples are left out of the count and said so.
    let params = format!("{TRAIN_PARAMS}\nskip = 2800");
    let e = train(dir.path(), &params, x, u).summary().unwrap_err();
    assert!(e.contains("200 samples") && e.contains("after skipping the first 2800 samples"), "{e}");
}

#[test]
fn the_narx_node_refuses_bad_model_files() {
    let (dir, _) = trained();
    // Trained at 1 kHz, asked to run at 2 kHz.
    let e = infer(dir, "model = \"m.json\"", vec![0.0; 10], 2000.0, 1).run().unwrap_err();
    assert!(e.contains("m.json") && e.contains("rate_hz") && e.contains("trained at 1000 Hz"), "{e}");
    let e = infer(dir, "model = \"nope.json\"", vec![0.0; 10], 1000.0, 1).run().unwrap_err();
    assert!(e.contains("nope.json") && e.contains("cannot read"), "{e}");
    let bad = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(dir.join("m.json")).unwrap().replace("\"version\": 1", "\"version\": 7");
    std::fs::write(bad.path().join("new.json"), text).unwrap();
    let e = infer(bad.path(), "model = \"new.json\"", vec![0.0; 10], 1000.0, 1).run().unwrap_err();
    assert!(e.contains("new.json") && e.contains("version 7 is not supported"), "{e}");
}

#[test]
fn skip_and_samples_cut_a_stretch_and_reruns_without_time_are_identical() {
    let dir = tempfile::tempdir().unwrap();
    let u = rbs(3000, 2);
    let x = Lab::default().force(&u);
    let params = "path = \"cut.json\"\nhidden = [4]\nfeedback = 1\ninput = 3\nepochs = 5\nprogress = false\n\
                  skip = 500\nsamples = 2000\nrecord_time = false\nseed = 9";
    let s = train(dir.path(), params, x.clone(), u.clone()).summary().unwrap();
    assert!(s.get("seconds").is_none(), "{s:?}");
    let first = std::fs::read(dir.path().join("cut.json")).unwrap();
    let m = Model::load(&dir.path().join("cut.json")).unwrap();
    assert_eq!(m.training.samples, 2000);
    assert_eq!(m.training.seconds, 0.0);
    assert_eq!(m.training.data_hash, evflow_nodes::narx::model::data_hash(&[&x[500..2500], &u[500..2500]]));
    train(dir.path(), params, x, u).summary().unwrap();
    assert_eq!(std::fs::read(dir.path().join("cut.json")).unwrap(), first, "a rerun wrote other bytes");
}

#[test]
fn a_gate_keeps_and_concatenates_the_open_stretches() {
    // Two open stretches, [300, 1300) and [1800, 2600): the model is trained
    // on exactly their concatenation (the data hash says so).
    let dir = tempfile::tempdir().unwrap();
    let u = rbs(3000, 4);
    let x = Lab::default().force(&u);
    let gate: Vec<f64> =
        (0..3000).map(|i| if (300..1300).contains(&i) || (1800..2600).contains(&i) { 1.0 } else { 0.0 }).collect();
    let params = "path = \"gated.json\"\nhidden = [4]\nfeedback = 1\ninput = 3\nepochs = 3\nprogress = false\n\
                  gate = [\"steady\"]\nrecord_time = false\nseed = 9";
    let mut single = train(dir.path(), params, x.clone(), u.clone());
    single.inputs.push(("steady", gate, 1000.0));
    single.summary().unwrap();
    let m = Model::load(&dir.path().join("gated.json")).unwrap();
    assert_eq!(m.training.samples, 1800);
    let cat = |s: &[f64]| [&s[300..1300], &s[1800..2600]].concat();
    assert_eq!(m.training.data_hash, evflow_nodes::narx::model::data_hash(&[&cat(&x), &cat(&u)]));
    // A gate that keeps too little is refused, saying how much it kept.
    let mut single = train(dir.path(), params, x, u);
    single.inputs.push(("steady", vec![0.0; 3000], 1000.0));
    let e = single.summary().unwrap_err();
    assert!(e.contains("gates kept 0 of 3000"), "{e}");
}
