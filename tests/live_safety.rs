//! The loader refuses a graph in which a hardware output is not fed
//! directly by a safety guard (`limit`), and accepts it when it is.

use evflow_engine::graph::parse_graph;
use evflow_engine::{check, BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Registry, Role};
use std::path::Path;

/// A stand-in for a hardware output (`serial.out` comes later).
static ACTUATOR: NodeSpec = NodeSpec::new("test.actuator", "test", Role::Sink, "hardware output (test only)", build)
    .ports(&[PortSpec::input("u", "1", "actuation"), PortSpec::input("aux", "1", "second channel")])
    .hardware();

struct Actuator;
fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Actuator))
}
impl Node for Actuator {
    fn process(&mut self, _: &mut Io<'_>) -> Result<(), NodeError> {
        Ok(())
    }
    fn reset(&mut self) {}
}

fn registry() -> Registry {
    let mut r = evflow_nodes::registry();
    r.add(&ACTUATOR);
    r
}

/// A graph with the connections given and the nodes they name (the
/// hardware output `dac` last, so its table starts on the last line but one).
fn graph(connections: &[&str]) -> String {
    let c: Vec<String> = connections.iter().map(|c| format!("\"{c}\"")).collect();
    let mut s = format!("[graph]\nformat = 1\nname = \"hw\"\nrate = 1000.0\nconnections = [{}]\n", c.join(", "));
    for (name, kind) in [("drive", "sine"), ("gain", "gain"), ("limit", "limit"), ("limit2", "limit")] {
        if connections.iter().any(|c| c.contains(&format!("{name}."))) {
            s += &format!("[nodes.{name}]\ntype = \"{kind}\"\n");
        }
    }
    s + "[nodes.dac]\ntype = \"test.actuator\"\n"
}

fn load(connections: &[&str]) -> Result<(), String> {
    let text = graph(connections);
    let g = parse_graph(Path::new("rig.toml"), &text).map_err(|e| e.to_string())?;
    check(&g, &registry(), &[]).map(|_| ()).map_err(|e| e.to_string())
}

#[test]
fn a_hardware_output_fed_by_limit_loads() {
    load(&[
        "drive.out -> gain.in",
        "gain.out -> limit.in",
        "limit.out -> dac.u",
        "drive.out -> limit2.in",
        "limit2.out -> dac.aux",
    ])
    .unwrap();
    // One limiter may feed both channels.
    load(&["drive.out -> gain.in", "gain.out -> limit.in", "limit.out -> dac.u", "limit.out -> dac.aux"]).unwrap();
}

#[test]
fn a_hardware_output_without_limit_is_refused_naming_file_line_and_node() {
    let e = load(&["drive.out -> gain.in", "gain.out -> dac.u", "gain.out -> dac.aux"]).unwrap_err();
    let line = graph(&["drive.out -> gain.in", "gain.out -> dac.u", "gain.out -> dac.aux"]).lines().count() - 1;
    assert!(e.contains(&format!("rig.toml:{line}:")) && e.contains("node `dac`"), "{e}");
    assert!(e.contains("hardware output `dac.u` is not fed by a `limit` node"), "{e}");
    assert!(e.contains("hardware output `dac.aux` is not fed by a `limit` node"), "{e}");
    assert!(e.contains("must pass a `limit` node"), "{e}");
}

#[test]
fn limit_must_be_directly_in_front_of_the_hardware() {
    // A gain after the limiter could undo the clamp.
    let e = load(&["drive.out -> limit.in", "limit.out -> gain.in", "gain.out -> dac.u", "limit.out -> dac.aux"])
        .unwrap_err();
    assert!(e.contains("`dac.u` is not fed by a `limit` node"), "{e}");
    assert!(!e.contains("dac.aux"), "{e}");
}

#[test]
fn one_unguarded_channel_is_enough_to_refuse() {
    let e = load(&["drive.out -> limit.in", "limit.out -> dac.u", "drive.out -> dac.aux"]).unwrap_err();
    assert!(e.contains("`dac.aux` is not fed by a `limit` node") && !e.contains("`dac.u`"), "{e}");
}
