//! [`Plan::build_with`]'s steps: construct the needed nodes (downstream
//! first, folding constants), choose the block size, lay out the buffer
//! slots, wire the entries, allocate the pool and prepare the nodes.

use super::{Entry, Folding, Held, NodeFailure, Plan, PlanOptions, MAX_BUFFER_SAMPLES, MAX_POOL_SAMPLES};
use crate::check::prune::Pruning;
use crate::check::Checked;
use crate::node::{BuildContext, Node, NodeError, PrepareContext, RunMode};
use crate::rate::{lcm, Ratio};
use std::time::{Duration, Instant};

/// One plan's construction: the checked graph and how to build it.
struct Builder<'a> {
    checked: &'a Checked,
    opts: &'a PlanOptions,
    folding: Folding,
    /// Whether the plan takes live changes (folds may not read them).
    takes_changes: bool,
}

/// The nodes constructed, by node index, before they are wired.
struct Built {
    /// The constructed node, where it is needed and not constant.
    nodes: Vec<Option<Box<dyn Node>>>,
    /// Time each took to build (with `timing`).
    setup: Vec<Duration>,
    /// Each node's notes, by node index.
    notes: Vec<(usize, Vec<String>)>,
}

/// Where the plan's nodes and buffers go.
struct Layout {
    /// The nodes in the plan, in run order.
    order: Vec<usize>,
    /// The block is a multiple of this many base ticks (every divided rate).
    unit: u64,
    /// The slot of each output of each node in the plan.
    slot_of: Vec<Vec<usize>>,
    /// The number of slots.
    n_slots: usize,
}

/// See [`Plan::build_with`].
pub(super) fn build(checked: &Checked, opts: &PlanOptions, folding: Folding) -> Result<Plan, Box<NodeFailure>> {
    let takes_changes = folding == Folding::Changes || opts.mode == RunMode::Live;
    let b = Builder { checked, opts, folding, takes_changes };
    let mut pruning = Pruning::new(checked, !takes_changes, folding != Folding::Off).map_err(|(i, e)| b.fail(i, e))?;
    let mut built = b.construct(&mut pruning)?;
    let order = pruning.order();
    built.notes.retain(|(i, _)| pruning.needed(*i));
    built.notes.sort_by_key(|(i, _)| order.iter().position(|j| j == i));
    let unit = block_unit(checked, &order);
    let mut max_block = b.block_by_memory(&order, unit)?;
    let layout = slots(checked, order, unit);
    let (mut entries, late) = b.entries(&layout, &pruning, &mut built, &mut max_block)?;
    let pool = pool(&entries, max_block, layout.n_slots);
    b.prepare(&mut entries, &layout.order, max_block)?;
    let g = &checked.graph;
    let mut plan = Plan {
        name: g.name.clone(),
        file: g.file.clone(),
        base_rate: g.rate,
        entries,
        late,
        pool,
        tick: 0,
        max_block: max_block as usize,
        timing: opts.timing,
        pruned: pruning.pruned(),
        folded: pruning.folded(),
        notes: built.notes.into_iter().map(|(i, l)| (checked.nodes[i].name.clone(), l)).collect(),
        duration: g.duration,
        mode: opts.mode,
    };
    plan.hold_constants();
    Ok(plan)
}

impl Builder<'_> {
    /// The failure of node `i`.
    fn fail(&self, i: usize, error: NodeError) -> Box<NodeFailure> {
        let n = &self.checked.nodes[i];
        let g = &self.checked.graph;
        Box::new(NodeFailure { file: g.file.clone(), loc: n.loc, node: n.name.clone(), kind: n.spec.name, error })
    }

    /// Builds the needed nodes, downstream first: a node that turns out
    /// constant leaves out its upstream before that is built.
    fn construct(&self, pruning: &mut Pruning) -> Result<Built, Box<NodeFailure>> {
        let (checked, opts) = (self.checked, self.opts);
        let g = &checked.graph;
        let base_dir =
            opts.base_dir.clone().unwrap_or_else(|| g.file.parent().map(|p| p.to_path_buf()).unwrap_or_default());
        let seed = opts.seed.unwrap_or(g.seed);
        let n_nodes = checked.nodes.len();
        let mut built = Built {
            nodes: (0..n_nodes).map(|_| None).collect(),
            setup: vec![Duration::ZERO; n_nodes],
            notes: Vec::new(),
        };
        let mut folded = Vec::new();
        for &i in checked.order.iter().rev() {
            if !pruning.needed(i) || pruning.constant(i).is_some() {
                continue;
            }
            let n = &checked.nodes[i];
            let ctx = BuildContext {
                node: n.origin.clone(),
                base_rate: g.rate,
                rate: n.ratio.hz(g.rate),
                input_rates: n.inputs().map(|p| n.ports[p].ratio.hz(g.rate)).collect(),
                output_rates: n.outputs().map(|p| n.ports[p].ratio.hz(g.rate)).collect(),
                base_dir: base_dir.clone(),
                out_dir: opts.out_dir.clone().unwrap_or_default(),
                seed,
                check_only: opts.check_only,
            };
            let started = Instant::now();
            let node = (n.spec.build)(&n.params, &ctx).map_err(|e| self.fail(i, e))?;
            let constant = if self.folding == Folding::Off { None } else { node.constant_output() };
            if opts.timing {
                built.setup[i] = started.elapsed();
            }
            let lines = node.notes();
            if !lines.is_empty() {
                built.notes.push((i, lines));
            }
            if let Some(k) = constant {
                pruning.declare(i, k).map_err(|(j, e)| self.fail(j, e))?;
            }
            if pruning.constant(i).is_none() {
                built.nodes[i] = Some(node);
            } else {
                folded.push(node);
            }
        }
        // The nodes folded into constants go only now: a node built after one
        // may share what it loaded (`mesh.gradient` the scenes of a
        // `mesh.edges` held constant on smooth scenes), built once that way.
        drop(folded);
        Ok(built)
    }

    /// The largest block (base ticks, a multiple of `unit`) that `--block`
    /// asks for and memory allows: every buffer holds one block of its
    /// port's rate, so a port at many samples per base tick (a fast node in
    /// a graph of a slow base rate) or a huge `--block` would ask for
    /// gigabytes. The block shrinks to fit (down to `unit`); a graph whose
    /// smallest block does not fit is refused, naming the fastest node.
    fn block_by_memory(&self, order: &[usize], unit: u64) -> Result<u64, Box<NodeFailure>> {
        let checked = self.checked;
        let requested = (self.opts.max_block.max(1) as u64).div_ceil(unit).saturating_mul(unit);
        let per_tick = |r: &Ratio| if r.div == 1 { r.mul as f64 } else { 1.0 / r.div as f64 };
        let (mut widest, mut total) = (None::<(usize, f64)>, 0.0);
        for &i in order {
            for p in checked.nodes[i].outputs() {
                let w = per_tick(&checked.nodes[i].ports[p].ratio);
                total += w;
                if widest.is_none_or(|(_, x)| w > x) {
                    widest = Some((i, w));
                }
            }
        }
        let fits = |samples_per_tick: f64, limit: usize| {
            if samples_per_tick > 0.0 {
                (limit as f64 / samples_per_tick).floor()
            } else {
                f64::INFINITY
            }
        };
        let by_memory = fits(widest.map_or(0.0, |w| w.1), MAX_BUFFER_SAMPLES).min(fits(total, MAX_POOL_SAMPLES));
        let by_memory = (by_memory.min(u64::MAX as f64) as u64) / unit * unit;
        if by_memory < unit {
            let (i, w) = widest.unwrap_or((order.first().copied().unwrap_or(0), 0.0));
            return Err(self.fail(
                i,
                NodeError::Other(format!(
                    "this node makes {w} samples per base tick of the graph's {} Hz, and the smallest block the \
                     graph's rates allow is {unit} base ticks: its buffers would need {:.3e} samples, more than the \
                     {MAX_BUFFER_SAMPLES} (128 MiB) a buffer may hold ({MAX_POOL_SAMPLES} for all); raise [graph] rate",
                    checked.graph.rate,
                    w * unit as f64
                )),
            ));
        }
        Ok(requested.min(by_memory))
    }

    /// The plan's entries in run order, wired to their slots, and which of
    /// them are split feedback nodes (run late); shrinks `max_block` to
    /// within every feedback delay.
    fn entries(
        &self,
        layout: &Layout,
        pruning: &Pruning,
        built: &mut Built,
        max_block: &mut u64,
    ) -> Result<(Vec<Entry>, Vec<usize>), Box<NodeFailure>> {
        let checked = self.checked;
        let unit = layout.unit;
        let mut entries = Vec::with_capacity(layout.order.len());
        let mut late = Vec::new();
        for &i in &layout.order {
            let n = &checked.nodes[i];
            let held = pruning.constant(i).map(|k| k.outputs.clone());
            let node: Box<dyn Node> = match (&held, built.nodes[i].take()) {
                (None, Some(node)) => node,
                (None, None) => return Err(self.fail(i, NodeError::Other("the planner lost this node".into()))),
                (Some(_), _) => Box::new(Held { takes_changes: self.takes_changes }),
            };
            let (in_slots, in_ratios) =
                if held.is_none() { inputs(checked, i, &layout.slot_of) } else { Default::default() };
            let out_ratios: Vec<Ratio> = n.outputs().map(|p| n.ports[p].ratio).collect();
            let split = held.is_none() && checked.in_cycle.contains(&i);
            if split {
                let d = node.cycle_delay() as u64;
                let limit = if n.ratio.div == 1 { d / n.ratio.mul } else { d * n.ratio.div };
                if limit < unit {
                    return Err(self.fail(i, NodeError::Other(format!("this feedback delay of {d} samples is shorter than the smallest block the graph's rates allow ({unit} base ticks)"))));
                }
                *max_block = (*max_block).min(limit / unit * unit);
                late.push(entries.len());
            }
            entries.push(Entry {
                name: n.name.clone(),
                kind: n.spec.name,
                spec: n.spec,
                out_names: n.outputs().map(|p| n.ports[p].name.clone()).collect(),
                in_unit: crate::check::units::input_unit(checked, i),
                loc: n.loc,
                node,
                ratio: n.ratio,
                in_lens: vec![0; in_slots.len()],
                in_slots,
                in_ratios,
                out_lens: vec![0; out_ratios.len()],
                scratch: (0..out_ratios.len()).map(|_| Vec::new()).collect(),
                out_slots: layout.slot_of[i].clone(),
                out_ratios,
                split,
                held,
                setup: built.setup[i],
                elapsed: Duration::ZERO,
                finishing: Duration::ZERO,
            });
        }
        Ok((entries, late))
    }

    /// Prepares every node that runs for the largest block of its ports.
    fn prepare(&self, entries: &mut [Entry], order: &[usize], max_block: u64) -> Result<(), Box<NodeFailure>> {
        for (k, e) in entries.iter_mut().enumerate() {
            if e.held.is_some() {
                continue;
            }
            let largest = e
                .in_ratios
                .iter()
                .chain(&e.out_ratios)
                .map(|r| cap(max_block, r))
                .max()
                .unwrap_or(cap(max_block, &e.ratio));
            let started = Instant::now();
            e.node.prepare(&PrepareContext { max_block: largest, mode: self.opts.mode }).map_err(|err| {
                let i = order[k];
                self.fail(i, err)
            })?;
            if self.opts.timing {
                e.setup += started.elapsed();
            }
        }
        Ok(())
    }
}

/// The block size's unit: a multiple of every divided rate of the nodes
/// in `order`.
fn block_unit(checked: &Checked, order: &[usize]) -> u64 {
    let mut unit = 1u64;
    for &i in order {
        for p in &checked.nodes[i].ports {
            unit = lcm(unit, p.ratio.div);
        }
    }
    unit
}

/// Slots: one per output of each node in the plan.
fn slots(checked: &Checked, order: Vec<usize>, unit: u64) -> Layout {
    let mut slot_of = vec![Vec::new(); checked.nodes.len()];
    let mut n_slots = 0;
    for &i in &order {
        slot_of[i] = checked.nodes[i]
            .outputs()
            .map(|_| {
                n_slots += 1;
                n_slots - 1
            })
            .collect();
    }
    Layout { order, unit, slot_of, n_slots }
}

/// The slots node `i`'s inputs read (its producers' outputs) and their
/// ratios.
fn inputs(checked: &Checked, i: usize, slot_of: &[Vec<usize>]) -> (Vec<usize>, Vec<Ratio>) {
    let n = &checked.nodes[i];
    let mut in_slots = Vec::new();
    let mut in_ratios = Vec::new();
    for p in n.inputs() {
        let e = checked.edges.iter().find(|e| e.to == (i, p)).expect("validated: every input has a producer");
        let out_index =
            checked.nodes[e.from.0].outputs().position(|q| q == e.from.1).expect("producer port is an output");
        in_slots.push(slot_of[e.from.0][out_index]);
        in_ratios.push(n.ports[p].ratio);
    }
    (in_slots, in_ratios)
}

/// Samples a buffer at ratio `r` holds for a block of `max_block` base
/// ticks.
fn cap(max_block: u64, r: &Ratio) -> usize {
    (if r.div == 1 { max_block * r.mul } else { max_block.div_ceil(r.div) }) as usize
}

/// The buffer pool: one buffer per slot, sized for a block.
fn pool(entries: &[Entry], max_block: u64, n_slots: usize) -> Vec<Vec<f64>> {
    let mut pool = vec![Vec::new(); n_slots];
    for e in entries {
        for (s, r) in e.out_slots.iter().zip(&e.out_ratios) {
            pool[*s] = vec![0.0; cap(max_block, r)];
        }
    }
    pool
}
