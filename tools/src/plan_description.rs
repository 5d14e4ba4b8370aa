//! What `evflow check` shows of a graph file's runs, computed here and
//! printed by the command: every run of a sweep validated, the first
//! run's plan as an offline run will execute it (each node's rate, what
//! feeds its inputs and the units of its outputs, or the constant that
//! replaces it; what is left out and why), and what building each run's
//! plan found (what the nodes loaded, what they then found constant).

use crate::batch::sweep_runs::sweep_runs;
use evflow_engine::batch::Failures;
use evflow_engine::check::prune::{Folded, Pruning};
use evflow_engine::check::Pruned;
use evflow_engine::graph::{Axis, Graph};
use evflow_engine::rate::Ratio;
use evflow_engine::sweep::{validate, Point};
use evflow_engine::{Checked, Direction, Override, Plan, PlanOptions};
use std::path::Path;

/// The runs a graph file makes with `--set` and `--sweep`, validated.
#[derive(Debug)]
pub struct ValidRuns {
    /// The graph as read (before any run's values).
    pub graph: Graph,
    /// The axes swept.
    pub swept: Vec<Axis>,
    /// Runs of the sweep (1 without one).
    pub total: usize,
    /// The runs that validate, in sweep order (at least one).
    pub runs: Vec<(Point, Checked)>,
    /// The runs that do not, with why.
    pub failures: Failures,
}

impl ValidRuns {
    /// True for a sweep of several runs.
    pub fn is_sweep(&self) -> bool {
        self.total > 1
    }
}

/// Reads `file` and validates every run its `--set` values (`overrides`)
/// and `--sweep` axes make, as `evflow run` will (a `[vars]` default that
/// every run overrides is not validated). A run that does not validate is
/// a failure of that run — the error itself when there is one run, or
/// when none validates.
pub fn validate_runs(file: &Path, overrides: &[Override], sweep: &[String]) -> Result<ValidRuns, String> {
    let (graph, swept, all) = sweep_runs(file, overrides, sweep)?;
    let total = all.len();
    let registry = evflow_nodes::registry();
    let mut failures = Failures::new();
    let mut runs: Vec<(Point, Checked)> = Vec::with_capacity(total);
    for v in validate(&graph, &registry, overrides, all, 0..total) {
        match v.checked {
            Ok(c) => runs.push((v.point, c)),
            Err(e) if total <= 1 => return Err(e.to_string()),
            Err(e) => failures.push(v.point.label(), e),
        }
    }
    if runs.is_empty() {
        return Err(format!(
            "no run of the sweep validates: {}",
            failures.summary_as(total, "sweep runs", "fail").trim_end()
        ));
    }
    Ok(ValidRuns { graph, swept, total, runs, failures })
}

/// One node of a plan.
#[derive(Debug, Clone)]
pub struct PlanNode {
    /// Its name.
    pub name: String,
    /// Its type.
    pub type_name: &'static str,
    /// What it does in the plan.
    pub role: PlanRole,
}

/// What a node of a plan does.
#[derive(Debug, Clone)]
pub enum PlanRole {
    /// It is held at a constant (never run), for this reason.
    Constant(String),
    /// It runs.
    Runs {
        /// At this rate, Hz.
        hz: f64,
        /// That is, this ratio to the base rate.
        ratio: Ratio,
        /// What feeds each connected input: `port←node.port`.
        inputs: Vec<String>,
        /// Each output with its unit: `port [unit]`.
        outputs: Vec<String>,
    },
}

/// A checked graph's plan, before anything is built.
#[derive(Debug, Clone)]
pub struct PlanDescription {
    /// The nodes the plan keeps, in execution order.
    pub nodes: Vec<PlanNode>,
    /// The graph's nodes.
    pub of: usize,
    /// Nodes replaced by constants, with their values and why.
    pub folded: Vec<Folded>,
    /// Nodes left out (never constructed), and why.
    pub pruned: Vec<Pruned>,
    /// The nodes that break feedback cycles.
    pub cycles: Vec<String>,
}

impl PlanDescription {
    /// The plan of `c` that `pruning` (of an offline run) gives.
    pub fn new(c: &Checked, pruning: &Pruning<'_>) -> Self {
        let rate = c.graph.rate;
        let nodes = pruning
            .order()
            .into_iter()
            .map(|i| {
                let n = &c.nodes[i];
                let role = match pruning.constant(i) {
                    Some(k) => PlanRole::Constant(k.reason.clone()),
                    None => PlanRole::Runs {
                        hz: n.ratio.hz(rate),
                        ratio: n.ratio,
                        inputs: inputs(c, i),
                        outputs: (n.ports.iter().enumerate())
                            .filter(|(_, p)| p.dir == Direction::Out)
                            .map(|(k, p)| format!("{} [{}]", p.name, evflow_engine::check::units::output_unit(c, i, k)))
                            .collect(),
                    },
                };
                PlanNode { name: n.name.clone(), type_name: n.spec.name, role }
            })
            .collect();
        PlanDescription {
            nodes,
            of: c.nodes.len(),
            folded: pruning.folded(),
            pruned: pruning.pruned(),
            cycles: c.in_cycle.iter().map(|&i| c.nodes[i].name.clone()).collect(),
        }
    }
}

/// What feeds each connected input of node `i`: `port←node.port`.
fn inputs(c: &Checked, i: usize) -> Vec<String> {
    let n = &c.nodes[i];
    c.edges
        .iter()
        .filter(|e| e.to.0 == i)
        .map(|e| {
            format!("{}←{}.{}", n.ports[e.to.1].name, c.nodes[e.from.0].name, c.nodes[e.from.0].ports[e.from.1].name)
        })
        .collect()
}

/// What building a run's plan found beyond what checking it did.
#[derive(Debug, Clone)]
pub struct Built {
    /// The run's label (`mass=60 speed=3`; empty without a sweep).
    pub run: String,
    /// Nodes built.
    pub nodes: usize,
    /// The buffers' block, base ticks.
    pub block: usize,
    /// What each node said it loaded, by node.
    pub notes: Vec<(String, Vec<String>)>,
    /// Nodes found constant once built.
    pub folded: Vec<Folded>,
    /// Nodes left out once built.
    pub pruned: Vec<Pruned>,
}

/// Builds the plan of every run as `evflow run` would, running nothing:
/// the first one built, described against `pruning` (the first run's
/// plan before building). A run whose plan does not build is a failure
/// of that run, or the error itself outside a sweep.
pub fn build_runs(
    runs: &[(Point, Checked)],
    pruning: &Pruning<'_>,
    is_sweep: bool,
    failures: &mut Failures,
) -> Result<Option<Built>, String> {
    let opts = PlanOptions { check_only: true, ..PlanOptions::default() };
    let mut first = None;
    for (p, c) in runs {
        let plan = match Plan::build(c, &opts) {
            Ok(plan) => plan,
            Err(e) if !is_sweep => return Err(e.to_string()),
            Err(e) => {
                failures.push(p.label(), e);
                continue;
            }
        };
        if first.is_none() {
            first = Some(built(&plan, pruning, if is_sweep { p.label() } else { String::new() }));
        }
    }
    Ok(first)
}

/// What building `plan` found beyond `pruning`.
fn built(plan: &Plan, pruning: &Pruning<'_>, run: String) -> Built {
    let before = pruning.folded();
    let folded = plan.folded().iter().filter(|f| !before.iter().any(|b| b.node == f.node)).cloned().collect();
    let before = pruning.pruned();
    let pruned = plan.pruned().iter().filter(|p| !before.iter().any(|b| b.node == p.node)).cloned().collect();
    Built { run, nodes: plan.schedule().len(), block: plan.max_block(), notes: plan.notes().to_vec(), folded, pruned }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graphs() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("graphs")
    }

    #[test]
    fn a_sweep_keeps_the_runs_that_validate_and_names_the_others() {
        let file = graphs().join("excitation.toml");
        let v = validate_runs(&file, &[], &["mass=60,-5".into()]).unwrap();
        assert!(v.is_sweep());
        assert_eq!((v.total, v.runs.len()), (2, 1));
        assert_eq!(v.failures.list.len(), 1);
        assert_eq!(v.failures.list[0].0, "mass=-5");
        let none = validate_runs(&file, &[], &["mass=-5,-6".into()]).unwrap_err();
        assert!(none.starts_with("no run of the sweep validates: "), "{none}");
        let one = validate_runs(&file, &[], &["mass=-5".into()]).unwrap_err();
        assert!(!one.starts_with("no run"), "one run's error is its own: {one}");
    }

    #[test]
    fn the_plan_lists_each_node_kept_with_its_rate_inputs_and_units_and_building_adds_what_was_loaded() {
        let v = validate_runs(&graphs().join("mesh-live.toml"), &[], &[]).unwrap();
        let c = &v.runs[0].1;
        let pruning = Pruning::new(c, true, true).unwrap();
        let plan = PlanDescription::new(c, &pruning);
        assert_eq!((plan.nodes.len(), plan.of), (9, 9));
        let limit = plan.nodes.iter().find(|n| n.name == "limit").unwrap();
        let PlanRole::Runs { hz, inputs, outputs, .. } = &limit.role else { panic!("limit runs") };
        assert_eq!((*hz, inputs.as_slice()), (1000.0, ["in←gain.out".to_string()].as_slice()));
        assert_eq!(outputs, &["out [1]", "state [1]"]);
        let mut failures = Failures::new();
        let built = build_runs(&v.runs, &pruning, false, &mut failures).unwrap().unwrap();
        assert!(failures.is_empty() && built.run.is_empty());
        assert!(built.notes.iter().any(|(node, _)| node == "surface"), "the mesh says what it loaded");
        assert!(built.folded.iter().any(|f| f.node == "edges"), "edges without sharp edges fold when built");
    }
}
