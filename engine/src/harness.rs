//! Runs one node alone, fed from vectors, for unit tests and benchmarks.
//!
//! The harness builds a real graph — `feed` sources → the node under test →
//! `tap` sinks — and drives it through the same [`Plan::step`] as every other
//! run, collecting each output port after every step.

use crate::check::check;
use crate::graph::parse_graph;
use crate::node::{BuildContext, Io, Node, NodeError, RunMode};
use crate::params::{toml_float, Params};
use crate::plan::{Folding, Plan, PlanOptions};
use crate::ports::OutPort;
use crate::registry::Registry;
use crate::spec::{NodeSpec, PortSpec, RateSpec, Role};
use crate::typed_params::{Float, Floats};
use std::path::Path;

/// A source that plays the `values` list once, at `rate` Hz.
pub static FEED: NodeSpec =
    NodeSpec::new("harness.feed", "harness", Role::Source, "Plays a list of values (test harness).", build_feed)
        .ports(FEED_PORTS)
        .params(&[VALUES.spec(), RATE.spec()])
        .rate_param(RATE.name());

/// `harness.feed`'s one output.
const FEED_PORTS: &[PortSpec] = &[PortSpec::output("out", "1", "the values")];
const FEED_OUT: OutPort = OutPort::named(FEED_PORTS, "out");
/// `values`: the samples `harness.feed` plays.
const VALUES: Floats = Floats::new("values", f64::NEG_INFINITY, f64::INFINITY, "1", "samples to play");
/// `rate`: `harness.feed`'s sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

/// A sink that accepts any rate and discards its input (the harness reads
/// the plan's buffers directly).
pub static TAP: NodeSpec =
    NodeSpec::new("harness.tap", "harness", Role::Sink, "Discards its input (test harness).", build_tap)
        .ports(&[PortSpec::input("in", "1", "anything").at(RateSpec::Any)]);

struct Feed {
    values: Vec<f64>,
    pos: usize,
}

impl Node for Feed {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for y in io.output(FEED_OUT).iter_mut() {
            *y = self.values.get(self.pos).copied().unwrap_or(0.0);
            self.pos += 1;
        }
        Ok(())
    }
    fn reset(&mut self) {
        self.pos = 0;
    }
    fn remaining(&self) -> Option<u64> {
        Some(self.values.len().saturating_sub(self.pos) as u64)
    }
}

struct Tap;

impl Node for Tap {
    fn process(&mut self, _io: &mut Io<'_>) -> Result<(), NodeError> {
        Ok(())
    }
    fn reset(&mut self) {}
}

fn build_feed(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Feed { values: VALUES.get(p).to_vec(), pos: 0 }))
}

fn build_tap(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    Ok(Box::new(Tap))
}

/// One node under test.
pub struct Single<'a> {
    /// Its declaration.
    pub spec: &'static NodeSpec,
    /// Its parameters, as the body of a TOML node table (without `type`).
    pub params: &'a str,
    /// Its inputs by port name, each with its samples and rate in Hz.
    pub inputs: Vec<(&'a str, Vec<f64>, f64)>,
    /// Output ports to collect.
    pub outputs: Vec<&'a str>,
    /// The base rate in Hz.
    pub base_rate: f64,
    /// Base ticks to run.
    pub ticks: u64,
    /// Base ticks per step (1 = the live tick).
    pub block: usize,
    /// Folder for relative paths (inputs and outputs).
    pub base_dir: &'a Path,
}

impl<'a> Single<'a> {
    /// A node under test with its parameters (the body of a TOML node table),
    /// no inputs or outputs yet, a base rate of 1 kHz, no ticks, blocks of
    /// 64 ticks and relative paths taken from the working folder.
    ///
    /// ```
    /// use evflow_engine::harness::{Single, FEED};
    /// let out = Single::new(&FEED, "values = [1.0, 2.0, 3.0]").output("out").ticks(3).run().unwrap();
    /// assert_eq!(out, vec![vec![1.0, 2.0, 3.0]]);
    /// ```
    pub fn new(spec: &'static NodeSpec, params: &'a str) -> Self {
        Self {
            spec,
            params,
            inputs: Vec::new(),
            outputs: Vec::new(),
            base_rate: 1000.0,
            ticks: 0,
            block: 64,
            base_dir: Path::new("."),
        }
    }

    /// Feeds input port `port` with `samples` at `rate` Hz.
    pub fn input(mut self, port: &'a str, samples: Vec<f64>, rate: f64) -> Self {
        self.inputs.push((port, samples, rate));
        self
    }

    /// Collects output port `port` (in the order asked).
    pub fn output(mut self, port: &'a str) -> Self {
        self.outputs.push(port);
        self
    }

    /// Feeds each of these input ports: `(port, samples, rate in Hz)`.
    pub fn inputs(mut self, ports: impl IntoIterator<Item = (&'a str, Vec<f64>, f64)>) -> Self {
        self.inputs.extend(ports);
        self
    }

    /// Collects these output ports, in this order.
    pub fn outputs(mut self, ports: impl IntoIterator<Item = &'a str>) -> Self {
        self.outputs.extend(ports);
        self
    }

    /// The base rate in Hz.
    pub fn base_rate(mut self, hz: f64) -> Self {
        self.base_rate = hz;
        self
    }

    /// Base ticks to run.
    pub fn ticks(mut self, n: u64) -> Self {
        self.ticks = n;
        self
    }

    /// Base ticks per step (1 = the live tick).
    pub fn block(mut self, n: usize) -> Self {
        self.block = n;
        self
    }

    /// Folder for relative paths.
    pub fn base_dir(mut self, dir: &'a Path) -> Self {
        self.base_dir = dir;
        self
    }
}

impl Single<'_> {
    /// Builds the plan (without running it).
    pub fn plan(&self) -> Result<(Plan, Vec<usize>), String> {
        let mut reg = Registry::new();
        reg.add(self.spec);
        if self.spec.name != FEED.name {
            reg.add(&FEED);
        }
        reg.add(&TAP);
        let mut doc = format!(
            "[graph]\nformat = 1\nname = \"harness\"\nrate = {}\nconnections = [\n",
            toml_float(self.base_rate)
        );
        for (i, (port, _, _)) in self.inputs.iter().enumerate() {
            doc += &format!("  \"feed{i}.out -> dut.{port}\",\n");
        }
        for (i, port) in self.outputs.iter().enumerate() {
            doc += &format!("  \"dut.{port} -> tap{i}.in\",\n");
        }
        doc += "]\n";
        doc += &format!("[nodes.dut]\ntype = \"{}\"\n{}\n", self.spec.name, self.params);
        for (i, (_, values, rate)) in self.inputs.iter().enumerate() {
            let list: Vec<String> = values.iter().map(|x| toml_float(*x)).collect();
            doc += &format!(
                "[nodes.feed{i}]\ntype = \"harness.feed\"\nrate = {}\nvalues = [{}]\n",
                toml_float(*rate),
                list.join(",")
            );
        }
        for i in 0..self.outputs.len() {
            doc += &format!("[nodes.tap{i}]\ntype = \"harness.tap\"\n");
        }
        let graph = parse_graph(Path::new("<harness>"), &doc).map_err(|d| d.to_string())?;
        let checked = check(&graph, &reg, &[]).map_err(|d| d.to_string())?;
        let dut = checked.index("dut").ok_or("no dut")?;
        let node = &checked.nodes[dut];
        let out_index: Vec<usize> = self
            .outputs
            .iter()
            .map(|name| {
                node.outputs().position(|p| node.ports[p].name == *name).ok_or_else(|| format!("no output `{name}`"))
            })
            .collect::<Result<_, _>>()?;
        let opts = PlanOptions {
            max_block: self.block,
            seed: None,
            base_dir: Some(self.base_dir.to_path_buf()),
            out_dir: Some(self.base_dir.to_path_buf()),
            timing: false,
            mode: RunMode::Offline,
            check_only: false,
        };
        // The node under test always runs: never replaced by a constant.
        let plan = Plan::build_with(&checked, &opts, Folding::Off).map_err(|e| e.to_string())?;
        Ok((plan, out_index))
    }

    /// Runs the node and returns each collected output.
    pub fn run(&self) -> Result<Vec<Vec<f64>>, String> {
        let (mut plan, out_index) = self.plan()?;
        let outs = self.collect(&mut plan, &out_index)?;
        plan.finish().map_err(|e| e.to_string())?;
        Ok(outs)
    }

    /// Runs the node for `ticks` base ticks, finishes the run and returns
    /// what the node reported (for sinks).
    pub fn summary(&self) -> Result<crate::node::Summary, String> {
        let (mut plan, out_index) = self.plan()?;
        self.collect(&mut plan, &out_index)?;
        let summaries = plan.finish().map_err(|e| e.to_string())?;
        summaries
            .into_iter()
            .find(|(n, _)| n == "dut")
            .map(|(_, s)| s)
            .ok_or_else(|| "the node reported nothing".into())
    }

    /// Runs `ticks` base ticks of an already built plan (from [`Single::plan`])
    /// and returns each collected output, without finishing the plan.
    pub fn collect(&self, plan: &mut Plan, out_index: &[usize]) -> Result<Vec<Vec<f64>>, String> {
        let mut outs = vec![Vec::new(); self.outputs.len()];
        let mut done = 0;
        while done < self.ticks {
            let n = (plan.max_block() as u64).min(self.ticks - done);
            plan.step(n as usize).map_err(|e| e.to_string())?;
            for (o, &k) in outs.iter_mut().zip(out_index) {
                o.extend_from_slice(plan.output("dut", k).unwrap_or(&[]));
            }
            done += n;
        }
        Ok(outs)
    }
}
