//! Unit tests of the runner with small test nodes (the integration tests in
//! `tests/live_*.rs` run the node library's graphs).

use super::*;
use crate::check::{check, Checked};
use crate::graph::parse_graph;
use crate::harness::TAP;
use crate::node::{BuildContext, Change, Io, Node, NodeError, Refused};
use crate::params::Params;
use crate::plan::{Plan, PlanOptions};
use crate::ports::{InPort, OutPort};
use crate::registry::Registry;
use crate::spec::{NodeSpec, ParamSpec, PortSpec, Role};
use crate::typed_params::{Flag, Float};
use std::path::Path;
use std::time::Duration;

/// Endless source: `level + n` scaled... outputs the tick index n plus
/// `level` (live), and sleeps `stall_ms` per sample from sample `stall_from`.
static COUNTER: NodeSpec = NodeSpec::new("test.counter", "test", Role::Source, "n + level (test only)", build_counter)
    .ports(&[PortSpec::output("out", "1", "n + level")])
    .params(&[
        LEVEL.spec(),
        ParamSpec::float("stall_ms", 0.0, 100.0, 0.0, "ms", "sleep per sample"),
        ParamSpec::int("stall_from", 0, 1 << 40, 0, "1", "first stalled sample"),
        ParamSpec::int("length", 0, 1 << 40, 0, "1", "samples (0 = endless)"),
    ]);

struct Counter {
    n: u64,
    level: f64,
    stall: Duration,
    stall_from: u64,
    length: u64,
}

fn build_counter(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Counter {
        n: 0,
        level: LEVEL.get(p),
        stall: Duration::from_secs_f64(p.f64("stall_ms") / 1e3),
        stall_from: p.i64("stall_from") as u64,
        length: p.i64("length") as u64,
    }))
}

impl Node for Counter {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for y in io.output(OutPort::at(0)) {
            if !self.stall.is_zero() && self.n >= self.stall_from {
                std::thread::sleep(self.stall);
            }
            *y = self.n as f64 + self.level;
            self.n += 1;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.n = 0;
    }
    fn remaining(&self) -> Option<u64> {
        (self.length > 0).then(|| self.length.saturating_sub(self.n))
    }
    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match LEVEL.changed(&c) {
            Some(level) => {
                self.level = level;
                Ok(())
            }
            None => Err(c.refused()),
        }
    }
}

/// The offset of `test.const`, changeable live.
const LEVEL: Float = Float::new("level", -1e9, 1e9, 0.0, "1", "offset").live();
/// The gate of `test.guard`.
const ENABLE: Flag = Flag::new("enable", true, "gate").live();

/// A guard: passes its input times a gate that closes in 3 samples.
static GUARD: NodeSpec = NodeSpec::new("test.guard", "test", Role::Filter, "gate (test only)", build_guard)
    .ports(&[PortSpec::input("in", "1", "x"), PortSpec::output("out", "1", "x · gate")])
    .params(&[ENABLE.spec()])
    .safety_guard(ENABLE.name());

struct Guard {
    open: bool,
    gate: f64,
}

fn build_guard(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Guard { open: true, gate: 1.0 }))
}

impl Node for Guard {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(InPort::at(0), OutPort::at(0));
        for (y, x) in y.iter_mut().zip(x) {
            self.gate = if self.open { 1.0 } else { (self.gate - 1.0 / 3.0).max(0.0) };
            *y = x * self.gate;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.gate = 1.0;
    }
    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match ENABLE.changed(&c) {
            Some(open) => {
                self.open = open;
                Ok(())
            }
            None => Err(c.refused()),
        }
    }
}

fn live_plan(counter: &str, taps: &[(&str, &str)]) -> LivePlan {
    let doc = format!(
        "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\nconnections = [\"c.out -> g.in\", \"g.out -> t.in\"]\n\
         [nodes.c]\ntype = \"test.counter\"\n{counter}\n[nodes.g]\ntype = \"test.guard\"\n[nodes.t]\ntype = \"harness.tap\"\n"
    );
    let mut reg = Registry::new();
    reg.add(&COUNTER).add(&GUARD).add(&TAP);
    let g = parse_graph(Path::new("t.toml"), &doc).unwrap();
    let checked = check(&g, &reg, &[]).unwrap();
    let plan = Plan::build(
        &checked,
        &PlanOptions { max_block: 1, mode: crate::RunMode::Live, timing: false, ..PlanOptions::default() },
    )
    .unwrap();
    let taps: Vec<Tap> = taps.iter().map(|(n, p)| Tap::new(n, p)).collect();
    LivePlan::new(plan, &taps).unwrap()
}

fn config(duration: Option<f64>) -> LiveConfig {
    LiveConfig { duration, miss_streak: 0, stop_ramp: Duration::from_millis(3), ..LiveConfig::default() }
}

fn drain(ring: &mut rtrb::Consumer<f64>) -> Vec<f64> {
    let mut v = Vec::new();
    while let Ok(x) = ring.pop() {
        v.push(x);
    }
    v
}

fn events(ring: &mut rtrb::Consumer<Event>) -> Vec<Event> {
    let mut v = Vec::new();
    while let Ok(x) = ring.pop() {
        v.push(x);
    }
    v
}

#[test]
fn a_finite_source_ends_the_session_after_the_guards_faded() {
    let live = start(live_plan("length = 120", &[("c", "out"), ("g", "out")]), &config(None)).unwrap();
    let mut p = live.into_parts();
    let exit = p.thread.join();
    assert_eq!(exit.ticks, 120, "every sample of the source, no tick past its end");
    assert_eq!(exit.reason, Some(StopReason::SourcesEnded));
    let c = drain(&mut p.taps[0].1);
    let g = drain(&mut p.taps[1].1);
    assert_eq!(c, (0..120).map(|n| n as f64).collect::<Vec<_>>());
    // The stop sequence is 3 ms + 1 tick = 4 ticks: the gate closed in 3.
    assert_eq!(&g[..116], &c[..116]);
    let expected = [116.0 * 2.0 / 3.0, 117.0 / 3.0, 0.0, 0.0];
    for (a, b) in g[116..].iter().zip(expected) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    let ev = events(&mut p.events);
    assert_eq!(ev[0], Event { tick: 116, kind: EventKind::Stop(StopReason::SourcesEnded) });
    assert_eq!(ev[1], Event { tick: 116, kind: EventKind::Set { node: 1, param: "enable", value: 0.0 } });
}

#[test]
fn commands_apply_at_their_tick_in_order() {
    let mut live = start(live_plan("", &[("c", "out")]), &config(Some(0.2))).unwrap();
    live.control.set("c", "level", "1000", Some(50)).unwrap();
    live.control.set_text("c.level=2000", Some(50)).unwrap();
    live.control.set_text("c.level 3000", Some(60)).unwrap();
    assert!(live
        .control
        .set("c", "stall_ms", "1", None)
        .unwrap_err()
        .to_string()
        .contains("cannot change while running"));
    assert!(live.control.set("c", "level", "1e10", None).is_err());
    assert!(live.control.set("x", "level", "1", None).is_err());
    let mut p = live.into_parts();
    let exit = p.thread.join();
    assert_eq!(exit.reason, Some(StopReason::Duration));
    assert_eq!(exit.ticks, 200 + 4);
    let c = drain(&mut p.taps[0].1);
    assert_eq!(c[49], 49.0);
    assert_eq!(c[50], 2050.0);
    assert_eq!(c[59], 2059.0);
    assert_eq!(c[60], 3060.0);
    let sets: Vec<(u64, f64)> = events(&mut p.events)
        .into_iter()
        .filter_map(|e| match e.kind {
            EventKind::Set { param: "level", value, .. } => Some((e.tick, value)),
            _ => None,
        })
        .collect();
    assert_eq!(sets, vec![(50, 1000.0), (50, 2000.0), (60, 3000.0)]);
}

#[test]
fn a_stop_request_fades_the_guards_before_the_thread_ends() {
    let live = start(live_plan("level = 1", &[("g", "out")]), &config(None)).unwrap();
    let mut p = live.into_parts();
    while p.shared.ticks() < 30 {
        std::thread::sleep(Duration::from_millis(2));
    }
    p.control.stop();
    let exit = p.thread.join();
    assert_eq!(exit.reason, Some(StopReason::Requested));
    let g = drain(&mut p.taps[0].1);
    assert_eq!(g.len() as u64, exit.ticks);
    assert_eq!(*g.last().unwrap(), 0.0);
    let ev = events(&mut p.events);
    let stop = ev.iter().find(|e| matches!(e.kind, EventKind::Stop(_))).unwrap().tick;
    assert_eq!(exit.ticks, stop + 4);
    assert!(g[stop as usize - 1] > 0.0);
}

#[test]
fn a_full_ring_drops_whole_ticks_counts_them_and_never_blocks() {
    // A ring of 0.02 s (20 samples) that nobody reads during the run.
    let cfg = LiveConfig { tap_seconds: 0.02, ..config(Some(0.1)) };
    let live = start(live_plan("", &[("c", "out"), ("g", "out")]), &cfg).unwrap();
    let mut p = live.into_parts();
    let exit = p.thread.join();
    assert_eq!(exit.ticks, 104, "the run went on to its end");
    let dropped = p.shared.tap_overruns.load(std::sync::atomic::Ordering::Relaxed);
    assert_eq!(dropped, 104 - 20);
    let c = drain(&mut p.taps[0].1);
    assert_eq!(c, (0..20).map(|n| n as f64).collect::<Vec<_>>());
    assert_eq!(drain(&mut p.taps[1].1).len(), 20);
    let gaps: Vec<Event> =
        events(&mut p.events).into_iter().filter(|e| matches!(e.kind, EventKind::Gap { .. })).collect();
    assert_eq!(gaps, vec![Event { tick: 20, kind: EventKind::Gap { ticks: 84 } }]);
}

#[test]
fn a_streak_of_deadline_misses_stops_the_session() {
    // From sample 20 on, every tick sleeps 3 ms: three periods.
    let cfg = LiveConfig { miss_streak: 5, ..config(Some(5.0)) };
    let live = start(live_plan("stall_ms = 3.0\nstall_from = 20", &[("g", "out")]), &cfg).unwrap();
    let mut p = live.into_parts();
    let exit = p.thread.join();
    assert_eq!(exit.reason, Some(StopReason::DeadlineMisses));
    assert!(exit.ticks < 60, "stopped early: {}", exit.ticks);
    let mut m = Metrics::new();
    m.drain(&mut p.stats);
    assert!(m.longest_streak >= 5);
    let g = drain(&mut p.taps[0].1);
    assert_eq!(*g.last().unwrap(), 0.0);
}

#[test]
fn a_replaced_plan_comes_back_to_be_dropped_off_the_real_time_thread() {
    let mut live = start(live_plan("level = 0.5", &[("g", "out")]), &config(Some(0.3))).unwrap();
    assert!(matches!(live.control.replace(live_plan("", &[("c", "out")])), Err(LiveError::TapMismatch(_))));
    live.control.replace(live_plan("level = 1000", &[("g", "out")])).unwrap();
    let mut p = live.into_parts();
    let mut back = 0;
    while !p.thread.is_finished() {
        back += p.control.collect_retired();
        std::thread::sleep(Duration::from_millis(5));
    }
    let exit = p.thread.join();
    back += p.control.collect_retired();
    assert_eq!(back, 1);
    let ev = events(&mut p.events);
    let at = ev.iter().find(|e| e.kind == EventKind::Replaced).unwrap().tick;
    let g = drain(&mut p.taps[0].1);
    assert_eq!(g[at as usize - 1], 0.0, "the old plan faded out before the swap");
    assert_eq!(g[at as usize], 1000.0, "the new plan starts at its own t = 0");
    assert_eq!(exit.ticks, 304);
}

#[test]
fn offline_only_nodes_and_unknown_taps_are_refused() {
    static OFF: NodeSpec = NodeSpec::new("test.off", "test", Role::Sink, "offline (test only)", build_off)
        .ports(&[PortSpec::input("in", "1", "x")])
        .offline_only("it writes files while processing");
    fn build_off(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Ok(Box::new(Guard { open: true, gate: 1.0 }))
    }
    let doc = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\nconnections = [\"c.out -> o.in\"]\n\
               [nodes.c]\ntype = \"test.counter\"\n[nodes.o]\ntype = \"test.off\"\n";
    let mut reg = Registry::new();
    reg.add(&COUNTER).add(&OFF);
    let checked = check(&parse_graph(Path::new("t.toml"), doc).unwrap(), &reg, &[]).unwrap();
    let live = PlanOptions { mode: crate::RunMode::Live, ..PlanOptions::default() };
    let plan = Plan::build(&checked, &live).unwrap();
    let e = LivePlan::new(plan, &[]).err().unwrap().to_string();
    assert_eq!(e, "node `o` (test.off) cannot run live: it writes files while processing");

    let lp = live_plan("", &[]);
    let e = LivePlan::new(lp.plan, &[Tap::new("g", "outt")]).err().unwrap().to_string();
    assert!(e.contains("cannot record `g.outt`") && e.contains("`out`"), "{e}");
}

/// Two counters whose `level` is one graph variable, each tapped.
fn two_counters() -> (Checked, LivePlan) {
    let doc = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\n\
               connections = [\"a.out -> g.in\", \"g.out -> t.in\", \"b.out -> h.in\", \"h.out -> u.in\"]\n\
               [vars]\nlevel = 0.0\nstall = 0.0\n\
               [nodes.a]\ntype = \"test.counter\"\nlevel = \"$level\"\nstall_ms = \"$stall\"\n\
               [nodes.b]\ntype = \"test.counter\"\nlevel = \"$level\"\n\
               [nodes.g]\ntype = \"test.guard\"\n[nodes.t]\ntype = \"harness.tap\"\n\
               [nodes.h]\ntype = \"test.guard\"\n[nodes.u]\ntype = \"harness.tap\"\n";
    let mut reg = Registry::new();
    reg.add(&COUNTER).add(&GUARD).add(&TAP);
    let checked = check(&parse_graph(Path::new("t.toml"), doc).unwrap(), &reg, &[]).unwrap();
    let plan = Plan::build(
        &checked,
        &PlanOptions { max_block: 1, mode: crate::RunMode::Live, timing: false, ..PlanOptions::default() },
    )
    .unwrap();
    let lp = LivePlan::new(plan, &[Tap::new("a", "out"), Tap::new("b", "out")]).unwrap();
    (checked, lp)
}

#[test]
fn a_graph_variable_sets_every_live_parameter_it_names_at_one_tick() {
    let (checked, lp) = two_counters();
    let vars = live_vars(&checked);
    // `stall` names a parameter that cannot change live: not bound.
    assert_eq!(vars, vec![LiveVar { name: "level".into(), uses: vec![("a".into(), "level"), ("b".into(), "level")] }]);
    let mut live = start(lp, &config(Some(0.1))).unwrap();
    live.control.bind_vars(vars);
    live.control.set_text("level=500", Some(40)).unwrap();
    live.control.set_var("$level", "7", Some(70)).unwrap();
    let e = live.control.set_text("stall=1", None).unwrap_err().to_string();
    assert!(e.contains("no graph variable `stall`") && e.contains("live variables: level"), "{e}");
    let e = live.control.set_text("level=1e12", None).unwrap_err().to_string();
    assert!(e.contains("outside its limits"), "{e}");
    let e = live.control.set_text("levl=1", None).unwrap_err().to_string();
    assert!(e.contains("`level`"), "suggests the closest name: {e}");
    let mut p = live.into_parts();
    p.thread.join();
    let a = drain(&mut p.taps[0].1);
    let b = drain(&mut p.taps[1].1);
    for s in [&a, &b] {
        assert_eq!((s[39], s[40], s[69], s[70]), (39.0, 540.0, 569.0, 77.0));
    }
    // An "as soon as possible" change lands on one tick for both nodes.
    let (checked, lp) = two_counters();
    let mut live = start(lp, &config(Some(0.2))).unwrap();
    live.control.bind_vars(live_vars(&checked));
    while live.control.ticks() < 20 {
        std::thread::sleep(Duration::from_millis(1));
    }
    for v in 1..=20 {
        live.control.set_var("level", &format!("{}", v * 1000), None).unwrap();
    }
    let mut p = live.into_parts();
    p.thread.join();
    let a = drain(&mut p.taps[0].1);
    let b = drain(&mut p.taps[1].1);
    assert_eq!(a, b, "both counters changed at the same ticks");
    assert!(a.iter().any(|&x| x >= 20_000.0), "the changes applied");
}

#[test]
fn a_variable_bound_to_nodes_the_plan_left_out_binds_only_what_runs() {
    let (_, lp) = two_counters();
    let mut live = start(lp, &config(Some(0.05))).unwrap();
    live.control.bind_vars(vec![
        LiveVar { name: "level".into(), uses: vec![("a".into(), "level"), ("gone".into(), "level")] },
        LiveVar { name: "only_gone".into(), uses: vec![("gone".into(), "level")] },
    ]);
    assert_eq!(live.control.vars(), &[LiveVar { name: "level".into(), uses: vec![("a".into(), "level")] }]);
    live.control.set_var("level", "3", None).unwrap();
    let e = live.control.set_var("only_gone", "3", None).unwrap_err().to_string();
    assert!(e.contains("no graph variable `only_gone`"), "{e}");
    live.into_parts().thread.join();
}

#[test]
fn a_plan_built_to_run_offline_is_refused_by_the_live_runner() {
    let doc = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\nconnections = [\"c.out -> g.in\", \"g.out -> t.in\"]\n\
               [nodes.c]\ntype = \"test.counter\"\n[nodes.g]\ntype = \"test.guard\"\n[nodes.t]\ntype = \"harness.tap\"\n";
    let mut reg = Registry::new();
    reg.add(&COUNTER).add(&GUARD).add(&TAP);
    let checked = check(&parse_graph(Path::new("t.toml"), doc).unwrap(), &reg, &[]).unwrap();
    // Blocks of one tick do not make a plan live: only its mode does.
    let offline = Plan::build(&checked, &PlanOptions { max_block: 1, ..PlanOptions::default() }).unwrap();
    assert_eq!(offline.mode(), crate::RunMode::Offline);
    assert!(matches!(LivePlan::new(offline, &[]), Err(LiveError::NotLive)));
}
