//! Shared sweeps: what is shared and what is copied, the merged run equal
//! to the separate runs, each point's report, and points that cannot merge.

use super::{copy_name, merge};
use crate::check::prune::tests::SCALE;
use crate::check::{check, Checked, Override};
use crate::graph::parse_graph;
use crate::harness::FEED;
use crate::node::{BuildContext, Io, Node, NodeError, Summary};
use crate::params::{Params, Value};
use crate::plan::{Plan, PlanOptions};
use crate::ports::InPort;
use crate::registry::Registry;
use crate::run::{run_offline, RunOptions, RunReport};
use crate::spec::{NodeSpec, PortSpec, Role};
use std::path::Path;

/// Sums its input; reports the sum and the name it was built under.
static TOTAL: NodeSpec =
    NodeSpec::new("t.total", "test", Role::Sink, "Σ x", build_total).ports(&[PortSpec::input("in", "1", "x")]);

struct Total(f64, String);
impl Node for Total {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        self.0 += io.input(InPort::at(0)).iter().sum::<f64>();
        Ok(())
    }
    fn reset(&mut self) {
        self.0 = 0.0;
    }
    fn finish(&mut self) -> Result<Summary, NodeError> {
        let mut s = Summary::default().value("total", self.0, "1");
        s.lines.push(format!("built as {}", self.1));
        Ok(s)
    }
}

fn build_total(_: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Total(0.0, ctx.node.clone())))
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add(&FEED).add(&SCALE).add(&TOTAL);
    r
}

/// feed → pre (k = 3, shared) → g (k = $gain) → post (k = 2) → sum;
/// feed → other (k = 5) → side: the other branch is shared too.
const GRAPH: &str = r#"[graph]
format = 1
name = "s"
rate = 1000
connections = ["feed.out -> pre.in", "pre.out -> g.in", "g.out -> post.in", "post.out -> sum.in",
               "feed.out -> other.in", "other.out -> side.in"]
[vars]
gain = 1.0
[nodes.feed]
type = "harness.feed"
values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
[nodes.pre]
type = "t.scale"
k = 3.0
[nodes.g]
type = "t.scale"
k = "$gain"
[nodes.post]
type = "t.scale"
k = 2.0
[nodes.sum]
type = "t.total"
[nodes.other]
type = "t.scale"
k = 5.0
[nodes.side]
type = "t.total"
"#;

fn at(gain: f64) -> Checked {
    let g = parse_graph(Path::new("s.toml"), GRAPH).unwrap();
    let o = [Override { key: "gain".into(), value: Value::Float(gain) }];
    check(&g, &registry(), &o).unwrap_or_else(|e| panic!("{e}"))
}

fn run(c: &Checked) -> RunReport {
    let mut plan = Plan::build(c, &PlanOptions { max_block: 3, ..PlanOptions::default() }).unwrap();
    run_offline(&mut plan, RunOptions::default()).unwrap()
}

const GAINS: [f64; 3] = [0.5, 1.0, -2.0];

#[test]
fn shares_what_no_point_changes_and_copies_the_rest() {
    let points: Vec<Checked> = GAINS.iter().map(|&g| at(g)).collect();
    let m = merge(&points).unwrap();
    assert_eq!(m.points(), 3);
    assert_eq!(m.copied().collect::<Vec<_>>(), ["g", "post", "sum"]);
    let names: Vec<&str> = m.checked.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(
        names,
        ["feed", "pre", "g@0", "g@1", "g@2", "post@0", "post@1", "post@2", "sum@0", "sum@1", "sum@2", "other", "side"]
    );
    // Each copy has its point's parameters and its original's build name.
    for (k, &gain) in GAINS.iter().enumerate() {
        let n = &m.checked.nodes[m.checked.index(&copy_name("g", k)).unwrap()];
        assert_eq!(n.params.f64("k"), gain);
        assert_eq!(n.origin, "g");
    }
    // Shared `pre` feeds every copy of `g`; each copy of `post` reads its own point's `g`.
    let c = &m.checked;
    let pre = c.index("pre").unwrap();
    let fed: Vec<&str> = c.edges.iter().filter(|e| e.from.0 == pre).map(|e| c.nodes[e.to.0].name.as_str()).collect();
    assert_eq!(fed, ["g@0", "g@1", "g@2"]);
    for k in 0..3 {
        let post = c.index(&copy_name("post", k)).unwrap();
        let e = c.edges.iter().find(|e| e.to.0 == post).unwrap();
        assert_eq!(c.nodes[e.from.0].name, copy_name("g", k));
    }
    assert_eq!(c.order.len(), 13, "every node runs");
}

#[test]
fn each_point_reports_what_its_own_run_reports() {
    let points: Vec<Checked> = GAINS.iter().map(|&g| at(g)).collect();
    let m = merge(&points).unwrap();
    let merged = run(&m.checked);
    for (k, c) in points.iter().enumerate() {
        let alone = run(c);
        let share = m.report(&merged, k);
        assert_eq!(share.ticks, alone.ticks);
        let pick = |r: &RunReport| r.summaries.iter().map(|(n, s)| (n.clone(), s.clone())).collect::<Vec<_>>();
        assert_eq!(pick(&share), pick(&alone), "point {k}");
        let times: Vec<String> = share.times.iter().map(|t| t.node.clone()).collect();
        let alone_times: Vec<String> = alone.times.iter().map(|t| t.node.clone()).collect();
        assert_eq!(times, alone_times, "point {k}: the same nodes, in run order");
    }
    // 3·2·gain·Σ(1..7) = 168·gain, bit for bit as a run of that gain alone.
    assert_eq!(m.report(&merged, 2).value("sum", "total"), Some(168.0 * -2.0));
    let one = m.report(&merged, 1);
    let lines = &one.summaries.iter().find(|(n, _)| n == "sum").unwrap().1.lines;
    assert_eq!(lines, &["built as sum"], "a copy is built under its original's name");
}

#[test]
fn a_sweep_that_changes_nothing_shares_everything() {
    let m = merge(&[at(1.0), at(1.0)]).unwrap();
    assert_eq!(m.copied().count(), 0);
    assert_eq!(m.checked.nodes.len(), 7);
    let r = run(&m.checked);
    assert_eq!(m.report(&r, 1).value("sum", "total"), Some(168.0));
}

#[test]
fn points_of_another_structure_are_refused_with_the_reason() {
    let mut other = at(2.0);
    other.graph.seed = 9;
    let e = merge(&[at(1.0), other]).unwrap_err();
    assert!(e.to_string().contains("point 1 differs from point 0 in its seed"), "{e}");
    let mut other = at(2.0);
    other.edges.pop();
    let e = merge(&[at(1.0), other]).unwrap_err();
    assert!(e.to_string().contains("its connections"), "{e}");
    assert!(merge(&[]).is_err());
}

#[test]
fn each_point_reads_what_was_left_out_of_its_own_copies() {
    let m = merge(&[at(1.0), at(2.0)]).unwrap();
    let r = RunReport {
        ticks: 0,
        base_rate: 1000.0,
        elapsed: std::time::Duration::ZERO,
        times: Vec::new(),
        summaries: Vec::new(),
        left_out: vec![
            "held constant `pre` (out = 0): k = 0".into(),
            "held constant `g@0` (out = 0): k = 0".into(),
            "left out `post@1`: feeds only `sum@1`".into(),
        ],
    };
    assert_eq!(
        m.report(&r, 0).left_out,
        ["held constant `pre` (out = 0): k = 0", "held constant `g` (out = 0): k = 0"]
    );
    assert_eq!(m.report(&r, 1).left_out, ["held constant `pre` (out = 0): k = 0", "left out `post`: feeds only `sum`"]);
}
