//! Generic checks run on every node type of the library:
//! - its declaration is complete (doc, example, units and docs on every port
//!   and parameter) and its example builds;
//! - block processing ≡ per-sample processing (the live tick), bit for bit;
//! - `reset` restores the initial output;
//! - no NaN or Inf leaves it on a random input.

use evflow_engine::graph::parse_graph;
use evflow_engine::harness::Single;
use evflow_engine::{NodeSpec, Value};
use std::path::Path;

const TICKS: u64 = 3000;

/// Deterministic test input: a mix of a chirp and pseudo-random noise.
fn signal(len: usize, salt: u64) -> Vec<f64> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ salt;
    (0..len)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let t = i as f64 / 1000.0;
            0.5 * (2.0 * std::f64::consts::PI * (5.0 + 40.0 * t) * t).sin() + 0.3 * noise
        })
        .collect()
}

/// Files some node examples read (e.g. a recording), written into `dir`.
fn fixtures(dir: &Path) {
    use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
    std::fs::create_dir_all(dir.join("recordings")).expect("fixture folder");
    let meta = RecordingMeta::new(1000.0, vec![Channel::new("force", "N")]);
    let mut w = RecordingWriter::create(&dir.join("recordings/felt.wav"), meta).expect("fixture recording");
    for x in signal(TICKS as usize + 100, 99) {
        w.write_frame(&[0.2 + 0.05 * x]).expect("fixture frame");
    }
    w.finish().expect("fixture recording finished");
    // A 2 × 2 grid of actuation signals for `interp` (loads 60/110 g, velocities 3/7 cm/s).
    std::fs::create_dir_all(dir.join("recordings/grid")).expect("grid folder");
    for (k, (load, velocity)) in [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)].into_iter().enumerate() {
        let mut meta = RecordingMeta::new(1000.0, vec![Channel::new("u", "1")]);
        meta.condition.load_g = Some(load);
        meta.condition.velocity_cm_s = Some(velocity);
        let mut w =
            RecordingWriter::create(&dir.join(format!("recordings/grid/cell{k}.wav")), meta).expect("grid cell");
        for x in signal(4000, 7 + k as u64) {
            w.write_frame(&[x]).expect("grid frame");
        }
        w.finish().expect("grid cell finished");
    }
    // A small NARX model (the `narx` node's example), trained on a chirp.
    use evflow_nodes::narx::fit::{fit, FitConfig};
    let x = signal(2000, 7);
    let u: Vec<f64> = x.iter().map(|v| if *v > 0.0 { 1.0 } else { -1.0 }).collect();
    let cfg = FitConfig {
        hidden: vec![4],
        feedback: 1,
        input: 3,
        lookahead: Some(1),
        options: evflow_nodes::narx::train::Options { max_epochs: 3, ..Default::default() },
        ..FitConfig::default()
    };
    let model = fit(&x, &u, &cfg, &mut |_| {}).expect("fixture model");
    model.save(&dir.join("models/narx.json")).expect("fixture model written");
    // The same model at two conditions, for `narx.grid`'s example.
    for (m, v) in [(60.0, 3.0), (110.0, 7.0)] {
        let mut at = model.clone();
        at.condition.mass_g = Some(m);
        at.condition.speed_cm_s = Some(v);
        at.save(&dir.join(format!("models/narx-{m}g-{v}cms.json"))).expect("fixture grid model written");
    }
    // A forward model (`synth.optimize`'s example) of a square law behind a short filter.
    use evflow_nodes::synth::model_file::{ForwardModel, Training};
    use evflow_nodes::synth::volterra_fit::{fit as fit_forward, FitConfig as ForwardConfig};
    let u: Vec<f64> = signal(3000, 5).iter().map(|v| 2.0 * v).collect();
    let y: Vec<f64> = (0..u.len()).map(|n| (0.8 * u[n] - 0.3 * if n > 0 { u[n - 1] } else { 0.0 }).powi(2)).collect();
    let cfg = ForwardConfig { memory: 4, ..ForwardConfig::default() };
    let fitted = fit_forward(&u, &y, &vec![true; u.len()], &cfg).expect("fixture forward model");
    let training = Training {
        scores: fitted.scores,
        actuation_rms: 0.5,
        actuation_peak: 1.0,
        data_hash: String::new(),
        seconds: 0.0,
    };
    let forward = ForwardModel::new(
        &fitted.model,
        1000.0,
        &cfg.filter,
        Default::default(),
        fitted.noise,
        fitted.spectrum,
        training,
    );
    forward.save(&dir.join("models/forward.json")).expect("fixture forward model written");
    // The same forward model at the four corners, for `synth.live`'s example.
    for (m, v) in [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)] {
        let mut at = forward.clone();
        at.condition.mass_g = Some(m);
        at.condition.speed_cm_s = Some(v);
        at.save(&dir.join(format!("models/forward-{m}g-{v}cms.json"))).expect("fixture grid forward model written");
    }
}

struct Case {
    inputs: Vec<(String, Vec<f64>)>,
    outputs: Vec<String>,
}

fn case(spec: &NodeSpec) -> Case {
    let doc = format!(
        "[graph]\nformat = 1\nname = \"x\"\nrate = 1000\n[nodes.x]\ntype = \"{}\"\n{}\n",
        spec.name, spec.example
    );
    let g = parse_graph(Path::new("example"), &doc)
        .unwrap_or_else(|e| panic!("{}: example does not parse: {e}", spec.name));
    let decl = &g.nodes[0];
    let list = |param: &str| -> Vec<String> {
        match decl.params.iter().find(|p| p.name == param).map(|p| &p.value) {
            Some(Value::TextList(v)) => v.clone(),
            _ => Vec::new(),
        }
    };
    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    for (k, p) in spec.ports.iter().enumerate() {
        let names = match p.multi {
            Some(l) => list(l),
            None => vec![p.name.to_string()],
        };
        for (j, n) in names.into_iter().enumerate() {
            match p.dir {
                evflow_engine::Direction::In => inputs.push((n, signal(TICKS as usize, (k * 31 + j) as u64))),
                evflow_engine::Direction::Out => outputs.push(n),
            }
        }
    }
    Case { inputs, outputs }
}

fn single<'a>(spec: &'static NodeSpec, c: &'a Case, dir: &'a Path, block: usize) -> Single<'a> {
    Single {
        spec,
        params: spec.example,
        inputs: c.inputs.iter().map(|(n, v)| (n.as_str(), v.clone(), 1000.0)).collect(),
        outputs: c.outputs.iter().map(String::as_str).collect(),
        base_rate: 1000.0,
        ticks: TICKS,
        block,
        base_dir: dir,
    }
}

/// Hardware outputs (`serial.out`) cannot run alone: the loader refuses
/// them unless a `limit` feeds them. They have no outputs to compare; their
/// own tests run them behind a limiter.
fn runs_alone(spec: &NodeSpec) -> bool {
    !spec.hardware
}

#[test]
fn every_declaration_is_complete() {
    for spec in evflow_nodes::all_specs() {
        assert!(!spec.summary.is_empty(), "{}: no summary", spec.name);
        assert!(spec.doc.len() > 40, "{}: the doc must explain the node", spec.name);
        assert!(!spec.example.is_empty() || spec.params.is_empty(), "{}: no example", spec.name);
        for p in spec.ports {
            assert!(!p.doc.is_empty() && !p.unit.is_empty(), "{}.{}: port needs a unit and a doc", spec.name, p.name);
        }
        for p in spec.params {
            assert!(!p.doc.is_empty(), "{}: parameter `{}` needs a doc", spec.name, p.name);
        }
    }
}

#[test]
fn block_processing_equals_per_sample_processing() {
    let dir = tempfile::tempdir().unwrap();
    fixtures(dir.path());
    for spec in evflow_nodes::all_specs().into_iter().filter(|s| runs_alone(s)) {
        let c = case(spec);
        let tick = single(spec, &c, dir.path(), 1).run().unwrap_or_else(|e| panic!("{}: {e}", spec.name));
        for block in [7, 4096] {
            let blk = single(spec, &c, dir.path(), block).run().unwrap_or_else(|e| panic!("{}: {e}", spec.name));
            assert_eq!(tick.len(), blk.len());
            for (k, (a, b)) in tick.iter().zip(&blk).enumerate() {
                assert_eq!(a.len(), b.len(), "{}: output {k} length differs (block {block})", spec.name);
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    assert!(
                        x.to_bits() == y.to_bits(),
                        "{}: output {k} sample {i}: tick {x} ≠ block({block}) {y}",
                        spec.name
                    );
                }
            }
        }
        for out in &tick {
            assert!(out.iter().all(|x| x.is_finite()), "{}: NaN or Inf in output", spec.name);
        }
    }
}

#[test]
fn reset_restores_the_initial_output() {
    let dir = tempfile::tempdir().unwrap();
    fixtures(dir.path());
    for spec in evflow_nodes::all_specs().into_iter().filter(|s| runs_alone(s)) {
        let c = case(spec);
        let s = single(spec, &c, dir.path(), 256);
        let (mut plan, idx) = s.plan().unwrap_or_else(|e| panic!("{}: {e}", spec.name));
        let first = s.collect(&mut plan, &idx).unwrap();
        plan.reset();
        let second = s.collect(&mut plan, &idx).unwrap();
        for (a, b) in first.iter().zip(&second) {
            assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{}: output after reset differs",
                spec.name
            );
        }
    }
}

#[test]
fn node_reference_is_current() {
    let want = evflow_engine::reference::reference_markdown(&evflow_nodes::registry());
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/nodes.md");
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        have == want,
        "docs/nodes.md is out of date: regenerate with `cargo run -p evflow -- nodes --markdown > docs/nodes.md`"
    );
}
