//! The plan: a validated graph compiled into a flat schedule of constructed
//! nodes and preallocated buffer slots. Both drivers (offline and live) call
//! the same [`Plan::step`].

mod build;

use crate::check::prune::Folded;
use crate::check::{Checked, Pruned};
use crate::diag::Loc;
use crate::node::{Change, Io, Node, NodeError, Refused, RunMode, Summary};
use crate::rate::Ratio;
use crate::spec::NodeSpec;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// The most samples one buffer of a plan may hold: 2²⁴ (128 MiB of f64).
pub const MAX_BUFFER_SAMPLES: usize = 1 << 24;

/// The most samples all the buffers of a plan may hold together: 2²⁷ (1 GiB).
pub const MAX_POOL_SAMPLES: usize = 1 << 27;

/// A node that failed to build, prepare, process or finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}: node `{node}` ({kind}): {error}", file.display(), if loc.line > 0 { format!(":{}", loc.line) } else { String::new() })]
pub struct NodeFailure {
    /// The graph file.
    pub file: PathBuf,
    /// Where the node is declared.
    pub loc: Loc,
    /// The node's name.
    pub node: String,
    /// Its type.
    pub kind: &'static str,
    /// What went wrong.
    pub error: NodeError,
}

/// How to build a plan.
#[derive(Debug, Clone)]
pub struct PlanOptions {
    /// Largest block in base ticks (rounded to what the rates and feedback
    /// delays allow). Live runs use 1.
    pub max_block: usize,
    /// Overrides the graph's seed.
    pub seed: Option<u64>,
    /// Folder relative input paths are taken from (default: the graph file's).
    pub base_dir: Option<PathBuf>,
    /// Folder relative output paths are written to (default: the current directory).
    pub out_dir: Option<PathBuf>,
    /// Measure run time per node.
    pub timing: bool,
    /// Offline (the default, whatever the block size) or live: only a live
    /// plan lets hardware nodes open their devices.
    pub mode: RunMode,
    /// Built only to be checked (`evflow check`), never run: nodes validate
    /// their files as a run would but may leave out what only running needs
    /// ([`BuildContext::check_only`](crate::node::BuildContext::check_only)).
    pub check_only: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            max_block: 4096,
            seed: None,
            base_dir: None,
            out_dir: None,
            timing: true,
            mode: RunMode::Offline,
            check_only: false,
        }
    }
}

struct Entry {
    name: String,
    kind: &'static str,
    spec: &'static NodeSpec,
    out_names: Vec<String>,
    /// The unit of what feeds the first input: the unit of summary values
    /// declared [`crate::ports::SAME_AS_INPUT`].
    in_unit: String,
    loc: Loc,
    node: Box<dyn Node>,
    ratio: Ratio,
    in_slots: Vec<usize>,
    in_ratios: Vec<Ratio>,
    in_lens: Vec<usize>,
    out_slots: Vec<usize>,
    out_ratios: Vec<Ratio>,
    out_lens: Vec<usize>,
    scratch: Vec<Vec<f64>>,
    split: bool,
    /// The output values of a node replaced by a constant (never stepped;
    /// `None`: an output no node reads, held at 0).
    held: Option<Vec<Option<f64>>>,
    /// Time in build and prepare.
    setup: Duration,
    /// Time in process, emit and absorb.
    elapsed: Duration,
    /// Time in finish.
    finishing: Duration,
}

/// Run time of one node: all the work the node did for the run, wherever
/// the node does it — a node that reads its data when built, or trains
/// when the run ends (`narx.train`, `forward.train`), is charged for it.
#[derive(Debug, Clone)]
pub struct NodeTime {
    /// Node name.
    pub node: String,
    /// Node type.
    pub kind: &'static str,
    /// All of it: `setup + process + finish`.
    pub elapsed: Duration,
    /// Time spent building and preparing the node (before the first block).
    pub setup: Duration,
    /// Time spent in `process` (and `emit`/`absorb`).
    pub process: Duration,
    /// Time spent in `finish` when the run ended.
    pub finish: Duration,
}

/// A compiled graph.
pub struct Plan {
    name: String,
    file: PathBuf,
    base_rate: f64,
    entries: Vec<Entry>,
    late: Vec<usize>,
    pool: Vec<Vec<f64>>,
    tick: u64,
    max_block: usize,
    timing: bool,
    pruned: Vec<Pruned>,
    folded: Vec<Folded>,
    notes: Vec<(String, Vec<String>)>,
    duration: Option<f64>,
    mode: RunMode,
}

/// Whether the planner replaces nodes whose output is constant
/// (`docs/pruning.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Folding {
    /// Replace them. Folds may read live parameters unless the plan is
    /// live ([`RunMode::Live`]), which takes changes while it runs.
    #[default]
    On,
    /// Replace them, but take live parameters as changeable although the
    /// plan runs offline: a replay that applies a live session's changes.
    Changes,
    /// Leave nothing out for being constant, only what no sink needs (for
    /// comparisons and benchmarks).
    Off,
}

/// The stand-in of a node replaced by a constant: never stepped (its
/// output buffers hold the value). A live change of a parameter is taken
/// and has no effect when the constant holds for every value the plan lets
/// it take (a live plan, or one built with [`Folding::Changes`]); otherwise
/// it is refused.
struct Held {
    takes_changes: bool,
}

impl Node for Held {
    fn process(&mut self, _io: &mut Io<'_>) -> Result<(), NodeError> {
        Ok(())
    }
    fn reset(&mut self) {}
    fn set(&mut self, change: Change) -> Result<(), Refused> {
        if self.takes_changes {
            Ok(())
        } else {
            Err(change.refused())
        }
    }
}

impl Plan {
    /// Constructs the nodes that survived pruning (and only those), sizes
    /// every buffer, and prepares every node; nodes whose output is
    /// constant for this plan are replaced by the constant, and what fed
    /// only them is never built ([`Folding::On`], `docs/pruning.md`).
    pub fn build(checked: &Checked, opts: &PlanOptions) -> Result<Plan, Box<NodeFailure>> {
        Self::build_with(checked, opts, Folding::On)
    }

    /// [`Plan::build`] with a choice of [`Folding`].
    pub fn build_with(checked: &Checked, opts: &PlanOptions, folding: Folding) -> Result<Plan, Box<NodeFailure>> {
        build::build(checked, opts, folding)
    }

    /// Fills the output buffers of the nodes replaced by constants.
    fn hold_constants(&mut self) {
        for e in &self.entries {
            if let Some(values) = &e.held {
                for (&s, &v) in e.out_slots.iter().zip(values) {
                    self.pool[s].fill(v.unwrap_or(0.0));
                }
            }
        }
    }

    /// Runs `n` base ticks (`1 ≤ n ≤ max_block`). Allocation-free.
    pub fn step(&mut self, n: usize) -> Result<(), Box<NodeFailure>> {
        debug_assert!(n <= self.max_block, "block larger than the plan allows");
        let n = n.min(self.max_block) as u64;
        let t0 = self.tick;
        for k in 0..self.entries.len() {
            let e = &mut self.entries[k];
            let mut any = false;
            for (len, r) in e.in_lens.iter_mut().zip(&e.in_ratios) {
                *len = r.count(t0, n) as usize;
                any |= *len > 0;
            }
            for (len, r) in e.out_lens.iter_mut().zip(&e.out_ratios) {
                *len = r.count(t0, n) as usize;
                any |= *len > 0;
            }
            if (!any && e.ratio.count(t0, n) == 0) || e.held.is_some() {
                continue;
            }
            for (j, &s) in e.out_slots.iter().enumerate() {
                std::mem::swap(&mut self.pool[s], &mut e.scratch[j]);
            }
            let started = self.timing.then(Instant::now);
            let result = {
                let mut io =
                    Io::new(&self.pool, &e.in_slots, &e.in_lens, &mut e.scratch, &e.out_lens, e.ratio.first(t0));
                if e.split {
                    e.node.emit(&mut io)
                } else {
                    e.node.process(&mut io)
                }
            };
            if let Some(s) = started {
                e.elapsed += s.elapsed();
            }
            for (j, &s) in e.out_slots.iter().enumerate() {
                std::mem::swap(&mut self.pool[s], &mut e.scratch[j]);
            }
            if let Err(err) = result {
                return Err(self.failure(k, err));
            }
        }
        for li in 0..self.late.len() {
            let k = self.late[li];
            let e = &mut self.entries[k];
            let mut none: [Vec<f64>; 0] = [];
            let started = self.timing.then(Instant::now);
            let result = {
                let mut io = Io::new(&self.pool, &e.in_slots, &e.in_lens, &mut none, &[], e.ratio.first(t0));
                e.node.absorb(&mut io)
            };
            if let Some(s) = started {
                e.elapsed += s.elapsed();
            }
            if let Err(err) = result {
                return Err(self.failure(k, err));
            }
        }
        self.tick += n;
        Ok(())
    }

    #[cold]
    fn failure(&self, k: usize, error: NodeError) -> Box<NodeFailure> {
        let e = &self.entries[k];
        Box::new(NodeFailure { file: self.file.clone(), loc: e.loc, node: e.name.clone(), kind: e.kind, error })
    }

    /// One base tick (the live runner's step).
    #[inline]
    pub fn tick(&mut self) -> Result<(), Box<NodeFailure>> {
        self.step(1)
    }

    /// Ends the run: every node's `finish`, in plan order (sinks rename their
    /// files here; trainers train). Returns each node's summary, a value
    /// declared in [`crate::ports::SAME_AS_INPUT`] given the unit of what
    /// feeds the node. The time
    /// each `finish` takes is charged to its node ([`Plan::times`]).
    pub fn finish(&mut self) -> Result<Vec<(String, Summary)>, Box<NodeFailure>> {
        let mut out = Vec::new();
        for k in 0..self.entries.len() {
            let started = self.timing.then(Instant::now);
            let result = self.entries[k].node.finish();
            if let Some(s) = started {
                self.entries[k].finishing += s.elapsed();
            }
            match result {
                Ok(mut s) if !s.is_empty() => {
                    for (_, _, unit) in &mut s.values {
                        if unit == crate::ports::SAME_AS_INPUT {
                            unit.clone_from(&self.entries[k].in_unit);
                        }
                    }
                    out.push((self.entries[k].name.clone(), s))
                }
                Ok(_) => {}
                Err(e) => return Err(self.failure(k, e)),
            }
        }
        Ok(out)
    }

    /// Back to t = 0: every node reset, every buffer zeroed, the process
    /// and finish times zeroed (the setup was done once and stays).
    pub fn reset(&mut self) {
        for e in &mut self.entries {
            e.node.reset();
            e.elapsed = Duration::ZERO;
            e.finishing = Duration::ZERO;
        }
        for b in &mut self.pool {
            b.fill(0.0);
        }
        self.hold_constants();
        self.tick = 0;
    }

    /// Base ticks left before the first finite source ends (`None`: all endless).
    pub fn remaining_ticks(&self) -> Option<u64> {
        self.entries.iter().filter_map(|e| e.node.remaining().map(|r| e.ratio.ticks_for(r))).min()
    }

    /// The samples an output port produced in the last step.
    pub fn output(&self, node: &str, port_index: usize) -> Option<&[f64]> {
        let e = self.entries.iter().find(|e| e.name == node)?;
        let s = *e.out_slots.get(port_index)?;
        Some(&self.pool[s][..e.out_lens[port_index]])
    }

    /// Run time of each node so far: setup, processing and finish (see
    /// [`NodeTime`]; all zero when the plan was built without timing).
    pub fn times(&self) -> Vec<NodeTime> {
        self.entries
            .iter()
            .map(|e| NodeTime {
                node: e.name.clone(),
                kind: e.kind,
                elapsed: e.setup + e.elapsed + e.finishing,
                setup: e.setup,
                process: e.elapsed,
                finish: e.finishing,
            })
            .collect()
    }

    /// Nodes in execution order: (name, type, rate in Hz).
    pub fn schedule(&self) -> Vec<(String, &'static str, f64)> {
        self.entries.iter().map(|e| (e.name.clone(), e.kind, e.ratio.hz(self.base_rate))).collect()
    }

    /// Number of nodes in the plan; node indices run over `0..len()` in
    /// execution order.
    pub fn len(&self) -> usize {
        self.entries.len()
    }
    /// True when the plan holds no node.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    /// Index of the node of that name.
    pub fn index(&self, node: &str) -> Option<usize> {
        self.entries.iter().position(|e| e.name == node)
    }
    /// The name of node `k`.
    pub fn node_name(&self, k: usize) -> &str {
        &self.entries[k].name
    }
    /// The declaration of node `k`.
    pub fn spec(&self, k: usize) -> &'static NodeSpec {
        self.entries[k].spec
    }
    /// Names of node `k`'s output ports, in order (`multi` ports expanded).
    pub fn output_names(&self, k: usize) -> &[String] {
        &self.entries[k].out_names
    }
    /// Rate of output `j` of node `k` relative to the base rate.
    pub fn output_ratio(&self, k: usize, j: usize) -> Ratio {
        self.entries[k].out_ratios[j]
    }
    /// The samples output `j` of node `k` produced in the last step
    /// (allocation-free; for the live runner's taps).
    #[inline]
    pub fn output_at(&self, k: usize, j: usize) -> &[f64] {
        let e = &self.entries[k];
        &self.pool[e.out_slots[j]][..e.out_lens[j]]
    }
    /// Applies a live parameter change to node `k` before the next step
    /// ([`Node::set`]); `param` is the declared name. Allocation-free.
    #[inline]
    pub fn set(&mut self, k: usize, param: &'static str, value: f64) -> Result<(), Refused> {
        self.entries[k].node.set(Change { param, value })
    }

    /// Nodes left out, and why: those no sink needs, then those that fed
    /// only nodes replaced by constants.
    pub fn pruned(&self) -> &[Pruned] {
        &self.pruned
    }
    /// Nodes replaced by constants (in the plan, never stepped), with their
    /// values and why.
    pub fn folded(&self) -> &[Folded] {
        &self.folded
    }
    /// True when output `j` of node `k` is held by a node replaced by a
    /// constant but is not constant itself: no node of the plan reads it,
    /// and its buffer holds 0, not what the node would have computed.
    pub fn output_dropped(&self, k: usize, j: usize) -> bool {
        self.entries[k].held.as_ref().is_some_and(|h| h.get(j).is_some_and(Option::is_none))
    }
    /// What the built nodes said about what they loaded
    /// ([`Node::notes`]), by node, in plan order.
    pub fn notes(&self) -> &[(String, Vec<String>)] {
        &self.notes
    }
    /// The graph's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The base rate in Hz.
    pub fn base_rate(&self) -> f64 {
        self.base_rate
    }
    /// How the plan was built to run (see [`RunMode`]).
    pub fn mode(&self) -> RunMode {
        self.mode
    }
    /// The largest block in base ticks.
    pub fn max_block(&self) -> usize {
        self.max_block
    }
    /// Base ticks run since t = 0.
    pub fn ticks(&self) -> u64 {
        self.tick
    }
    /// The graph's `duration` in seconds, if set.
    pub fn duration(&self) -> Option<f64> {
        self.duration
    }
}
