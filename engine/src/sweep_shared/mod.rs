//! Shared sweeps: the points of a sweep run as one plan, the work that is
//! the same at every point done once.
//!
//! A sweep ([`crate::sweep`]) runs a graph once per point. Often most of
//! the graph does not depend on the swept values: a gain sweep repeats
//! every synthesis before the gain node only to scale its output. [`merge`]
//! takes the graph checked at each point and builds one graph in which a
//! node is **shared** when its type, parameters and ports are the same at
//! every point and every node feeding it is shared; every other node (one
//! whose parameters differ, and everything downstream of one) is
//! **copied** once per point, each copy with that point's parameters and
//! fed by the shared nodes or by its own point's copies.
//!
//! Each copy is named `NODE@K` (K the point's index) but is built under
//! its original's name ([`crate::check::CheckedNode::origin`]), so it seeds,
//! labels and writes exactly as the node of a run of that point alone. The
//! merged run is the same arithmetic on the same samples as the separate
//! runs: [`Merged::report`] gives each point's report as its own run would
//! have given it (the same summaries under the same names; the shared
//! nodes' times are counted in each point's).
//!
//! Points whose graphs differ in structure (nodes, connections, what is
//! pruned, the base rate, the run length or the seed) cannot be merged;
//! [`merge`] says why, and the caller runs them one by one.

use crate::check::{Checked, CheckedNode, Edge, Pruned};
use crate::run::RunReport;

/// The points' graphs as one, and where each point's nodes are.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The merged graph, ready to plan.
    pub checked: Checked,
    /// The number of points.
    points: usize,
    /// For each copied node: its original name, then its copies' names by point.
    copies: Vec<(String, Vec<String>)>,
}

/// Why points could not be merged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the sweep's points cannot share one run: {0}")]
pub struct MergeError(pub String);

/// The name of node `name`'s copy for point `k` (a graph's node names
/// hold letters, digits, `_` and `-` only, so no copy's name is a node's).
pub fn copy_name(name: &str, k: usize) -> String {
    format!("{name}@{k}")
}

fn same_node(a: &CheckedNode, b: &CheckedNode) -> bool {
    a.name == b.name
        && std::ptr::eq(a.spec, b.spec)
        && a.params == b.params
        && a.ratio == b.ratio
        && a.ports.len() == b.ports.len()
        && a.ports.iter().zip(&b.ports).all(|(p, q)| {
            p.name == q.name && p.dir == q.dir && p.unit == q.unit && p.rate == q.rate && p.ratio == q.ratio
        })
}

/// Why `c` (point `k`) differs in structure from `first`, if it does.
fn structure(first: &Checked, c: &Checked, k: usize) -> Result<(), MergeError> {
    let (g, h) = (&first.graph, &c.graph);
    let what = if c.nodes.len() != first.nodes.len() || c.nodes.iter().zip(&first.nodes).any(|(a, b)| a.name != b.name)
    {
        Some("its nodes")
    } else if c.edges != first.edges {
        Some("its connections")
    } else if c.order != first.order || c.pruned != first.pruned || c.in_cycle != first.in_cycle {
        Some("what it leaves out")
    } else if g.rate.to_bits() != h.rate.to_bits() {
        Some("its base rate")
    } else if g.duration.map(f64::to_bits) != h.duration.map(f64::to_bits) {
        Some("its run length")
    } else if g.seed != h.seed {
        Some("its seed")
    } else {
        None
    };
    match what {
        Some(w) => Err(MergeError(format!("point {k} differs from point 0 in {w}"))),
        None => Ok(()),
    }
}

/// Merges the graph checked at each of `points` (in point order) into one.
pub fn merge(points: &[Checked]) -> Result<Merged, MergeError> {
    let first = points.first().ok_or_else(|| MergeError("a sweep of no points".into()))?;
    for (k, c) in points.iter().enumerate().skip(1) {
        structure(first, c, k)?;
    }
    let n = first.nodes.len();
    // A node is copied when it differs between points, or something feeding it is copied.
    let mut copied: Vec<bool> =
        (0..n).map(|i| points.iter().any(|c| !same_node(&c.nodes[i], &first.nodes[i]))).collect();
    loop {
        let mut changed = false;
        for e in &first.edges {
            if copied[e.from.0] && !copied[e.to.0] {
                copied[e.to.0] = true;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    // The merged nodes: each shared node once, each copied node once per point, in file order.
    let mut nodes = Vec::new();
    let mut at: Vec<Vec<usize>> = Vec::with_capacity(n);
    let mut copies = Vec::new();
    for (i, &copy) in copied.iter().enumerate() {
        if copy {
            let mut names = Vec::with_capacity(points.len());
            let mut idx = Vec::with_capacity(points.len());
            for (k, c) in points.iter().enumerate() {
                let mut node = c.nodes[i].clone();
                node.name = copy_name(&node.name, k);
                names.push(node.name.clone());
                idx.push(nodes.len());
                nodes.push(node);
            }
            copies.push((first.nodes[i].name.clone(), names));
            at.push(idx);
        } else {
            at.push(vec![nodes.len()]);
            nodes.push(first.nodes[i].clone());
        }
    }
    let each = |i: usize| -> Vec<usize> { at[i].clone() };
    let of = |i: usize, k: usize| if at[i].len() == 1 { at[i][0] } else { at[i][k] };
    let mut edges = Vec::new();
    for e in &first.edges {
        let per_point = if copied[e.to.0] { points.len() } else { 1 };
        for k in 0..per_point {
            edges.push(Edge { from: (of(e.from.0, k), e.from.1), to: (of(e.to.0, k), e.to.1) });
        }
    }
    let order = first.order.iter().flat_map(|&i| each(i)).collect();
    let in_cycle = first.in_cycle.iter().flat_map(|&i| each(i)).collect();
    let mut pruned = Vec::new();
    for p in &first.pruned {
        match copies.iter().find(|(name, _)| *name == p.node) {
            Some((_, names)) => {
                pruned.extend(names.iter().map(|m| Pruned { node: m.clone(), reason: p.reason.clone() }))
            }
            None => pruned.push(p.clone()),
        }
    }
    let checked = Checked { graph: first.graph.clone(), nodes, edges, order, pruned, in_cycle };
    Ok(Merged { checked, points: points.len(), copies })
}

impl Merged {
    /// The number of points.
    pub fn points(&self) -> usize {
        self.points
    }

    /// The original names of the copied nodes (those that differ between
    /// points or are fed by one that does), in file order.
    pub fn copied(&self) -> impl Iterator<Item = &str> {
        self.copies.iter().map(|(n, _)| n.as_str())
    }

    /// Point `k`'s share of the merged run `r`: the shared nodes and point
    /// `k`'s copies under their original names, in run order (their times,
    /// summaries and what the plan left out); the other points' copies
    /// left out.
    pub fn report(&self, r: &RunReport, k: usize) -> RunReport {
        let name = |node: &str| -> Option<String> {
            match self.copies.iter().find(|(_, names)| names.iter().any(|m| m == node)) {
                Some((orig, names)) => (names[k] == node).then(|| orig.clone()),
                None => Some(node.to_string()),
            }
        };
        let times = r
            .times
            .iter()
            .filter_map(|t| name(&t.node).map(|node| crate::plan::NodeTime { node, ..t.clone() }))
            .collect();
        let summaries = r.summaries.iter().filter_map(|(n, s)| name(n).map(|n| (n, s.clone()))).collect();
        // The lines name their node first, in backticks: another point's copies' lines go.
        let left_out = r
            .left_out
            .iter()
            .filter(|line| line.split('`').nth(1).is_none_or(|node| name(node).is_some()))
            .map(|line| {
                let mut line = line.clone();
                for (orig, names) in &self.copies {
                    line = line.replace(&format!("`{}`", names[k]), &format!("`{orig}`"));
                }
                line
            })
            .collect();
        RunReport { ticks: r.ticks, base_rate: r.base_rate, elapsed: r.elapsed, times, summaries, left_out }
    }
}

#[cfg(test)]
mod tests;
