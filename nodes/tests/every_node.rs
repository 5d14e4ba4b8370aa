//! Generic checks run on every node type of the library:
//! - its declaration is complete (doc, example, units and docs on every port
//!   and parameter; a cost cap within its parameter's limits, a bound on one
//!   of its outputs) and its example builds;
//! - block processing ≡ per-sample processing (the live tick), bit for bit;
//! - `reset` restores the initial output;
//! - no NaN or Inf leaves it on a random input.

use evflow_engine::graph::parse_graph;
use evflow_engine::harness::Single;
use evflow_engine::spec::ParamKind;
use evflow_engine::{Direction, NodeSpec, Value};
use evflow_nodes::example_files::signal;
use std::path::Path;

const TICKS: u64 = 3000;

/// Files the node examples read (a recording, a grid, models), written into `dir`.
fn fixtures(dir: &Path) {
    evflow_nodes::example_files::write(dir).expect("example files");
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
    Single::new(spec, spec.example)
        .inputs(c.inputs.iter().map(|(n, v)| (n.as_str(), v.clone(), 1000.0)))
        .outputs(c.outputs.iter().map(String::as_str))
        .ticks(TICKS)
        .block(block)
        .base_dir(dir)
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
            if let Some((cap, why)) = p.cost_cap {
                let numeric = matches!(p.kind, ParamKind::Float { .. } | ParamKind::Int { .. });
                assert!(numeric && !why.is_empty(), "{}: costly `{}` needs a number and a reason", spec.name, p.name);
                let (min, max) = match p.kind {
                    ParamKind::Float { min, max } => (min, max),
                    ParamKind::Int { min, max } => (min as f64, max as f64),
                    _ => unreachable!(),
                };
                assert!(
                    min <= cap && cap < max,
                    "{}: `{}`'s cost cap {cap} is not below its limits",
                    spec.name,
                    p.name
                );
            }
        }
        for p in spec.ports.iter().filter(|p| p.view) {
            assert!(p.multi.is_none(), "{}.{}: a repeated port is never shown by default", spec.name, p.name);
        }
        // A declared bound names an output of the type (any parameters, any input).
        if let Some((port, _, why)) = spec.output_bound(&|_| None, 1.0) {
            let out = spec.ports.iter().any(|p| p.dir == Direction::Out && p.name == port);
            assert!(out && !why.is_empty(), "{}: its bound's port `{port}` is not one of its outputs", spec.name);
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
