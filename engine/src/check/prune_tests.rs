//! The planner's constants: replacing, propagating, leaving out upstream
//! before it is built, live parameters, and output identical without.

use crate::check::check;
use crate::graph::parse_graph;
use crate::harness::{FEED, TAP};
use crate::node::{BuildContext, Constant, Io, Node, NodeError, RunMode};
use crate::params::Params;
use crate::plan::{Folding, Plan, PlanOptions};
use crate::ports::{InPort, OutPort};
use crate::registry::Registry;
use crate::spec::{FoldArgs, NodeSpec, ParamSpec, PortSpec, Role};
use std::path::Path;
use std::sync::Mutex;

/// Paths the `t.file` sources were built with (each test uses its own).
static OPENED: Mutex<Vec<String>> = Mutex::new(Vec::new());

fn opened(path: &str) -> bool {
    OPENED.lock().unwrap().iter().any(|p| p == path)
}

/// A source that reads its file when built (a `recording.in`): a missing
/// file is an error.
static FILE: NodeSpec = NodeSpec::new("t.file", "test", Role::Source, "reads a file when built", build_file)
    .ports(&[PortSpec::output("out", "1", "ramp")])
    .params(&[ParamSpec::text("path", "", "file")]);

struct Ramp(f64);
impl Node for Ramp {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for y in io.output(OutPort::at(0)) {
            self.0 += 0.25;
            *y = self.0;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.0 = 0.0;
    }
}

fn build_file(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    OPENED.lock().unwrap().push(p.str("path").to_string());
    let path = ctx.path(p.str("path"));
    if !path.exists() {
        return Err(NodeError::file(&path, "no such file"));
    }
    Ok(Box::new(Ramp(0.0)))
}

/// y = k·x, `k` live; folds when k = 0 or x is constant (the shared
/// sweeps' tests use it too).
pub(crate) static SCALE: NodeSpec = NodeSpec::new("t.scale", "test", Role::Filter, "y = k x", build_scale)
    .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", "1", "k x")])
    .params(&[ParamSpec::float("k", -10.0, 10.0, 1.0, "1", "factor").live()])
    .fold(fold_scale);

struct Scale(f64);
impl Node for Scale {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(InPort::at(0), OutPort::at(0));
        for (y, x) in y.iter_mut().zip(x) {
            *y = self.0 * x;
        }
        Ok(())
    }
    fn reset(&mut self) {}
    fn set(&mut self, c: crate::node::Change) -> Result<(), crate::node::Refused> {
        self.0 = c.value;
        Ok(())
    }
}

fn build_scale(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Scale(p.f64("k"))))
}

fn fold_scale(f: &FoldArgs<'_>) -> Option<Constant> {
    let k = f.f64("k")?;
    if k == 0.0 {
        return Some(Constant::all(1, 0.0, "k = 0"));
    }
    f.input(0).map(|x| Constant::all(1, k * x, format!("k × constant input {x}")))
}

/// a + b; folds when both are constant.
static SUM: NodeSpec = NodeSpec::new("t.sum", "test", Role::Filter, "a + b", build_sum)
    .ports(&[PortSpec::input("a", "1", "a"), PortSpec::input("b", "1", "b"), PortSpec::output("out", "1", "a + b")])
    .fold(|f| Some(Constant::all(1, f.input(0)? + f.input(1)?, "sum of constants")));

struct Sum;
impl Node for Sum {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            io.output(OutPort::at(0))[k] = io.input(InPort::at(0))[k] + io.input(InPort::at(1))[k];
        }
        Ok(())
    }
    fn reset(&mut self) {}
}

fn build_sum(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Sum))
}

/// Decides at build, from what it "loaded" (`flat`), that its output is
/// constant: as `mesh.edges` on a mesh without sharp edges. Two outputs.
static PROBE: NodeSpec = NodeSpec::new("t.probe", "test", Role::Filter, "constant when flat", build_probe)
    .ports(&[
        PortSpec::input("in", "1", "x"),
        PortSpec::output("out", "1", "x or 0"),
        PortSpec::output("angle", "deg", "180"),
    ])
    .params(&[
        ParamSpec::flag("flat", false, "loaded a flat scene"),
        ParamSpec::int("outputs", 0, 3, 2, "1", "declared"),
        ParamSpec::flag("vary_angle", false, "the angle output is not constant"),
    ]);

struct Probe {
    flat: bool,
    outputs: usize,
    vary_angle: bool,
}
impl Node for Probe {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            io.output(OutPort::at(0))[k] = if self.flat { 0.0 } else { io.input(InPort::at(0))[k] };
            io.output(OutPort::at(1))[k] = 180.0;
        }
        Ok(())
    }
    fn reset(&mut self) {}
    fn constant_output(&self) -> Option<Constant> {
        let angle = (!self.vary_angle).then_some(180.0);
        self.flat.then(|| Constant::new([Some(0.0), angle, Some(7.0)][..self.outputs].to_vec(), "flat scene"))
    }
    fn notes(&self) -> Vec<String> {
        vec![format!("flat: {}", self.flat)]
    }
}

fn build_probe(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Probe { flat: p.bool("flat"), outputs: p.usize("outputs"), vary_angle: p.bool("vary_angle") }))
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add(&FEED).add(&TAP).add(&FILE).add(&SCALE).add(&SUM).add(&PROBE);
    r
}

fn checked(text: &str) -> crate::check::Checked {
    let doc = format!("[graph]\nformat = 1\nname = \"p\"\nrate = 1000\nduration = 0.02\n{text}");
    check(&parse_graph(Path::new("p.toml"), &doc).unwrap(), &registry(), &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn opts(block: usize) -> PlanOptions {
    PlanOptions { max_block: block, timing: false, ..PlanOptions::default() }
}

/// `ticks` ticks of output `node.port 0`, in blocks of `block`.
fn run(plan: &mut Plan, node: &str, ticks: usize) -> Vec<f64> {
    let mut out = Vec::new();
    while out.len() < ticks {
        let n = plan.max_block().min(ticks - out.len());
        plan.step(n).unwrap();
        out.extend_from_slice(plan.output(node, 0).unwrap());
    }
    out
}

const GAIN_ZERO: &str = r#"connections = ["rec.out -> g.in", "g.out -> s.a", "feed.out -> s.b", "s.out -> tap.in"]
[nodes.rec]
type = "t.file"
path = "missing-gain-zero.wav"
[nodes.g]
type = "t.scale"
k = 0.0
[nodes.feed]
type = "harness.feed"
values = [1.0, 2.0, 3.0, 4.0, 5.0]
[nodes.s]
type = "t.sum"
[nodes.tap]
type = "harness.tap"
"#;

#[test]
fn a_zero_gain_is_a_constant_and_its_missing_file_is_never_opened() {
    let c = checked(GAIN_ZERO);
    let mut plan = Plan::build(&c, &opts(3)).unwrap_or_else(|e| panic!("{e}"));
    assert!(!opened("missing-gain-zero.wav"));
    let folded = plan.folded();
    assert_eq!(folded.len(), 1, "{folded:?}");
    assert_eq!((folded[0].node.as_str(), folded[0].outputs.clone()), ("g", vec![("out".to_string(), Some(0.0))]));
    assert_eq!(folded[0].reason, "k = 0");
    assert_eq!(plan.pruned().len(), 1);
    assert_eq!(plan.pruned()[0].node, "rec");
    assert_eq!(plan.pruned()[0].reason, "feeds only `g`, which is replaced by a constant");
    // The constant holds in the plan; the sum reads it.
    assert_eq!(run(&mut plan, "s", 5), vec![1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!(plan.output("g", 0).unwrap(), &[0.0; 2][..]);
    // Reset keeps it.
    plan.reset();
    assert_eq!(run(&mut plan, "s", 5), vec![1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!(plan.schedule().iter().map(|s| s.0.as_str()).collect::<Vec<_>>(), ["feed", "g", "s", "tap"]);
    // Without folding the file must be opened, and is missing.
    let e = Plan::build_with(&c, &opts(3), Folding::Off).err().unwrap().to_string();
    assert!(e.contains("node `rec`") && e.contains("missing-gain-zero.wav: no such file"), "{e}");
}

#[test]
fn constants_propagate_through_the_nodes_that_fold_them() {
    // 0 · ramp = 0 → 3·0 = 0 → 0 + 0.5·4 = 2: the whole chain is one constant.
    let text = r#"connections = ["rec.out -> z.in", "z.out -> three.in", "three.out -> s.a", "four.out -> half.in", "half.out -> s.b", "s.out -> tap.in", "rec.out -> tap2.in"]
[nodes.rec]
type = "t.file"
path = "Cargo.toml"
[nodes.z]
type = "t.scale"
k = 0.0
[nodes.three]
type = "t.scale"
k = 3.0
[nodes.four]
type = "t.probe"
flat = true
outputs = 2
[nodes.half]
type = "t.scale"
k = 0.5
[nodes.s]
type = "t.sum"
[nodes.tap]
type = "harness.tap"
[nodes.tap2]
type = "harness.tap"
"#;
    // `four` is a probe with an input: feed it from a file nobody else reads.
    let text = text.replace("\"four.out -> half.in\"", "\"four.out -> half.in\", \"rec2.out -> four.in\"")
        + "[nodes.rec2]\ntype = \"t.file\"\npath = \"missing-behind-probe.wav\"\n";
    let c = checked(&text);
    let mut plan = Plan::build(&c, &opts(4)).unwrap_or_else(|e| panic!("{e}"));
    // The whole chain collapses into the sum: only it stays, as a constant.
    let folded: Vec<(&str, Option<f64>)> = plan.folded().iter().map(|f| (f.node.as_str(), f.outputs[0].1)).collect();
    assert_eq!(folded, [("s", Some(0.0))]);
    assert_eq!(plan.folded()[0].reason, "sum of constants");
    let mut pruned: Vec<(&str, &str)> = plan.pruned().iter().map(|p| (p.node.as_str(), p.reason.as_str())).collect();
    pruned.sort_unstable();
    let only_s = "feeds only `s`, which is replaced by a constant";
    assert_eq!(pruned, [("four", only_s), ("half", only_s), ("rec2", only_s), ("three", only_s), ("z", only_s)]);
    // The probe decided when built, before what fed only it was built.
    assert!(!opened("missing-behind-probe.wav"));
    // Notes are kept for the nodes in the plan only.
    assert!(plan.notes().is_empty());
    assert!(run(&mut plan, "s", 9).iter().all(|&v| v == 0.0));
    // `rec` still feeds a sink, so it stays.
    assert!(plan.index("rec").is_some());
}

#[test]
fn a_probe_that_is_not_flat_stays_and_its_upstream_is_built() {
    let text = r#"connections = ["rec.out -> p.in", "p.out -> tap.in"]
[nodes.rec]
type = "t.file"
path = "Cargo.toml"
[nodes.p]
type = "t.probe"
"#
    .to_string()
        + "[nodes.tap]\ntype = \"harness.tap\"\n";
    let c = checked(&text);
    let mut plan = Plan::build(&c, &opts(2)).unwrap();
    assert!(plan.folded().is_empty() && plan.pruned().is_empty());
    assert_eq!(plan.notes(), &[("p".to_string(), vec!["flat: false".to_string()])]);
    assert_eq!(run(&mut plan, "p", 4), vec![0.25, 0.5, 0.75, 1.0]);
}

#[test]
fn live_plans_never_fold_on_a_live_parameter_but_fold_what_was_loaded() {
    let text = GAIN_ZERO.replace("missing-gain-zero.wav", "Cargo.toml");
    let c = checked(&text);
    for (mode, folding) in [(RunMode::Live, Folding::On), (RunMode::Offline, Folding::Changes)] {
        let o = PlanOptions { mode, ..opts(1) };
        let mut plan = Plan::build_with(&c, &o, folding).unwrap();
        assert!(plan.folded().is_empty(), "{:?}", plan.folded());
        // k changes live: 0 → 2 at tick 2.
        let g = plan.index("g").unwrap();
        let mut out = Vec::new();
        for t in 0..4 {
            if t == 2 {
                plan.set(g, "k", 2.0).unwrap();
            }
            plan.step(1).unwrap();
            out.push(plan.output("s", 0).unwrap()[0]);
        }
        assert_eq!(out, vec![1.0, 2.0, 3.0 + 2.0 * 0.75, 4.0 + 2.0 * 1.0]);
    }
    // A constant decided by what a node loaded holds for every live value:
    // a live change to it is taken, and changes nothing.
    let text = "connections = [\"feed.out -> p.in\", \"p.out -> tap.in\"]\n[nodes.feed]\ntype = \"harness.feed\"\nvalues = [1.0]\n[nodes.p]\ntype = \"t.probe\"\nflat = true\n[nodes.tap]\ntype = \"harness.tap\"\n";
    let c = checked(text);
    let mut plan = Plan::build(&c, &PlanOptions { mode: RunMode::Live, ..opts(1) }).unwrap();
    let p = plan.index("p").unwrap();
    assert!(plan.set(p, "flat", 0.0).is_ok());
    plan.step(1).unwrap();
    assert_eq!(plan.output_at(p, 1), &[180.0]);
    // Offline (settled), the stand-in refuses changes: none were expected.
    let mut plan = Plan::build(&c, &opts(1)).unwrap();
    assert!(plan.set(p, "flat", 0.0).is_err());
}

#[test]
fn output_is_identical_with_and_without_folding() {
    let text = GAIN_ZERO.replace("missing-gain-zero.wav", "Cargo.toml");
    let c = checked(&text);
    for block in [1, 2, 5] {
        let mut on = Plan::build(&c, &opts(block)).unwrap();
        let mut off = Plan::build_with(&c, &opts(block), Folding::Off).unwrap();
        assert_eq!(on.folded().len(), 1);
        assert!(off.folded().is_empty() && off.index("rec").is_some());
        assert_eq!(run(&mut on, "s", 5), run(&mut off, "s", 5));
    }
}

#[test]
fn a_constant_of_the_wrong_shape_is_an_error_of_its_node() {
    for (outputs, says) in [(1, "declared 1 constant outputs for its 2 output ports"), (3, "declared 3")] {
        let text = format!("connections = [\"feed.out -> p.in\", \"p.out -> tap.in\"]\n[nodes.feed]\ntype = \"harness.feed\"\nvalues = [1.0]\n[nodes.p]\ntype = \"t.probe\"\nflat = true\noutputs = {outputs}\n[nodes.tap]\ntype = \"harness.tap\"\n");
        let e = Plan::build(&checked(&text), &opts(1)).err().unwrap().to_string();
        assert!(e.contains("node `p`") && e.contains(says), "{e}");
    }
}

#[test]
fn an_output_that_varies_keeps_the_node_only_when_something_reads_it() {
    let base = "[nodes.feed]\ntype = \"harness.feed\"\nvalues = [1.0]\n[nodes.p]\ntype = \"t.probe\"\nflat = true\nvary_angle = true\n[nodes.tap]\ntype = \"harness.tap\"\n[nodes.tap2]\ntype = \"harness.tap\"\n";
    // `angle` read by nobody: the node is replaced, `angle` is dropped.
    let text = format!("connections = [\"feed.out -> p.in\", \"p.out -> tap.in\", \"feed.out -> tap2.in\"]\n{base}");
    let plan = Plan::build(&checked(&text), &opts(1)).unwrap();
    assert_eq!(plan.folded()[0].outputs, [("out".to_string(), Some(0.0)), ("angle".to_string(), None)]);
    let p = plan.index("p").unwrap();
    assert!(!plan.output_dropped(p, 0) && plan.output_dropped(p, 1));
    // `angle` read by a sink: the node stays.
    let text = format!("connections = [\"feed.out -> p.in\", \"p.out -> tap.in\", \"p.angle -> tap2.in\"]\n{base}");
    let plan = Plan::build(&checked(&text), &opts(1)).unwrap();
    assert!(plan.folded().is_empty());
}

/// Builds and drops of the `t.loads` nodes, in order ("build NAME", "drop NAME").
static LOADS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// A node that "loads" something at build and lets it go when dropped;
/// constant when `flat` (as `mesh.edges` on smooth scenes, whose scenes
/// `mesh.gradient` shares).
static LOADS_SPEC: NodeSpec = NodeSpec::new("t.loads", "test", Role::Filter, "logs its build and drop", build_loads)
    .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", "1", "x or 0")])
    .params(&[ParamSpec::flag("flat", false, "constant 0")]);

struct Loads {
    name: String,
    flat: bool,
}
impl Node for Loads {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            io.output(OutPort::at(0))[k] = io.input(InPort::at(0))[k];
        }
        Ok(())
    }
    fn reset(&mut self) {}
    fn constant_output(&self) -> Option<Constant> {
        self.flat.then(|| Constant::all(1, 0.0, "flat"))
    }
}
impl Drop for Loads {
    fn drop(&mut self) {
        LOADS.lock().unwrap().push(format!("drop {}", self.name));
    }
}

fn build_loads(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    LOADS.lock().unwrap().push(format!("build {}", ctx.node));
    Ok(Box::new(Loads { name: ctx.node.clone(), flat: p.bool("flat") }))
}

#[test]
fn a_node_folded_into_a_constant_lives_until_every_node_is_built() {
    // `flat` is built before `x` and `y` (downstream first: both feed `s1`,
    // which is built before them) and folded; it is dropped only after them,
    // so what they share with it is loaded once.
    let text = r#"connections = ["feed.out -> flat.in", "feed.out -> x.in", "feed.out -> y.in", "flat.out -> s1.a", "x.out -> s1.b", "s1.out -> s2.a", "y.out -> s2.b", "s2.out -> tap.in"]
[nodes.feed]
type = "harness.feed"
values = [1.0, 2.0]
[nodes.flat]
type = "t.loads"
flat = true
[nodes.x]
type = "t.loads"
[nodes.y]
type = "t.loads"
[nodes.s1]
type = "t.sum"
[nodes.s2]
type = "t.sum"
[nodes.tap]
type = "harness.tap"
"#;
    let mut r = registry();
    r.add(&LOADS_SPEC);
    let doc = format!("[graph]\nformat = 1\nname = \"p\"\nrate = 1000\nduration = 0.02\n{text}");
    let c = check(&parse_graph(Path::new("p.toml"), &doc).unwrap(), &r, &[]).unwrap_or_else(|e| panic!("{e}"));
    let mut plan = Plan::build(&c, &opts(2)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plan.folded().len(), 1);
    let log = LOADS.lock().unwrap().clone();
    let at = |what: &str| log.iter().position(|l| l == what).unwrap_or_else(|| panic!("no `{what}` in {log:?}"));
    // The test means something only if a node is built after `flat`.
    let last_build = at("build x").max(at("build y"));
    assert!(at("build flat") < last_build, "{log:?}");
    assert!(at("drop flat") > last_build, "{log:?}");
    // The others live on in the plan, which runs.
    assert!(!log.iter().any(|l| l == "drop x" || l == "drop y"), "{log:?}");
    assert_eq!(run(&mut plan, "s2", 2), vec![2.0, 4.0]);
}
