//! The offline driver: runs a plan over its finite sources as fast as the
//! machine allows, in large blocks, single-threaded and deterministic.

use crate::node::Summary;
use crate::plan::{NodeFailure, NodeTime, Plan};
use std::time::{Duration, Instant};

/// Why an offline run could not run or did not finish.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// No finite source and no duration: the run would never end.
    #[error("graph `{0}` has only endless sources; set `duration` in [graph] or pass --duration")]
    Endless(String),
    /// A node failed.
    #[error(transparent)]
    Node(#[from] Box<NodeFailure>),
    /// A run length that is not a positive number of seconds up to [`MAX_DURATION_S`].
    #[error("a run of {0} s: {why}", why = duration_problem(*.0))]
    Duration(f64),
    /// Stopped by the caller (e.g. Ctrl-C); sinks were not finished, so no
    /// partial output was kept.
    #[error("interrupted after {0} base ticks; no output was written")]
    Interrupted(u64),
}

/// What an offline run did.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Base ticks run.
    pub ticks: u64,
    /// The base rate in Hz (ticks per second of signal).
    pub base_rate: f64,
    /// Wall-clock time of the processing loop.
    pub elapsed: Duration,
    /// Time per node.
    pub times: Vec<NodeTime>,
    /// What each node reported at the end (metrics, files written).
    pub summaries: Vec<(String, Summary)>,
    /// What the plan held constant or left out, and why, one line each
    /// (docs/pruning.md) — for people; tables and merges leave it out.
    pub left_out: Vec<String>,
}

impl RunReport {
    /// Base ticks per second of wall-clock time.
    pub fn ticks_per_second(&self) -> f64 {
        self.ticks as f64 / self.elapsed.as_secs_f64().max(1e-12)
    }
    /// A summary value by node and name.
    pub fn value(&self, node: &str, name: &str) -> Option<f64> {
        self.summaries.iter().find(|(n, _)| n == node)?.1.values.iter().find(|(k, _, _)| k == name).map(|(_, v, _)| *v)
    }
}

/// Options of an offline run.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Run length in seconds (overrides the graph's `duration`; finite
    /// sources still end the run early).
    pub duration: Option<f64>,
    /// Called after each block with (ticks done, ticks in all); returning
    /// `false` stops the run.
    pub progress: Option<&'a mut dyn FnMut(u64, u64) -> bool>,
}

/// The longest run length the engine takes, s (as the graph file's `duration`).
pub const MAX_DURATION_S: f64 = 1e7;

fn duration_problem(d: f64) -> &'static str {
    if d.is_nan() {
        "not a number"
    } else if d <= 0.0 {
        "a run length must be positive"
    } else {
        "a run length must be at most 1e7 s (116 days)"
    }
}

/// `d` if it is a run length the engine takes — a positive, finite number of
/// seconds up to [`MAX_DURATION_S`] — else why not (for `--duration`).
pub fn check_duration(d: f64) -> Result<f64, String> {
    if d.is_finite() && d > 0.0 && d <= MAX_DURATION_S {
        Ok(d)
    } else {
        Err(format!("{d} s: {}", duration_problem(d)))
    }
}

/// Runs a plan from t = 0 to the end of its shortest finite source (or the
/// duration), then finishes every node.
pub fn run_offline(plan: &mut Plan, mut opts: RunOptions<'_>) -> Result<RunReport, RunError> {
    if let Some(d) = opts.duration {
        check_duration(d).map_err(|_| RunError::Duration(d))?;
    }
    let by_duration = opts.duration.or(plan.duration()).map(|d| (d * plan.base_rate()).round() as u64);
    let total = match (plan.remaining_ticks(), by_duration) {
        (Some(a), Some(b)) => a.min(b),
        (Some(a), None) => a,
        (None, Some(b)) => b,
        (None, None) => return Err(RunError::Endless(plan.name().to_string())),
    };
    let block = plan.max_block() as u64;
    let started = Instant::now();
    let mut done = 0;
    while done < total {
        let n = block.min(total - done);
        plan.step(n as usize)?;
        done += n;
        if let Some(p) = opts.progress.as_mut() {
            if !p(done, total) {
                return Err(RunError::Interrupted(done));
            }
        }
    }
    let elapsed = started.elapsed();
    let summaries = plan.finish()?;
    let left_out = left_out_lines(plan);
    Ok(RunReport { ticks: done, base_rate: plan.base_rate(), elapsed, times: plan.times(), summaries, left_out })
}

/// One line per node the plan held constant (with its values) or left out.
fn left_out_lines(plan: &Plan) -> Vec<String> {
    let mut lines = Vec::new();
    for f in plan.folded() {
        let values: Vec<String> = f.outputs.iter().filter_map(|(port, v)| v.map(|v| format!("{port} = {v}"))).collect();
        lines.push(format!("held constant `{}` ({}): {}", f.node, values.join(", "), f.reason));
    }
    for p in plan.pruned() {
        lines.push(format!("left out `{}`: {}", p.node, p.reason));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{check, Checked};
    use crate::graph::parse_graph;
    use crate::harness::FEED;
    use crate::node::{BuildContext, Io, Node, NodeError};
    use crate::params::Params;
    use crate::plan::PlanOptions;
    use crate::registry::Registry;
    use crate::spec::{NodeSpec, PortSpec, Role};
    use std::path::Path;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// What the trainer below measured itself, in ns: its build, its finish.
    static BUILD_NS: AtomicU64 = AtomicU64::new(0);
    static FINISH_NS: AtomicU64 = AtomicU64::new(0);

    /// A sink that does its real work when the run ends, as `narx.train`
    /// does: it spins in `finish` (and, less, in `build`) until its own
    /// clock says it is done, and records how long that was.
    static TRAINER: NodeSpec =
        NodeSpec::new("test.trainer", "test", Role::Sink, "works when the run ends (test only)", build_trainer)
            .ports(&[PortSpec::input("in", "1", "anything")]);

    fn spin(least: Duration) -> Duration {
        let t = Instant::now();
        while t.elapsed() < least {
            std::hint::spin_loop();
        }
        t.elapsed()
    }

    fn build_trainer(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        let took = spin(Duration::from_millis(1));
        BUILD_NS.store(took.as_nanos() as u64, Ordering::SeqCst);
        Ok(Box::new(Trainer))
    }

    struct Trainer;

    impl Node for Trainer {
        fn process(&mut self, _io: &mut Io<'_>) -> Result<(), NodeError> {
            Ok(())
        }
        fn reset(&mut self) {}
        fn finish(&mut self) -> Result<Summary, NodeError> {
            let took = spin(Duration::from_millis(5));
            FINISH_NS.store(took.as_nanos() as u64, Ordering::SeqCst);
            Ok(Summary::default())
        }
    }

    /// Three samples fed to the test trainer.
    fn trainer_graph() -> Checked {
        let doc = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000.0\nconnections = [\"f.out -> t.in\"]\n\
                   [nodes.f]\ntype = \"harness.feed\"\nvalues = [1.0, 2.0, 3.0]\n[nodes.t]\ntype = \"test.trainer\"\n";
        let mut reg = Registry::new();
        reg.add(&FEED).add(&TRAINER);
        check(&parse_graph(Path::new("t.toml"), doc).unwrap(), &reg, &[]).unwrap()
    }

    #[test]
    fn a_run_length_must_be_a_positive_finite_number_of_seconds() {
        for bad in [f64::INFINITY, 1e308, 0.0, -1.0, f64::NAN] {
            assert!(check_duration(bad).is_err(), "{bad}");
        }
        assert_eq!(check_duration(2.5), Ok(2.5));
        let checked = trainer_graph();
        let mut plan = Plan::build(&checked, &PlanOptions::default()).unwrap();
        let e = run_offline(&mut plan, RunOptions { duration: Some(f64::INFINITY), progress: None }).unwrap_err();
        assert!(e.to_string().contains("at most 1e7 s"), "{e}");
    }

    #[test]
    fn work_done_when_the_run_ends_is_charged_to_the_node() {
        let checked = trainer_graph();
        let mut plan = Plan::build(&checked, &PlanOptions::default()).unwrap();
        let report = run_offline(&mut plan, RunOptions::default()).unwrap();
        let t = report.times.iter().find(|t| t.node == "t").unwrap();
        // The engine's clock brackets the node's own: whatever the machine
        // does meanwhile, the charged time cannot be less than what the node
        // measured inside its hooks.
        let (build, finish) = (
            Duration::from_nanos(BUILD_NS.load(Ordering::SeqCst)),
            Duration::from_nanos(FINISH_NS.load(Ordering::SeqCst)),
        );
        assert!(t.finish >= finish && finish >= Duration::from_millis(5), "{t:?} vs {finish:?}");
        assert!(t.setup >= build && build >= Duration::from_millis(1), "{t:?} vs {build:?}");
        assert_eq!(t.elapsed, t.setup + t.process + t.finish);
        // Without timing nothing is charged.
        let mut plan = Plan::build(&checked, &PlanOptions { timing: false, ..PlanOptions::default() }).unwrap();
        let report = run_offline(&mut plan, RunOptions::default()).unwrap();
        assert!(report.times.iter().all(|t| t.elapsed.is_zero()));
    }
}
