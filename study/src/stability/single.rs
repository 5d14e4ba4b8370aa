//! One node run alone (the engine's harness: feed sources → the node →
//! taps), its outputs and the values it reports watched into an
//! [`Observed`].

use super::invariant::Observed;
use evflow_engine::graph::parse_graph;
use evflow_engine::harness::Single;
use evflow_engine::{Direction, NodeSpec, Value};
use std::path::Path;

/// The harness' rate, Hz (every node example runs at 1 kHz).
pub const RATE: f64 = 1000.0;

/// The node's input and output port names as its `params` (a TOML node
/// body) expand them (`multi` ports take their names from a list
/// parameter), or why the body does not parse.
pub fn ports(spec: &NodeSpec, params: &str) -> Result<(Vec<String>, Vec<String>), String> {
    let doc =
        format!("[graph]\nformat = 1\nname = \"x\"\nrate = 1000\n[nodes.x]\ntype = \"{}\"\n{params}\n", spec.name);
    let g = parse_graph(Path::new("stability"), &doc).map_err(|e| e.to_string())?;
    let decl = g.nodes.first().ok_or("no node")?;
    let list = |param: &str| -> Vec<String> {
        match decl.params.iter().find(|p| p.name == param).map(|p| &p.value) {
            Some(Value::TextList(v)) => v.clone(),
            _ => Vec::new(),
        }
    };
    let (mut ins, mut outs) = (Vec::new(), Vec::new());
    for p in spec.ports {
        let names = match p.multi {
            Some(l) => list(l),
            None => vec![p.name.to_string()],
        };
        match p.dir {
            Direction::In => ins.extend(names),
            Direction::Out => outs.extend(names),
        }
    }
    Ok((ins, outs))
}

/// Runs `spec` with `params` for `ticks` base ticks at 1 kHz, every input
/// fed by `input(k)` for input `k`, in blocks of `block`; watches every
/// output and every value the node reports when the run ends.
pub fn run(
    spec: &'static NodeSpec,
    params: &str,
    input: &dyn Fn(usize) -> Vec<f64>,
    ticks: u64,
    block: usize,
    dir: &Path,
) -> Observed {
    let mut o = Observed::default();
    let (ins, outs) = match ports(spec, params) {
        Ok(p) => p,
        Err(e) => {
            o.error = Some(e);
            return o;
        }
    };
    let single = Single::new(spec, params)
        .inputs(ins.iter().enumerate().map(|(k, n)| (n.as_str(), input(k), RATE)))
        .outputs(outs.iter().map(String::as_str))
        .base_rate(RATE)
        .ticks(ticks)
        .block(block)
        .base_dir(dir);
    let (mut plan, index) = match single.plan() {
        Ok(p) => p,
        Err(e) => {
            o.error = Some(e);
            return o;
        }
    };
    match single.collect(&mut plan, &index) {
        Ok(values) => {
            for (name, v) in outs.iter().zip(&values) {
                o.watch(name, v);
            }
        }
        Err(e) => {
            o.error = Some(e);
            return o;
        }
    }
    match plan.finish() {
        Ok(summaries) => {
            for (node, s) in summaries {
                if node == "dut" {
                    for (name, v, _) in &s.values {
                        o.watch(&format!("summary {name}"), &[*v]);
                    }
                }
            }
        }
        Err(e) => o.error = Some(e.to_string()),
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gain_node_is_watched_and_its_overflow_saturates() {
        let spec = evflow_nodes::registry().get("gain").unwrap();
        let dir = tempfile::tempdir().unwrap();
        let o = run(spec, "gain = 2.0", &|_| vec![1.0, -3.0, 0.5], 3, 64, dir.path());
        assert_eq!(o.error, None);
        assert_eq!(o.max_abs, 6.0);
        assert_eq!(o.non_finite, 0);
        let big = run(spec, "gain = 2.0", &|_| vec![f64::MAX, 1.0], 2, 64, dir.path());
        assert_eq!((big.max_abs, big.non_finite), (f64::MAX, 0), "{big:?}");
        // A NaN or Inf output is counted, by port.
        let mut o = Observed::default();
        o.watch("out", &[1.0, f64::INFINITY, f64::NAN]);
        assert_eq!((o.non_finite, o.bad_ports.as_slice()), (2, ["out".to_string()].as_slice()));
    }
}
