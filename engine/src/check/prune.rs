//! Leaving out what a plan does not need — the one place that decides it
//! (`docs/pruning.md`).
//!
//! A node enters a plan when a sink needs it: it is a sink, or it feeds a
//! node in the plan that reads its inputs. A node whose output is a
//! constant for this plan reads no input: it enters the plan as that
//! constant (its output buffers hold the value; it is never stepped), and
//! what fed only it is left out — never built, its files never opened.
//!
//! Constness is decided in two steps, in an order that lets nodes upstream
//! of a constant be skipped before they load anything:
//!
//! 1. **Before any build**, in the plan's order, every node type's
//!    [`crate::spec::NodeSpec::fold`] is asked with its parameters and the
//!    constant values of its inputs (a constant propagates: `gain` of a
//!    constant, `add` of two constants, …).
//! 2. **While building**, downstream first, each built node is asked
//!    [`crate::node::Node::constant_output`] (what it loaded may make it
//!    constant, e.g. `mesh.edges` on a mesh without sharp edges); when it
//!    answers, the folds run again and the nodes upstream that now feed
//!    only constants are left out before their turn to be built comes.
//!
//! Without constants, the same rule is the sink reachability [`check`]
//! applies to every graph (nodes no sink needs).
//!
//! [`check`]: crate::check::check

use super::{Checked, Edge, Pruned};
use crate::node::{Constant, NodeError};
use crate::spec::{FoldArgs, NodeSpec, Role};
use std::collections::VecDeque;

/// Which nodes a sink needs: `needed[i]`. `is_sink(i)` seeds the search;
/// a node with `reads_inputs(i)` false (a constant) needs none of its
/// producers.
pub(crate) fn needed(
    n: usize,
    edges: &[Edge],
    is_sink: impl Fn(usize) -> bool,
    reads_inputs: impl Fn(usize) -> bool,
) -> Vec<bool> {
    let mut live = vec![false; n];
    let mut queue: VecDeque<usize> = (0..n).filter(|&i| is_sink(i)).collect();
    for &i in &queue {
        live[i] = true;
    }
    while let Some(i) = queue.pop_front() {
        if !reads_inputs(i) {
            continue;
        }
        for e in edges.iter().filter(|e| e.to.0 == i) {
            let j = e.from.0;
            if !live[j] {
                live[j] = true;
                queue.push_back(j);
            }
        }
    }
    live
}

/// True for node types the planner may replace by a constant: never a sink
/// (it has an effect), a hardware output or a safety guard.
pub fn may_fold(spec: &NodeSpec) -> bool {
    spec.role != Role::Sink && !spec.hardware && !spec.is_guard()
}

/// A node replaced by a constant.
#[derive(Debug, Clone, PartialEq)]
pub struct Folded {
    /// The node.
    pub node: String,
    /// Each output port's name and value (`None`: not constant, and read
    /// by no node of the plan).
    pub outputs: Vec<(String, Option<f64>)>,
    /// Why its output is constant.
    pub reason: String,
}

/// The leave-out decision for one plan, as it is being built.
#[derive(Debug, Clone)]
pub struct Pruning<'a> {
    c: &'a Checked,
    settled: bool,
    fold: bool,
    constant: Vec<Option<Constant>>,
    needed: Vec<bool>,
}

impl<'a> Pruning<'a> {
    /// Step 1: every fold of the graph asked, before anything is built.
    /// `settled`: the plan takes no live parameter changes (folds may read
    /// live parameters); `fold`: false leaves nothing out for being
    /// constant (only what no sink needs). An invalid constant (wrong
    /// number of outputs, not finite) is an error of that node.
    pub fn new(c: &'a Checked, settled: bool, fold: bool) -> Result<Self, (usize, NodeError)> {
        let n = c.nodes.len();
        let mut p = Self { c, settled, fold, constant: vec![None; n], needed: Vec::new() };
        p.propagate()?;
        Ok(p)
    }

    /// Step 2: node `i`, just built, declared its output constant.
    pub fn declare(&mut self, i: usize, k: Constant) -> Result<(), (usize, NodeError)> {
        if !self.fold || !may_fold(self.c.nodes[i].spec) {
            return Ok(());
        }
        self.set(i, k)?;
        self.propagate()
    }

    /// True when node `i` enters the plan (built, or as a constant).
    pub fn needed(&self, i: usize) -> bool {
        self.needed[i]
    }

    /// The constant that replaces node `i`, if any.
    pub fn constant(&self, i: usize) -> Option<&Constant> {
        self.constant[i].as_ref()
    }

    /// Nodes in the plan, in execution order.
    pub fn order(&self) -> Vec<usize> {
        self.c.order.iter().copied().filter(|&i| self.needed[i]).collect()
    }

    /// Nodes replaced by constants, in execution order.
    pub fn folded(&self) -> Vec<Folded> {
        self.order()
            .into_iter()
            .filter_map(|i| {
                let k = self.constant[i].as_ref()?;
                let node = &self.c.nodes[i];
                let outputs = node.outputs().map(|p| node.ports[p].name.clone()).zip(k.outputs.iter().copied());
                Some(Folded { node: node.name.clone(), outputs: outputs.collect(), reason: k.reason.clone() })
            })
            .collect()
    }

    /// Every node left out, with why: those no sink needs ([`Checked`]'s),
    /// then those that fed only constants.
    pub fn pruned(&self) -> Vec<Pruned> {
        let mut out = self.c.pruned.clone();
        for &j in &self.c.order {
            if self.needed[j] {
                continue;
            }
            // The constants this node's output reached, through other left-out nodes.
            let mut seen = vec![false; self.c.nodes.len()];
            let mut queue = VecDeque::from([j]);
            let mut reached = Vec::new();
            while let Some(a) = queue.pop_front() {
                for e in self.c.edges.iter().filter(|e| e.from.0 == a) {
                    let b = e.to.0;
                    if std::mem::replace(&mut seen[b], true) {
                        continue;
                    }
                    if self.needed[b] {
                        reached.push(self.c.nodes[b].name.as_str());
                    } else {
                        queue.push_back(b);
                    }
                }
            }
            reached.sort_unstable();
            let reason = match reached.as_slice() {
                [one] => format!("feeds only `{one}`, which is replaced by a constant"),
                many => format!("feeds only `{}`, which are replaced by constants", many.join("`, `")),
            };
            out.push(Pruned { node: self.c.nodes[j].name.clone(), reason });
        }
        out
    }

    fn set(&mut self, i: usize, k: Constant) -> Result<(), (usize, NodeError)> {
        let node = &self.c.nodes[i];
        let n_out = node.outputs().count();
        if k.outputs.len() != n_out {
            let msg = format!("declared {} constant outputs for its {n_out} output ports", k.outputs.len());
            return Err((i, NodeError::Other(msg)));
        }
        if let Some(v) = k.outputs.iter().flatten().find(|v| !v.is_finite()) {
            return Err((i, NodeError::Other(format!("declared a constant output of {v}"))));
        }
        // An output that varies keeps the node when any node reads it.
        let varying_read = node.outputs().zip(&k.outputs).any(|(p, v)| {
            v.is_none() && self.c.edges.iter().any(|e| e.from == (i, p) && self.c.order.contains(&e.to.0))
        });
        if !varying_read {
            self.constant[i] = Some(k);
        }
        Ok(())
    }

    /// Asks every fold in plan order (inputs are decided before their
    /// consumers), then recomputes which nodes are needed.
    fn propagate(&mut self) -> Result<(), (usize, NodeError)> {
        if self.fold {
            for &i in &self.c.order {
                let node = &self.c.nodes[i];
                let Some(fold) = node.spec.fold.filter(|_| self.constant[i].is_none() && may_fold(node.spec)) else {
                    continue;
                };
                let inputs: Vec<Option<f64>> = node.inputs().map(|p| self.input_constant(i, p)).collect();
                let args = FoldArgs::new(node.spec, &node.params, &inputs, node.outputs().count(), self.settled);
                if let Some(k) = fold(&args) {
                    self.set(i, k)?;
                }
            }
        }
        let c = self.c;
        let live = |i: usize| c.order.contains(&i);
        let constant = &self.constant;
        let now = needed(
            c.nodes.len(),
            &c.edges,
            |i| live(i) && c.nodes[i].spec.role == Role::Sink,
            |i| constant[i].is_none(),
        );
        self.needed = now;
        Ok(())
    }

    /// The constant value input port `p` of node `i` receives, if its
    /// producer is a constant.
    fn input_constant(&self, i: usize, p: usize) -> Option<f64> {
        let e = self.c.edges.iter().find(|e| e.to == (i, p))?;
        let producer = &self.c.nodes[e.from.0];
        let k = self.constant[e.from.0].as_ref()?;
        let index = producer.outputs().position(|q| q == e.from.1)?;
        k.outputs.get(index).copied().flatten()
    }
}

#[cfg(test)]
#[path = "prune_tests.rs"]
pub(crate) mod tests;
