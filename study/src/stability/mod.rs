//! `evflow report stability`: one named suite of extreme and stiff cases
//! over every node type and every shipped graph family (issue 26, point 1;
//! docs/numerics.md).
//!
//! A [`Case`] runs something — a node alone fed extreme inputs or set at
//! the limits of its parameters, a named stiff configuration, a shipped
//! graph — and reports what it saw ([`Observed`]: the largest |output|,
//! how many outputs were NaN or infinite, the error that stopped it, a
//! measured value or series). Its [`Invariant`] judges that into a
//! [`Verdict`]; a panic is caught and fails the case. [`run`] runs the
//! suite into [`Row`]s, [`table`] prints them.
//!
//! The cases come from three places: [`generated`] (from every `NodeSpec`
//! of the registry, so a new node type is covered without a line here),
//! [`stiff`] (the named stiff cases of the issue) and [`graphs`] (one case
//! per shipped graph family). [`bounds`] reads what a node type declares
//! beyond its ports and parameters: an output bound tighter than "finite",
//! and the parameters whose largest values only cost time.

pub mod bounds;
pub mod generated;
pub mod graphs;
pub mod invariant;
pub mod signals;
pub mod single;
#[cfg(feature = "synth")]
pub mod stiff;
pub mod table;

pub use invariant::{Invariant, Observed, Verdict};

use std::path::{Path, PathBuf};
use std::time::Instant;

/// How much of each case runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Size {
    /// Short runs, parameters at their limits only: the CI suite (well
    /// under 2 minutes in the debug test profile).
    Ci,
    /// Longer runs, one step inside every limit too, the long live run.
    Full,
}

impl Size {
    /// Base ticks of a node case (at 1 kHz).
    pub fn ticks(self) -> u64 {
        match self {
            Size::Ci => 400,
            Size::Full => 4000,
        }
    }
    /// Samples of a long constant run.
    pub fn long_run(self) -> u64 {
        match self {
            Size::Ci => 4000,
            Size::Full => 200_000,
        }
    }
    /// Whether parameter cases also try one step inside each limit.
    pub fn steps_inside(self) -> bool {
        self == Size::Full
    }
    /// Seconds of the long live-graph run in fast-forward.
    pub fn live_seconds(self) -> f64 {
        match self {
            Size::Ci => 20.0,
            Size::Full => 3600.0,
        }
    }
    /// Seconds a shipped graph runs at most (its own end comes first:
    /// the model-building graphs need their whole recording).
    pub fn graph_seconds(self) -> f64 {
        match self {
            Size::Ci => 15.0,
            Size::Full => 600.0,
        }
    }
    /// The word on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Size::Ci => "ci",
            Size::Full => "full",
        }
    }
}

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "ci" => Ok(Size::Ci),
            "full" => Ok(Size::Full),
            _ => Err(format!("`{s}`: the size is `ci` or `full`")),
        }
    }
}

/// Where a case comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    /// Generated from a node type's declaration.
    Generated,
    /// A named stiff case.
    Stiff,
    /// A shipped graph family.
    Graph,
}

impl Group {
    /// A word for the table.
    pub fn name(self) -> &'static str {
        match self {
            Group::Generated => "generated",
            Group::Stiff => "stiff",
            Group::Graph => "graph",
        }
    }
}

/// What a case sees of the world: the folder of its fixture files and the
/// shipped graphs.
#[derive(Debug, Clone)]
pub struct Env {
    /// Folder holding the fixture files (recordings, models, meshes) the
    /// node examples and the stiff cases read ([`evflow_nodes::example_files::write`]).
    pub dir: PathBuf,
    /// The shipped graphs' folder (`graphs/`).
    pub graphs: PathBuf,
    /// The suite's size.
    pub size: Size,
}

/// The body of a case.
pub type Body = Box<dyn Fn(&Env) -> Observed>;

/// One case of the suite.
pub struct Case {
    /// Its name (unique in the suite), e.g. `butterworth/inputs ±f64::MAX`.
    pub name: String,
    /// Where it comes from.
    pub group: Group,
    /// The node types it runs.
    pub covers: Vec<&'static str>,
    /// The shipped graph family it covers, if any.
    pub family: Option<String>,
    /// What is extreme about it.
    pub extreme: String,
    /// What must hold.
    pub invariant: Invariant,
    /// Runs it.
    pub body: Body,
}

/// One row of the table: a case and its verdict.
#[derive(Debug, Clone)]
pub struct Row {
    /// The case's name.
    pub case: String,
    /// Where it comes from.
    pub group: Group,
    /// The node types it ran.
    pub covers: Vec<&'static str>,
    /// The shipped graph family it covers.
    pub family: Option<String>,
    /// What is extreme about it.
    pub extreme: String,
    /// The largest finite |output| seen.
    pub max_abs: f64,
    /// Outputs that were NaN or infinite.
    pub non_finite: u64,
    /// The invariant checked, for people.
    pub invariant: String,
    /// The verdict.
    pub verdict: Verdict,
    /// What else the case saw (errors, measured values, refusals).
    pub detail: String,
    /// Wall-clock seconds the case took (printed, never tested).
    pub seconds: f64,
}

/// The cases of the suite at `size`, with `env`'s fixtures.
pub fn cases(env: &Env) -> Vec<Case> {
    let mut v = generated::cases(env);
    #[cfg(feature = "synth")]
    v.extend(stiff::cases(env));
    v.extend(graphs::cases(env));
    v
}

/// Why the suite could not run at all.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// The fixture files could not be written.
    #[error("stability fixtures: {0}")]
    Fixtures(String),
}

/// Writes the fixtures into `dir` and returns the environment of a suite
/// of `size` over the shipped graphs in `graphs`.
pub fn prepare(dir: &Path, graphs: &Path, size: Size) -> Result<Env, SuiteError> {
    evflow_nodes::example_files::write(dir).map_err(SuiteError::Fixtures)?;
    Ok(Env { dir: dir.to_path_buf(), graphs: graphs.to_path_buf(), size })
}

/// Runs one case: its body (a panic is caught and fails it), then its
/// invariant.
pub fn run_case(case: &Case, env: &Env) -> Row {
    let started = Instant::now();
    let observed = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (case.body)(env))) {
        Ok(o) => o,
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            Observed { panic: Some(msg), ..Observed::default() }
        }
    };
    let verdict = case.invariant.judge(&observed);
    Row {
        case: case.name.clone(),
        group: case.group,
        covers: case.covers.clone(),
        family: case.family.clone(),
        extreme: case.extreme.clone(),
        max_abs: observed.max_abs,
        non_finite: observed.non_finite,
        invariant: case.invariant.describe(),
        verdict,
        // The fixtures' folder is a fresh temporary one each run: named
        // `<fixtures>` so that a row reads the same from run to run.
        detail: observed.detail().replace(&env.dir.display().to_string(), "<fixtures>"),
        seconds: started.elapsed().as_secs_f64(),
    }
}

/// Runs every case whose name contains `only` (all when empty), in
/// order, calling `each` after each row; panics inside cases are caught
/// (and kept off the terminal while the suite runs).
pub fn run(env: &Env, only: &str, each: &mut dyn FnMut(&Row)) -> Vec<Row> {
    let env = &Env { graphs: std::path::absolute(&env.graphs).unwrap_or_else(|_| env.graphs.clone()), ..env.clone() };
    let cases: Vec<Case> = cases(env).into_iter().filter(|c| only.is_empty() || c.name.contains(only)).collect();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut rows = Vec::with_capacity(cases.len());
    for c in &cases {
        let row = run_case(c, env);
        each(&row);
        rows.push(row);
    }
    std::panic::set_hook(hook);
    rows
}

/// How many rows failed.
pub fn failures(rows: &[Row]) -> usize {
    rows.iter().filter(|r| !r.verdict.passed()).count()
}
