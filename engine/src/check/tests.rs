//! Validation tests: every class of error names file, line and node; pruning;
//! rates; round trip. Uses small test-only node types.

use super::*;
use crate::graph::parse_graph;
use crate::harness::{FEED, TAP};
use crate::node::{BuildContext, Io, Node, NodeError};
use crate::plan::{Plan, PlanOptions};
use crate::ports::{InPort, OutPort};
use crate::spec::{ParamSpec, PortSpec, Role};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

static BUILT: AtomicUsize = AtomicUsize::new(0);

struct Pass;
impl Node for Pass {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(InPort::at(0), OutPort::at(0));
        y.copy_from_slice(x);
        Ok(())
    }
    fn reset(&mut self) {}
}

fn build_pass(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    BUILT.fetch_add(1, Ordering::SeqCst);
    Ok(Box::new(Pass))
}

static FILTER: NodeSpec = NodeSpec::new("filt", "test", Role::Filter, "pass-through", build_pass)
    .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", "1", "x")])
    .params(&[
        ParamSpec::float("cutoff", 0.001, 1000.0, 10.0, "Hz", "a cut-off"),
        ParamSpec::int("order", 1, 8, 4, "1", "an order"),
        ParamSpec::choice("kind", &["lowpass", "highpass"], "lowpass", "a kind"),
        ParamSpec::float("need", 0.0, 1.0, 0.0, "1", "a required value").required(),
    ]);

static SLOW: NodeSpec =
    NodeSpec::new("slow", "test", Role::Source, "a source at its own rate", crate::harness::FEED.build)
        .ports(&[PortSpec::output("out", "1", "x")])
        .params(&[
            ParamSpec::float_list("values", f64::NEG_INFINITY, f64::INFINITY, "1", "samples"),
            ParamSpec::float("rate", 1.0, 1e5, 40.0, "Hz", "rate"),
        ])
        .rate_param("rate");

static MIX: NodeSpec = NodeSpec::new("mix", "test", Role::Filter, "two inputs at one rate", build_pass).ports(&[
    PortSpec::input("a", "1", "x"),
    PortSpec::input("b", "1", "y"),
    PortSpec::output("out", "1", "x"),
]);

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add(&FILTER).add(&FEED).add(&TAP).add(&SLOW).add(&MIX);
    r
}

const GOOD: &str = r#"[graph]
format = 1
name = "test"
rate = 1000
connections = [
  "src.out -> f.in",
  "f.out -> sink.in",
]

[vars]
cut = 20.0

[nodes.src]
type = "harness.feed"
values = [1.0, 2.0, 3.0, 4.0]

[nodes.f]
type = "filt"
cutoff = "$cut"
need = 0.5

[nodes.sink]
type = "harness.tap"
"#;

fn errors(text: &str) -> Vec<Diagnostic> {
    let file = Path::new("g.toml");
    match parse_graph(file, text) {
        Err(d) => d.0,
        Ok(g) => match check(&g, &registry(), &[]) {
            Err(d) => d.0,
            Ok(_) => Vec::new(),
        },
    }
}

fn one_error(text: &str) -> Diagnostic {
    let e = errors(text);
    assert_eq!(e.len(), 1, "expected one error, got {e:#?}");
    e.into_iter().next().unwrap()
}

#[test]
fn a_type_this_build_left_out_names_its_feature() {
    let text = GOOD.replace("type = \"filt\"", "type = \"sim.display\"");
    let g = parse_graph(Path::new("g.toml"), &text).unwrap();
    let mut reg = registry();
    reg.add_absent("sim.display", "lab");
    let d = check(&g, &reg, &[]).unwrap_err().0;
    assert_eq!(d.len(), 1, "{d:#?}");
    assert!(d[0].message.contains("node type `sim.display` is not in this build"), "{}", d[0]);
    assert!(d[0].help.as_deref().unwrap().contains("cargo feature `lab`"), "{}", d[0]);
    assert_eq!(d[0].loc.line, 18);
}

#[test]
fn good_graph_checks() {
    assert!(errors(GOOD).is_empty());
}

#[test]
fn unknown_type_suggests_closest() {
    let d = one_error(&GOOD.replace("type = \"filt\"", "type = \"flit\""));
    assert_eq!(d.node.as_deref(), Some("f"));
    assert_eq!(d.loc.line, 18);
    assert!(d.message.contains("unknown node type `flit`"), "{d}");
    assert_eq!(d.help.as_deref(), Some("did you mean `filt`?"));
    assert!(d.to_string().starts_with("g.toml:18:1: node `f`:"), "{d}");
}

#[test]
fn unknown_parameter_suggests_closest() {
    let d = one_error(&GOOD.replace("need = 0.5", "need = 0.5\ncutof = 3.0"));
    assert!(d.message.contains("no parameter `cutof`"), "{d}");
    assert_eq!(d.help.as_deref(), Some("did you mean `cutoff`?"));
    assert_eq!(d.loc.line, 21);
}

#[test]
fn unknown_port_suggests_closest() {
    let d = one_error(&GOOD.replace("\"f.out -> sink.in\"", "\"f.outt -> sink.in\""));
    assert!(d.message.contains("no output port `outt`"), "{d}");
    assert_eq!(d.help.as_deref(), Some("did you mean `out`?"));
    assert_eq!(d.loc.line, 7);
}

#[test]
fn unknown_node_in_connection() {
    let e = errors(&GOOD.replace("\"f.out -> sink.in\"", "\"f.out -> snk.in\""));
    let d = e.iter().find(|d| d.message.contains("unknown node `snk`")).expect("reported");
    assert_eq!(d.help.as_deref(), Some("did you mean `sink`?"));
    assert_eq!(d.loc.line, 7);
}

#[test]
fn an_empty_type_is_an_error_not_a_panic() {
    // Found by tests/fuzz_loader.rs: `type = ""` once passed parsing
    // silently and left a node without a type for validation.
    let d = one_error(&GOOD.replacen("type = \"filt\"", "type = \"\"", 1));
    assert!(d.message.contains("`type` is empty"), "{d}");
    assert_eq!(d.node.as_deref(), Some("f"));
}

#[test]
fn missing_required_parameter() {
    let d = one_error(&GOOD.replace("need = 0.5\n", ""));
    assert!(d.message.contains("missing required parameter `need`"), "{d}");
    assert_eq!(d.node.as_deref(), Some("f"));
}

#[test]
fn value_outside_limits_names_limits() {
    let d = one_error(&GOOD.replace("need = 0.5", "need = 1.5"));
    assert!(d.message.contains("1.5 is outside its limits"), "{d}");
    assert!(d.help.as_deref().unwrap().contains("0 ..= 1"), "{d}");
    let d = one_error(&GOOD.replace("need = 0.5", "need = 0.5\norder = 2.5"));
    assert!(d.message.contains("expected an integer"), "{d}");
    let d = one_error(&GOOD.replace("need = 0.5", "need = 0.5\nkind = \"hihgpass\""));
    assert!(d.message.contains("did you mean `highpass`"), "{d}");
    let d = one_error(&GOOD.replace("need = 0.5", "need = nan"));
    assert!(d.message.contains("NaN"), "{d}");
}

#[test]
fn input_without_producer_and_with_two() {
    let d = one_error(&GOOD.replace("  \"src.out -> f.in\",\n", ""));
    assert!(d.message.contains("input `f.in` has no producer"), "{d}");
    let two = GOOD.replace("  \"src.out -> f.in\",\n", "  \"src.out -> f.in\",\n  \"src.out -> f.in\",\n");
    let d = one_error(&two);
    assert!(d.message.contains("two producers"), "{d}");
    assert_eq!(d.loc.line, 7);
}

#[test]
fn direction_confusion_is_explained() {
    let e = errors(&GOOD.replace("\"src.out -> f.in\"", "\"f.in -> src.out\""));
    assert!(e.iter().any(|d| d.message.contains("`f.in` is an input, not an output")), "{e:#?}");
    assert!(e.iter().any(|d| d.message.contains("`src.out` is an output, not an input")), "{e:#?}");
}

#[test]
fn cycle_without_delay_is_refused() {
    let text = GOOD.replace("\"src.out -> f.in\",", "\"g.out -> f.in\",\n  \"f.out -> g.in\",")
        + "\n[nodes.g]\ntype = \"filt\"\nneed = 0.1\n";
    let e = errors(&text);
    assert!(e.iter().any(|d| d.message.contains("not broken by a `delay`")), "{e:#?}");
}

/// Errors of every stage in one check: a misspelt parameter and a wrong
/// port (nodes and connections) beside a rate that does not fit and a rate
/// mismatch (topology) — reported together, and nothing the first two
/// cause (issue 37, point 13).
#[test]
fn one_check_reports_the_rate_errors_beside_the_others() {
    let text = r#"[graph]
format = 1
name = "all"
rate = 1000
connections = ["a.out -> tap.in", "b.out -> f.in", "f.out -> tap2.in", "c.outt -> tap3.in", "s.out -> m.a", "fast.out -> m.b", "m.out -> tap4.in"]
[nodes.a]
type = "slow"
rate = 333
[nodes.b]
type = "slow"
[nodes.f]
type = "filt"
need = 0
cutof = 3
[nodes.c]
type = "harness.feed"
[nodes.s]
type = "slow"
[nodes.fast]
type = "harness.feed"
[nodes.m]
type = "mix"
[nodes.tap]
type = "harness.tap"
[nodes.tap2]
type = "harness.tap"
[nodes.tap3]
type = "harness.tap"
[nodes.tap4]
type = "harness.tap"
"#;
    let e = errors(text);
    let has = |s: &str| e.iter().filter(|d| d.message.contains(s)).count();
    assert_eq!(has("cutof"), 1, "{e:#?}");
    assert_eq!(has("outt"), 1, "{e:#?}");
    assert_eq!(has("333 Hz"), 1, "{e:#?}");
    assert_eq!(has("rate mismatch: `fast.out` runs at 1000 Hz but `m.b` at 40 Hz"), 1, "{e:#?}");
    // Nothing about `f`'s or `tap3`'s rates: their errors come first.
    assert_eq!(e.len(), 4, "{e:#?}");
}

#[test]
fn rate_mismatch_is_refused_with_a_hint() {
    let text = r#"[graph]
format = 1
name = "rates"
rate = 1000
connections = ["a.out -> tap.in", "b.out -> f.in", "f.out -> tap2.in", "a.out -> f2.in", "f2.out -> tap3.in"]
[nodes.a]
type = "slow"
rate = 333
[nodes.b]
type = "slow"
[nodes.f]
type = "filt"
need = 0
[nodes.f2]
type = "filt"
need = 0
[nodes.tap]
type = "harness.tap"
[nodes.tap2]
type = "harness.tap"
[nodes.tap3]
type = "harness.tap"
"#;
    let e = errors(text);
    assert!(e.iter().any(|d| d.message.contains("333 Hz") && d.message.contains("not an integer")), "{e:#?}");
    // At the line of `rate = 333` (line 8), with the nearest rates that fit.
    let d = e.iter().find(|d| d.message.contains("333 Hz")).unwrap();
    assert_eq!(d.loc.line, 8, "{d}");
    let help = d.help.as_deref().unwrap_or_default();
    assert!(help.contains("250 Hz (1000 Hz ÷ 4)") && help.contains("(1000 Hz ÷ 3)"), "{help}");
    let text = r#"[graph]
format = 1
name = "rates"
rate = 1000
connections = ["slow.out -> m.a", "fast.out -> m.b", "m.out -> tap.in"]
[nodes.slow]
type = "slow"
[nodes.fast]
type = "harness.feed"
[nodes.m]
type = "mix"
[nodes.tap]
type = "harness.tap"
"#;
    let d = one_error(text);
    assert!(d.message.contains("rate mismatch: `fast.out` runs at 1000 Hz but `m.b` at 40 Hz"), "{d}");
    assert_eq!(d.loc.line, 5);
    // 1000 Hz into 40 Hz: an integer step down, with the lines to paste.
    let help = d.help.unwrap();
    for want in [
        "insert a `decimate` node (an integer step down, 1000 Hz ÷ 25",
        "[nodes.fast_40hz]\n      type = \"decimate\"\n      rate = 40.0\n",
        "replace \"fast.out -> m.b\" with\n      \"fast.out -> fast_40hz.in\",\n      \"fast_40hz.out -> m.b\",",
    ] {
        assert!(help.contains(want), "{want}\n---\n{help}");
    }
}

/// The rate node each step needs: `hold` for a slow control stream going
/// up, `resample` for a ratio that is not an integer, a fresh node name
/// when the natural one is taken.
#[test]
fn rate_mismatch_suggests_the_node_that_fits() {
    let graph = |slow: f64, other: f64| {
        format!(
            "[graph]\nformat = 1\nname = \"rates\"\nrate = 1000\n\
             connections = [\"other.out -> m.a\", \"slow.out -> m.b\", \"m.out -> tap.in\"]\n\
             [nodes.slow]\ntype = \"slow\"\nrate = {slow:?}\n[nodes.other]\ntype = \"slow\"\nrate = {other:?}\n\
             [nodes.m]\ntype = \"mix\"\n[nodes.tap]\ntype = \"harness.tap\"\n\
             [nodes.slow_1000hz]\ntype = \"slow\"\n"
        )
    };
    let help = |slow, other| one_error(&graph(slow, other)).help.unwrap();
    let h = help(40.0, 1000.0);
    assert!(h.contains("insert a `hold` node (the 40 Hz stream is slower than the 1000 Hz base clock"), "{h}");
    assert!(h.contains("[nodes.slow_1000hz_2]\n      type = \"hold\"\n      rate = 1000.0\n"), "{h}");
    let h = help(40.0, 100.0);
    assert!(h.contains("insert a `resample` node (40 Hz up to 100 Hz, interpolated"), "{h}");
    assert!(h.contains("type = \"resample\"\n      rate = 100.0\n      quality = \"balanced\"\n"), "{h}");
    let h = help(250.0, 100.0);
    assert!(h.contains("insert a `resample` node (a step down by 2.5000, not a whole number"), "{h}");
    let h = help(1000.0, 40.0);
    assert!(h.contains("insert a `decimate` node") && h.contains("\"slow_40hz.out -> m.b\""), "{h}");
}

#[test]
fn newer_format_is_refused() {
    let d = one_error(&GOOD.replace("format = 1", "format = 7"));
    assert!(d.message.contains("format 7, newer than this evflow reads"), "{d}");
    assert_eq!(d.loc.line, 2);
}

#[test]
fn syntax_error_names_line() {
    let d = one_error("[graph]\nformat = 1\nname = \"x\nrate = 1000\n");
    assert!(d.message.contains("not valid TOML"), "{d}");
    assert_eq!(d.loc.line, 3);
}

#[test]
fn several_errors_are_all_reported() {
    let text = GOOD
        .replace("need = 0.5", "need = 2.0\nbogus = 1")
        .replace("type = \"harness.tap\"", "type = \"harness.tapp\"");
    assert!(errors(&text).len() >= 3);
}

#[test]
fn unknown_variable_and_override() {
    let d = one_error(&GOOD.replace("\"$cut\"", "\"$cutt\""));
    assert!(d.message.contains("undeclared variable `$cutt`"), "{d}");
    assert_eq!(d.help.as_deref(), Some("did you mean `cut`?"));
    let g = parse_graph(Path::new("g.toml"), GOOD).unwrap();
    let c = check(&g, &registry(), &[Override::parse("cut=30").unwrap()]).unwrap();
    assert_eq!(c.nodes[1].params.f64("cutoff"), 30.0);
    let c = check(&g, &registry(), &[Override::parse("f.order=2").unwrap()]).unwrap();
    assert_eq!(c.nodes[1].params.i64("order"), 2);
    let e = check(&g, &registry(), &[Override::parse("cutt=30").unwrap()]).unwrap_err();
    assert!(e.0[0].message.contains("no graph variable `cutt`"));
    let e = check(&g, &registry(), &[Override::parse("cut=5000").unwrap()]).unwrap_err();
    assert!(e.0[0].message.contains("outside its limits"), "{e}");
}

#[test]
fn load_save_load_round_trips() {
    let g = parse_graph(Path::new("g.toml"), GOOD).unwrap();
    let text = g.to_toml();
    let g2 = parse_graph(Path::new("g.toml"), &text).unwrap();
    assert_eq!(g.without_locations(), g2.without_locations());
    assert_eq!(g2.to_toml(), text);
}

#[test]
fn pruned_nodes_are_never_constructed() {
    let text = GOOD.replace("\"f.out -> sink.in\",", "\"f.out -> sink.in\",\n  \"src.out -> lonely.in\",")
        + "\n[nodes.lonely]\ntype = \"filt\"\nneed = 0.2\n";
    let g = parse_graph(Path::new("g.toml"), &text).unwrap();
    let c = check(&g, &registry(), &[]).unwrap();
    assert_eq!(c.pruned.len(), 1);
    assert_eq!(c.pruned[0].node, "lonely");
    let before = BUILT.load(Ordering::SeqCst);
    let plan = Plan::build(&c, &PlanOptions::default()).unwrap();
    // Only `f` is a `filt` in the plan; `lonely` was never built.
    assert_eq!(BUILT.load(Ordering::SeqCst) - before, 1);
    assert_eq!(plan.schedule().len(), 3);
}

#[test]
fn no_sink_is_an_error() {
    let text = GOOD.replace("  \"f.out -> sink.in\",\n", "").replace("[nodes.sink]\ntype = \"harness.tap\"\n", "");
    let d = one_error(&text);
    assert!(d.message.contains("no sink"), "{d}");
}

#[test]
fn multirate_counts_follow_the_rates() {
    let text = r#"[graph]
format = 1
name = "mr"
rate = 1000
connections = ["slow.out -> tap.in"]
[nodes.slow]
type = "slow"
rate = 40
values = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]
[nodes.tap]
type = "harness.tap"
"#;
    let g = parse_graph(Path::new("g.toml"), text).unwrap();
    let c = check(&g, &registry(), &[]).unwrap();
    let mut plan = Plan::build(&c, &PlanOptions { max_block: 100, ..Default::default() }).unwrap();
    assert_eq!(plan.max_block(), 100);
    assert_eq!(plan.remaining_ticks(), Some(250));
    let mut seen = Vec::new();
    for _ in 0..250 {
        plan.tick().unwrap();
        seen.extend_from_slice(plan.output("slow", 0).unwrap());
    }
    assert_eq!(seen, (1..=10).map(f64::from).collect::<Vec<_>>());
}

const SWEPT: &str = r#"
[sweep]
cut = [10.0, 20.0]
"#;

#[test]
fn sweep_axes_must_name_declared_variables() {
    let text = GOOD.replace("[nodes.src]", &format!("{SWEPT}\n[nodes.src]"));
    assert!(errors(&text).is_empty(), "{:#?}", errors(&text));
    let d = one_error(&text.replace("cut = [10.0", "cutt = [10.0"));
    assert!(d.message.contains("no graph variable `cutt`"), "{}", d.message);
    assert_eq!(d.loc.line, 15);
    let d = one_error(&text.replace("cut = [10.0, 20.0]", "cut = 10.0"));
    assert!(d.message.contains("must be a list"), "{}", d.message);
    let d = one_error(&text.replace("cut = [10.0, 20.0]", "cut = []"));
    assert!(d.message.contains("no values"), "{}", d.message);
}

#[test]
fn sweep_round_trips() {
    let text = GOOD.replace("[nodes.src]", &format!("{SWEPT}\n[nodes.src]"));
    let g = parse_graph(Path::new("g.toml"), &text).unwrap();
    assert_eq!(g.sweep.len(), 1);
    let saved = g.to_toml();
    let g2 = parse_graph(Path::new("g.toml"), &saved).unwrap();
    assert_eq!(g.without_locations(), g2.without_locations());
}

#[test]
fn text_parameters_interpolate_variables() {
    let text = GOOD.replace("kind = ", "x = ").replace("need = 0.5", "need = 0.5\nkind = \"${mode}pass\"") + "";
    let text = text.replace("cut = 20.0", "cut = 20.0\nmode = \"high\"");
    let g = parse_graph(Path::new("g.toml"), &text).unwrap();
    let c = check(&g, &registry(), &[]).unwrap();
    assert_eq!(c.nodes[1].params.str("kind"), "highpass");
    let c = check(&g, &registry(), &[Override::parse("mode=low").unwrap()]).unwrap();
    assert_eq!(c.nodes[1].params.str("kind"), "lowpass");
    let d = one_error(&text.replace("${mode}", "${mood}"));
    assert!(d.message.contains("undeclared variable `${mood}`"), "{}", d.message);
    assert_eq!(d.node.as_deref(), Some("f"));
    assert!(d.help.unwrap_or_default().contains("mode"));
    let d = one_error(&text.replace("${mode}", "${mode"));
    assert!(d.message.contains("without its closing"), "{}", d.message);
}

const PLOTTED: &str = r#"
[[plot]]
file = "cut.png"
x = "cut"
y = ["sink.rms", "f.time"]
fit = "quadratic"
log_y = true
"#;

#[test]
fn plots_parse_check_and_round_trip() {
    let text = GOOD.replace("[nodes.src]", &format!("{PLOTTED}\n[nodes.src]"));
    let g = parse_graph(Path::new("g.toml"), &text).unwrap();
    assert_eq!(g.plots.len(), 1);
    assert_eq!(g.plots[0].y, ["sink.rms", "f.time"]);
    assert_eq!(g.plots[0].fit, crate::graph::Fit::Quadratic);
    assert!(check(&g, &registry(), &[]).is_ok());
    let saved = g.to_toml();
    let g2 = parse_graph(Path::new("g.toml"), &saved).unwrap();
    assert_eq!(g.without_locations(), g2.without_locations());

    let d = one_error(&text.replace("\"sink.rms\"", "\"snk.rms\""));
    assert!(d.message.contains("unknown quantity `snk.rms`"), "{}", d.message);
    assert!(d.help.unwrap_or_default().contains("sink"));
    let d = one_error(&text.replace("fit = \"quadratic\"", "fit = \"cubic\""));
    assert!(d.message.contains("not a known fit"), "{}", d.message);
    let d = one_error(&text.replace("cut.png", "cut.svg"));
    assert!(d.message.contains("must end in .png"), "{}", d.message);
    let d = one_error(&text.replace("x = \"cut\"\n", ""));
    assert!(d.message.contains("plot without `x`"), "{}", d.message);
    let d = one_error(&text.replace("log_y = true", "log_y = true\nseries = \"kind\""));
    assert!(d.message.contains("`series` names no graph variable"), "{}", d.message);
    let d = one_error(&text.replace("log_y = true", "logy = true"));
    assert!(d.message.contains("unknown plot key `logy`"), "{}", d.message);
}

/// A device sink and a guard of names the engine has never heard of: the
/// rule and its message come from the specs' roles, not from a node name.
static DEVICE: NodeSpec = NodeSpec::new("device", "test", Role::Sink, "drives hardware", build_pass)
    .ports(&[PortSpec::input("in", "1", "x")])
    .hardware();
static CLAMP: NodeSpec = NodeSpec::new("clamp", "test", Role::Filter, "a guard", build_pass)
    .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", "1", "x")])
    .safety_guard("enable");

#[test]
fn hardware_must_be_fed_by_a_guard_named_by_its_spec() {
    let mut reg = registry();
    reg.add(&DEVICE).add(&CLAMP);
    assert_eq!(reg.guard_words(), "`clamp`");
    let graph = |via: &str| {
        format!(
            "[graph]\nformat = 1\nname = \"t\"\nrate = 1000\nconnections = [\"src.out -> {via}.in\", \"{via}.out -> dev.in\"]\n\n\
             [nodes.src]\ntype = \"harness.feed\"\nvalues = [1.0]\n\n[nodes.{via}]\n{}\n\n[nodes.dev]\ntype = \"device\"\n",
            if via == "g" { "type = \"clamp\"" } else { "type = \"filt\"\nneed = 0.5" }
        )
    };
    let run = |text: &str| parse_graph(Path::new("g.toml"), text).map(|g| check(&g, &reg, &[]).map(|_| ()));
    assert!(matches!(run(&graph("g")), Ok(Ok(()))), "fed by the guard: accepted");
    let Ok(Err(d)) = run(&graph("f")) else { panic!("fed by a filter: refused") };
    let msg: Vec<String> = d.0.iter().map(|e| e.message.clone()).collect();
    assert!(msg.iter().any(|m| m == "hardware output `dev.in` is not fed by a `clamp` node"), "{msg:?}");
    assert_eq!(Registry::new().guard_words(), "safety-guard");
}
