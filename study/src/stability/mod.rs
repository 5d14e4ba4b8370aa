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

use evflow_engine::batch::{for_each_ordered_ahead, panic_message};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
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

/// The body of a case, or of one piece of a case.
pub type Body = Box<dyn Fn(&Env) -> Observed + Send + Sync>;

/// How a case runs.
pub enum Work {
    /// One body.
    Whole(Body),
    /// Independent pieces, which [`run`] may run side by side, joined in
    /// order as one body running them one after the other would have been
    /// ([`join`]).
    Pieces(Vec<Body>),
}

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
    pub work: Work,
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

/// Runs one body, catching a panic (its message is the outcome).
fn attempt(body: &Body, env: &Env) -> Result<Observed, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(env))).map_err(|p| panic_message(p.as_ref()))
}

/// What a case split into pieces saw, from each piece's outcome in order,
/// as one body running the pieces one after the other would have seen
/// it: the first panic is the case's (what the pieces before it saw is
/// lost, as a panic loses it); a piece's error becomes the case's (a later
/// one replaces it, the earlier stays among the notes); a piece marked
/// [`Observed::ends_case`] ends the case with its error, and what it and
/// the pieces after it saw is left out.
pub fn join(outcomes: Vec<Result<Observed, String>>) -> Result<Observed, String> {
    let mut o = Observed::default();
    for outcome in outcomes {
        let mut piece = outcome?;
        if let Some(e) = piece.error.take() {
            o.error = Some(e);
        }
        if piece.ends_case {
            return Ok(o);
        }
        o.merge(piece);
    }
    Ok(o)
}

/// The row of `case`, from what it saw (or its panic's message).
fn row(case: &Case, outcome: Result<Observed, String>, seconds: f64, env: &Env) -> Row {
    let observed = outcome.unwrap_or_else(|msg| Observed { panic: Some(msg), ..Observed::default() });
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
        seconds,
    }
}

/// Runs one case in the calling thread, its pieces one after the other:
/// its body (a panic is caught and fails it), then its invariant.
pub fn run_case(case: &Case, env: &Env) -> Row {
    let started = Instant::now();
    let outcome = match &case.work {
        Work::Whole(body) => attempt(body, env),
        Work::Pieces(pieces) => join(pieces.iter().map(|p| attempt(p, env)).collect()),
    };
    row(case, outcome, started.elapsed().as_secs_f64(), env)
}

/// Runs every case whose name contains `only` (all when empty) on `jobs`
/// threads, calling `each` with each row in the suite's order as soon as
/// it and the rows before it are done; returns the rows in that order,
/// the same for any `jobs`. Panics inside cases are caught (and kept off
/// the terminal while the suite runs).
///
/// The pieces of every case are one queue. The shipped graphs' pieces go
/// first: each runs minutes of simulated time, most other cases a few
/// seconds, so the longest work starts first and the two threads end
/// together. A row's seconds are its pieces' seconds summed.
pub fn run(env: &Env, only: &str, jobs: usize, each: &mut dyn FnMut(&Row)) -> Vec<Row> {
    let env = &Env { graphs: std::path::absolute(&env.graphs).unwrap_or_else(|_| env.graphs.clone()), ..env.clone() };
    let cases: Vec<Case> = cases(env).into_iter().filter(|c| only.is_empty() || c.name.contains(only)).collect();
    run_cases(&cases, env, jobs, each)
}

/// Runs `cases` as [`run`] does.
pub fn run_cases(cases: &[Case], env: &Env, jobs: usize, each: &mut dyn FnMut(&Row)) -> Vec<Row> {
    let pieces = |c: &Case| match &c.work {
        Work::Whole(_) => 1,
        Work::Pieces(p) => p.len(),
    };
    // (case, piece), the shipped graphs' first.
    let mut queue: Vec<(usize, usize)> =
        cases.iter().enumerate().flat_map(|(k, c)| (0..pieces(c)).map(move |p| (k, p))).collect();
    queue.sort_by_key(|&(k, _)| cases[k].group != Group::Graph);
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut outcomes: Vec<Vec<Option<Result<Observed, String>>>> =
        cases.iter().map(|c| (0..pieces(c)).map(|_| None).collect()).collect();
    let mut seconds = vec![0.0; cases.len()];
    let mut rows: Vec<Option<Row>> = cases.iter().map(|_| None).collect();
    // The rows handed to `each` so far: a prefix of the suite.
    let mut reported = 0;
    let work = |_: usize, (k, p): (usize, usize)| {
        let started = Instant::now();
        let body = match &cases[k].work {
            Work::Whole(body) => body,
            Work::Pieces(pieces) => &pieces[p],
        };
        (k, p, attempt(body, env), started.elapsed().as_secs_f64())
    };
    let all = queue.len();
    for_each_ordered_ahead(queue, jobs, all, &AtomicBool::new(false), work, |_, done| {
        // `attempt` catches every panic, so the pool's own catch never fires.
        let Ok((k, p, outcome, s)) = done else { return };
        outcomes[k][p] = Some(outcome);
        seconds[k] += s;
        if outcomes[k].iter().all(Option::is_some) {
            let mut got: Vec<Result<Observed, String>> = outcomes[k].iter_mut().filter_map(Option::take).collect();
            let outcome = match cases[k].work {
                Work::Whole(_) => got.remove(0),
                Work::Pieces(_) => join(got),
            };
            rows[k] = Some(row(&cases[k], outcome, seconds[k], env));
            while let Some(Some(r)) = rows.get(reported) {
                each(r);
                reported += 1;
            }
        }
    });
    std::panic::set_hook(hook);
    rows.into_iter().flatten().collect()
}

/// How many rows failed.
pub fn failures(rows: &[Row]) -> usize {
    rows.iter().filter(|r| !r.verdict.passed()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(max: f64, port: &str) -> Observed {
        Observed {
            max_abs: max,
            ports: vec![(port.into(), max)],
            samples: 1,
            notes: vec![format!("{port} ran")],
            ..Observed::default()
        }
    }

    fn case(name: &str, group: Group, work: Work) -> Case {
        Case {
            name: name.into(),
            group,
            covers: Vec::new(),
            family: None,
            extreme: String::new(),
            invariant: Invariant::Finite { refusal_ok: true },
            work,
        }
    }

    fn body(f: impl Fn(&Env) -> Observed + Send + Sync + 'static) -> Body {
        Box::new(f)
    }

    /// Whole cases and cases in pieces: errors, a piece that ends its
    /// case, a panicking piece, a slow case.
    fn suite() -> Vec<Case> {
        vec![
            case("whole", Group::Generated, Work::Whole(body(|_| seen(1.0, "a")))),
            case(
                "an error",
                Group::Graph,
                Work::Pieces(vec![
                    body(|_| seen(2.0, "b")),
                    body(|_| Observed { error: Some("c stopped".into()), ..seen(3.0, "c") }),
                    body(|_| seen(0.5, "d")),
                ]),
            ),
            case(
                "ended",
                Group::Graph,
                Work::Pieces(vec![
                    body(|_| seen(2.0, "e")),
                    body(|_| Observed { error: Some("f does not load".into()), ends_case: true, ..seen(7.0, "f") }),
                    body(|_| panic!("after the end")),
                ]),
            ),
            case(
                "a panic",
                Group::Graph,
                Work::Pieces(vec![body(|_| seen(2.0, "g")), body(|_| panic!("piece two")), body(|_| seen(9.0, "h"))]),
            ),
            case(
                "slow",
                Group::Stiff,
                Work::Whole(body(|_| {
                    std::thread::sleep(std::time::Duration::from_millis(30));
                    seen(4.0, "i")
                })),
            ),
        ]
    }

    fn shown(r: &Row) -> String {
        format!("{:?}", Row { seconds: 0.0, ..r.clone() })
    }

    #[test]
    fn pieces_join_as_one_body_running_them_in_order_would() {
        let env = Env { dir: PathBuf::from("."), graphs: PathBuf::from("."), size: Size::Ci };
        let cases = suite();
        let rows: Vec<Row> = cases.iter().map(|c| run_case(c, &env)).collect();
        assert_eq!(rows[1].max_abs, 3.0);
        assert!(rows[1].detail.contains("c stopped") && rows[1].detail.contains("d ran"), "{}", rows[1].detail);
        // Ended by its second piece: the first piece's notes, the second's
        // error, nothing of the second's or the third's outputs.
        assert_eq!(rows[2].max_abs, 2.0);
        assert!(rows[2].detail.contains("f does not load") && rows[2].detail.contains("e ran"), "{}", rows[2].detail);
        assert!(!rows[2].detail.contains("f ran") && !rows[2].detail.contains("after the end"), "{}", rows[2].detail);
        assert_eq!(rows[3].detail, "panicked: piece two");
        assert_eq!(rows[3].max_abs, 0.0);
        assert!(!rows[3].verdict.passed());
    }

    #[test]
    fn the_rows_are_the_same_for_any_number_of_jobs() {
        let env = Env { dir: PathBuf::from("."), graphs: PathBuf::from("."), size: Size::Ci };
        let cases = suite();
        let alone: Vec<String> = cases.iter().map(|c| shown(&run_case(c, &env))).collect();
        for jobs in [1, 2, 3, 8] {
            let mut done = Vec::new();
            let rows = run_cases(&cases, &env, jobs, &mut |r| done.push(r.case.clone()));
            assert_eq!(rows.iter().map(shown).collect::<Vec<_>>(), alone, "jobs {jobs}");
            let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
            assert_eq!(done, names, "jobs {jobs}: each row reported once, in the suite's order");
        }
    }
}
