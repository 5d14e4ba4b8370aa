//! What the page is told once, when it connects: the graph (nodes,
//! connections, rates, what the plan left out and why), the tapped
//! streams, the live parameters with their declared limits, the graph
//! variables bound to them, and the safety limiters to watch.

use evflow_engine::live::{LivePlan, LiveVar, Tap, TapInfo};
use evflow_engine::params::Value as PValue;
use evflow_engine::spec::{ParamKind, ParamSpec};
use evflow_engine::{Checked, Direction};
use evflow_nodes::safety::limit;
use serde_json::{json, Value};

/// A safety limiter (`limit`) whose state the studio shows: from its
/// `state` output when tapped (always, in a live session: every output of
/// a guard is), else inferred from its input and output taps and its
/// `enable` changes (recordings made before `limit` had `state`).
#[derive(Debug, Clone)]
pub(crate) struct LimiterSpec {
    /// Node name.
    pub node: String,
    /// Plan index (events name nodes by it).
    pub index: u32,
    /// Its `amplitude` parameter: |in| above it is clamped.
    pub amplitude: f64,
    /// Tap carrying what feeds its `in`, if tapped.
    pub input: Option<usize>,
    /// Tap of its `out`, if tapped.
    pub output: Option<usize>,
    /// Tap of its `state` output (`evflow_nodes::safety::limit::State`
    /// codes), if tapped.
    pub state: Option<usize>,
    /// `enable` as the graph sets it.
    pub enabled: bool,
}

/// Everything the studio knows about the session it shows.
#[derive(Debug, Clone)]
pub struct Description {
    pub(crate) hello: Value,
    pub(crate) taps: Vec<TapInfo>,
    pub(crate) names: Vec<String>,
    pub(crate) limiters: Vec<LimiterSpec>,
    pub(crate) base_rate: f64,
}

/// Streams worth seeing by default on top of the sources and guards the
/// session records anyway: the ports each node type declares shown
/// ([`evflow_engine::PortSpec::view`]) — an output's samples (the
/// display's force, the mesh intensities, each limiter's `state`, which is
/// also a guard output and so normally tapped already, the live
/// synthesis' target beside what it expects to render and its running
/// counts), or for an input, the stream that feeds it (what reaches each
/// limiter, whose peak shows; the (load, velocity) point of each texture
/// interpolator). Only nodes the plan kept.
pub fn default_taps(checked: &Checked, plan: &evflow_engine::Plan) -> Vec<Tap> {
    wanted_taps(checked).into_iter().filter(|t| plan.index(&t.node).is_some()).collect()
}

fn wanted_taps(checked: &Checked) -> Vec<Tap> {
    let mut taps = Vec::new();
    let mut add = |node: &str, port: &str| {
        let t = Tap::new(node, port);
        if !taps.contains(&t) {
            taps.push(t);
        }
    };
    for n in &checked.nodes {
        for port in n.spec.viewed(Direction::Out) {
            add(&n.name, port);
        }
    }
    for e in &checked.edges {
        let to = &checked.nodes[e.to.0];
        let port = &to.ports[e.to.1].name;
        if to.spec.viewed(Direction::In).any(|p| p == port) {
            let from = &checked.nodes[e.from.0];
            add(&from.name, &from.ports[e.from.1].name);
        }
    }
    taps
}

/// Nodes (with rates, and whether the plan kept them), connections (with
/// rates) and what was left out and why.
pub(crate) fn graph_json(checked: &Checked, base: f64, in_plan: &dyn Fn(&str) -> bool) -> Value {
    let nodes: Vec<Value> = checked
        .nodes
        .iter()
        .map(|n| {
            json!({
                "name": n.name, "type": n.spec.name, "rate": n.ratio.hz(base), "in_plan": in_plan(&n.name),
                "guard": n.spec.is_guard(),
                "inputs": n.ports.iter().filter(|q| q.dir == Direction::In).map(|q| &q.name).collect::<Vec<_>>(),
                "outputs": n.ports.iter().filter(|q| q.dir == Direction::Out).map(|q| &q.name).collect::<Vec<_>>(),
            })
        })
        .collect();
    let edges: Vec<Value> = checked
        .edges
        .iter()
        .map(|e| {
            let (f, t) = (&checked.nodes[e.from.0], &checked.nodes[e.to.0]);
            let fp = &f.ports[e.from.1];
            json!({ "from": f.name, "out": fp.name, "to": t.name, "in": t.ports[e.to.1].name, "rate": fp.ratio.hz(base) })
        })
        .collect();
    let pruned: Vec<Value> = checked.pruned.iter().map(|x| json!({ "node": x.node, "reason": x.reason })).collect();
    json!({
        "name": checked.graph.name, "description": checked.graph.description, "base_rate": base,
        "nodes": nodes, "edges": edges, "pruned": pruned,
    })
}

/// The `limit` nodes the plan kept, with the taps of their input and output.
pub(crate) fn limiter_specs(
    checked: &Checked,
    tap_of: &dyn Fn(&str, &str) -> Option<usize>,
    plan_index: &dyn Fn(&str) -> Option<usize>,
) -> Vec<LimiterSpec> {
    let mut limiters = Vec::new();
    for (k, n) in checked.nodes.iter().enumerate().filter(|(_, n)| n.spec.name == limit::SPEC.name) {
        let Some(index) = plan_index(&n.name) else { continue };
        let input = checked.edges.iter().find(|e| e.to.0 == k && n.ports[e.to.1].name == "in").and_then(|e| {
            let f = &checked.nodes[e.from.0];
            tap_of(&f.name, &f.ports[e.from.1].name)
        });
        limiters.push(LimiterSpec {
            node: n.name.clone(),
            index: index as u32,
            amplitude: limit::AMPLITUDE.get(&n.params),
            input,
            output: tap_of(&n.name, "out"),
            state: tap_of(&n.name, "state"),
            enabled: limit::ENABLE.get(&n.params),
        });
    }
    limiters
}

/// The taps for the page: which to show at first (the defaults, the
/// limiters' outputs, velocities; not the limiters' `state`, which the
/// badges show).
pub(crate) fn taps_json(checked: Option<&Checked>, taps: &[(String, String, f64)], limiters: &[LimiterSpec]) -> Value {
    let defaults = checked.map(wanted_taps).unwrap_or_default();
    let list: Vec<Value> = taps
        .iter()
        .enumerate()
        .map(|(i, (node, port, rate))| {
            let is_state = limiters.iter().any(|l| l.state == Some(i));
            // A running count is shown as its rate (the synthesis panel), not as a trace.
            let count = port == "iterations" || port == "fallbacks";
            let shown = !is_state && !count && defaults.iter().any(|d| &d.node == node && &d.port == port)
                || limiters.iter().any(|l| l.output == Some(i))
                || port == "velocity"
                || port == "out" && checked.is_none();
            json!({ "i": i, "node": node, "port": port, "rate": rate, "shown": shown })
        })
        .collect();
    Value::Array(list)
}

fn param_json(node: &str, p: &ParamSpec, current: Option<&PValue>) -> Value {
    let (kind, min, max, choices) = match p.kind {
        ParamKind::Float { min, max } => ("float", json!(min), json!(max), json!(null)),
        ParamKind::Int { min, max } => ("int", json!(min), json!(max), json!(null)),
        ParamKind::Bool => ("bool", json!(null), json!(null), json!(null)),
        ParamKind::Choice(w) => ("choice", json!(null), json!(null), json!(w)),
        _ => ("other", json!(null), json!(null), json!(null)),
    };
    let value = match current {
        Some(PValue::Float(x)) => json!(x),
        Some(PValue::Int(i)) => json!(i),
        Some(PValue::Bool(b)) => json!(b),
        Some(PValue::Text(t)) => json!(t),
        _ => json!(null),
    };
    json!({
        "node": node, "param": p.name, "kind": kind, "min": min, "max": max, "choices": choices,
        "limits": p.kind.limits(), "unit": p.unit, "doc": p.doc, "value": value,
    })
}

impl Description {
    /// Describes a live session about to run `plan` (built from `checked`),
    /// with the graph variables bound to its live parameters.
    pub fn live(checked: &Checked, plan: &LivePlan, vars: &[LiveVar]) -> Self {
        let p = plan.plan();
        let base = p.base_rate();
        let taps = plan.taps().to_vec();
        let names: Vec<String> = (0..p.len()).map(|k| p.node_name(k).to_string()).collect();
        let params: Vec<Value> = checked
            .nodes
            .iter()
            .filter(|n| p.index(&n.name).is_some())
            .flat_map(|n| n.spec.params.iter().filter(|q| q.live).map(|q| param_json(&n.name, q, n.params.get(q.name))))
            .collect();
        let vars_json: Vec<Value> = vars
            .iter()
            .map(|v| {
                let first = v.uses.first().and_then(|(node, param)| {
                    let n = checked.nodes.iter().find(|n| &n.name == node)?;
                    Some(param_json(node, n.spec.param(param)?, n.params.get(param)))
                });
                let uses: Vec<String> = v.uses.iter().map(|(n, q)| format!("{n}.{q}")).collect();
                json!({ "name": v.name, "uses": uses, "param": first })
            })
            .collect();
        let tap_of = |node: &str, port: &str| taps.iter().position(|t| t.node == node && t.port == port);
        let limiters = limiter_specs(checked, &tap_of, &|n| p.index(n));
        let list: Vec<(String, String, f64)> = taps.iter().map(|t| (t.node.clone(), t.port.clone(), t.rate)).collect();
        let hello = json!({
            "type": "hello",
            "mode": "live",
            "graph": graph_json(checked, base, &|n| p.index(n).is_some()),
            "taps": taps_json(Some(checked), &list, &limiters),
            "params": params,
            "vars": vars_json,
            "limiters": limiters.iter().map(|l| json!({ "node": l.node, "amplitude": l.amplitude })).collect::<Vec<_>>(),
        });
        Self { hello, taps, names, limiters, base_rate: base }
    }

    /// Adds the finger view's background ([`super::scene_json`]).
    pub fn with_scene(mut self, scene: Value) -> Self {
        self.hello["scene"] = scene;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::{Plan, PlanOptions};

    const DOC: &str = r#"
[graph]
format = 1
name = "d"
rate = 1000.0
connections = ["s.out -> g.in", "g.out -> limit.in", "limit.out -> st.in", "idle.out -> g2.in"]
[nodes.s]
type = "sine"
[nodes.g]
type = "gain"
gain = "$gain"
[nodes.limit]
type = "limit"
amplitude = 0.5
[nodes.st]
type = "stats"
[nodes.idle]
type = "sine"
[nodes.g2]
type = "gain"
[vars]
gain = 2.0
"#;

    /// Every shipped graph's wanted taps, `graph: node.port …`, in order.
    fn shipped_wanted_taps() -> Vec<String> {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("graphs");
        let mut files: Vec<_> = std::fs::read_dir(&root)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        files.sort();
        files
            .iter()
            .map(|f| {
                let c = evflow_engine::load_file(f, &evflow_nodes::registry(), &[]).unwrap();
                let taps: Vec<String> = wanted_taps(&c).iter().map(|t| format!("{}.{}", t.node, t.port)).collect();
                format!("{}: {}", f.file_stem().unwrap().to_string_lossy(), taps.join(" "))
            })
            .collect()
    }

    /// The streams the studio showed by default in every shipped graph
    /// when the node types' knowledge of them still lived in this file
    /// (issue 35): the declarations must give the same.
    const SHIPPED_TAPS: &[&str] = &[
        "characterize: display.force",
        "display-live: limit.state display.force gain.out",
        "display-serial: limit.state gain.out",
        "excitation: display.force",
        "forces-recordings: ",
        "forward-build-recordings: ",
        "forward-build: display.force",
        "lab-work-precision: display_ref.force display.force",
        "mesh-live: surface.intensity edges.intensity limit.state display.force gain.out",
        "mesh-scan: surface.intensity edges.intensity limit.state display.force gain.out",
        "mesh-serial: surface.intensity edges.intensity limit.state gain.out",
        "model-build-multilevel: display.force",
        "model-build-recordings: ",
        "model-build: display.force",
        "model-validate-recordings: ",
        "play-actuation: limit.state display.force gain.out",
        "record-stroke: ",
        "record-textures: ",
        "synthesize-optimized: ",
        "synthesize-recordings: ",
        "synthesize: narx_limit.state narx_display.force narx_ml_limit.state narx_ml_display.force optimized_limit.state optimized_display.force playback_limit.state playback_display.force floor_display.force narx_gain.out narx_ml_gain.out optimized_gain.out playback_gain.out",
        "texture-cross-validation: display.force playback_display.force ff_display.force cells_limit.state playback_limit.state ff_limit.state load.out speed.out playback.out playback_loop.out ff_gain.out",
        "texture-forces-live: limit.state display.force velocity_cm_s.out load_g.out gain.out",
        "texture-live-play: limit.state display.force gain.out",
        "texture-live-quality: nothing_display.force playback_limit.state playback_display.force narx_limit.state narx_display.force optimized_limit.state optimized_display.force ff_limit.state ff_display.force live_synth.target live_synth.predicted live_synth.iterations live_synth.fallbacks live_limit.state live_display.force velocity_cm_s.out load_g.out playback_gain.out narx_gain.out optimized_gain.out ff_gain.out live_gain.out",
        "texture-live-recorded: synth.target synth.predicted synth.iterations synth.fallbacks limit.state velocity_cm_s.out load_g.out gain.out",
        "texture-live: synth.target synth.predicted synth.iterations synth.fallbacks limit.state display.force velocity_cm_s.out load_g.out gain.out",
        "texture-quality: velocity_cm_s.out load_g.out",
        "texture-render-quality: display.force forces_display.force limit.state forces_limit.state velocity_cm_s.out load_g.out gain.out forces_gain.out",
        "texture-serial: synth.target synth.predicted synth.iterations synth.fallbacks limit.state velocity_cm_s.out load_g.out gain.out",
    ];

    #[test]
    fn the_default_taps_of_every_shipped_graph_are_as_they_were() {
        assert_eq!(shipped_wanted_taps(), SHIPPED_TAPS);
    }

    #[test]
    fn the_page_is_told_the_graph_the_plan_left_out_the_limits_and_the_limiter() {
        let g = evflow_engine::graph::parse_graph(std::path::Path::new("d.toml"), DOC).unwrap();
        let checked = evflow_engine::check(&g, &evflow_nodes::registry(), &[]).unwrap();
        let opts = PlanOptions { max_block: 1, mode: evflow_engine::RunMode::Live, ..Default::default() };
        let plan = Plan::build(&checked, &opts).unwrap();
        let defaults = default_taps(&checked, &plan);
        assert_eq!(
            defaults,
            vec![Tap::new("limit", "state"), Tap::new("g", "out")],
            "the limiter's state, what feeds it"
        );
        assert_eq!(LivePlan::guard_taps(&plan), vec![Tap::new("limit", "out"), Tap::new("limit", "state")]);
        let mut taps = LivePlan::guard_taps(&plan);
        taps.extend(defaults.into_iter().filter(|t| t.port != "state"));
        let lp = LivePlan::new(plan, &taps).unwrap();
        let vars = evflow_engine::live::live_vars(&checked);
        let d = Description::live(&checked, &lp, &vars);
        let h = &d.hello;
        // What the plan left out, and why.
        let pruned: Vec<&str> =
            h["graph"]["pruned"].as_array().unwrap().iter().map(|p| p["node"].as_str().unwrap()).collect();
        assert!(pruned.contains(&"g2") && pruned.contains(&"idle"), "{pruned:?}");
        let idle = h["graph"]["nodes"].as_array().unwrap().iter().find(|n| n["name"] == "idle").unwrap();
        assert_eq!(idle["in_plan"], false);
        assert_eq!(h["graph"]["edges"].as_array().unwrap().len(), 4);
        // Live parameters with their declared limits; the variable bound to one.
        let gain = h["params"].as_array().unwrap().iter().find(|p| p["node"] == "g" && p["param"] == "gain").unwrap();
        assert_eq!(gain["kind"], "float");
        assert_eq!(gain["value"], 2.0);
        assert_eq!(h["vars"][0]["name"], "gain");
        assert_eq!(h["vars"][0]["uses"], json!(["g.gain"]));
        // The limiter watched through its state, input and output taps.
        assert_eq!(d.limiters.len(), 1);
        let l = &d.limiters[0];
        assert_eq!((l.amplitude, l.input, l.output, l.state), (0.5, Some(2), Some(0), Some(1)));
        assert_eq!(h["taps"][0]["shown"], true);
        assert_eq!(h["taps"][1]["shown"], false, "the state is the badge, not a trace");
        assert_eq!(h["taps"][2]["shown"], true);
    }
}
