//! The graph-file loader never panics: arbitrary text and mutated graph
//! files (every shipped graph and every corpus case, mutated line- and
//! byte-wise) go through parsing, validation and — when valid — plan
//! construction.
//!
//! **Deterministic by default.** `cargo test` draws the property tests'
//! cases from a fixed seed (`fuzz_common.rs`, `CI_SEED`), so a run fails or passes the same
//! way every time, and it replays every file of `tests/fuzz_corpus/` — each
//! case that ever failed, plus hand-picked nasty inputs — with a plain test
//! (`tests/fuzz_corpus/README.md` says how to add one).
//!
//! **Open-ended fuzzing is opt-in:** `EVFLOW_FUZZ_CASES=N` draws N cases per
//! property from a fresh random seed, printed with the results;
//! `EVFLOW_FUZZ_SEED=S` replays seed S. A failing case's text is saved under
//! the target folder (the path is printed) for the corpus. `fuzz/` has a
//! cargo-fuzz target for longer runs. README.md, "Fuzzing", has the commands.

use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::fuzz_common as common;

/// Cases per property in the deterministic run (about 1.5 s for all three).
const CI_CASES: u32 = 400;

/// The configuration the property tests run with.
fn config() -> ProptestConfig {
    common::config("fuzz_loader", CI_CASES)
}

/// The corpus folder: one file per case, every file but README.md.
fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz_corpus")
}

/// Every corpus case, sorted by file name, with its text (invalid UTF-8
/// read lossily, as the property tests read arbitrary bytes).
fn corpus() -> Vec<(PathBuf, String)> {
    let dir = corpus_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            let text = String::from_utf8_lossy(&bytes).into_owned();
            (p, text)
        })
        .collect()
}

/// The texts the mutations start from: the shipped graphs and the corpus.
fn bases() -> &'static [String] {
    static BASES: OnceLock<Vec<String>> = OnceLock::new();
    BASES.get_or_init(|| evflow_tests::shipped_graphs().into_iter().chain(corpus()).map(|(_, text)| text).collect())
}

/// How far a text got through the loader.
#[derive(Debug)]
enum Outcome {
    /// Refused by the parser, with its message.
    Parse(String),
    /// Refused by validation, with its message.
    Check(String),
    /// Valid, but a node could not be built (e.g. a missing file).
    Build(String),
    /// Valid, and the plan was built.
    Built,
}

impl Outcome {
    /// The error message, if any.
    fn message(&self) -> Option<&str> {
        match self {
            Outcome::Parse(m) | Outcome::Check(m) | Outcome::Build(m) => Some(m),
            Outcome::Built => None,
        }
    }
}

/// Loads, validates and (when valid) builds.
fn load(text: &str) -> Outcome {
    let registry = evflow_nodes::registry();
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("fuzz.toml");
    let g = match parse_graph(&file, text) {
        Ok(g) => g,
        Err(e) => return Outcome::Parse(e.to_string()),
    };
    let c = match check(&g, &registry, &[]) {
        Ok(c) => c,
        Err(e) => return Outcome::Check(e.to_string()),
    };
    // Nodes that write files write them into the temp dir.
    match Plan::build(&c, &PlanOptions { max_block: 64, out_dir: Some(dir.path().to_path_buf()), ..Default::default() })
    {
        Ok(_) => Outcome::Built,
        Err(e) => Outcome::Build(e.to_string()),
    }
}

/// [`load`] for a property test: on a panic the text is saved to
/// `<target>/tmp/fuzz_loader/<property>.toml` for the corpus.
fn load_or_save(property: &str, text: &str) {
    common::or_save("fuzz_loader", property, "toml", text, || load(text));
}

#[derive(Debug, Clone, PartialEq)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    InsertText(usize, String),
    DeleteBytes(usize, usize),
    ReplaceNumber(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let token = prop_oneof![
        Just("[".to_string()),
        Just("]".to_string()),
        Just("\"".to_string()),
        Just("=".to_string()),
        Just("->".to_string()),
        Just(".".to_string()),
        Just("\n".to_string()),
        Just("[nodes.x]\ntype = \"gain\"\n".to_string()),
        Just("\"x.out -> y.in\",".to_string()),
        Just("format = 99\n".to_string()),
        Just("$".to_string()),
        "[a-z_.]{1,8}",
        "[ -~]{0,12}",
    ];
    let number = prop_oneof![
        Just("0".to_string()),
        Just("-1".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("9223372036854775807".to_string()),
        Just("0.000000001".to_string()),
        Just("\"text\"".to_string()),
        Just("[]".to_string()),
    ];
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (any::<usize>(), token).prop_map(|(a, t)| Mutation::InsertText(a, t)),
        (any::<usize>(), 1usize..16).prop_map(|(a, n)| Mutation::DeleteBytes(a, n)),
        (any::<usize>(), number).prop_map(|(a, t)| Mutation::ReplaceNumber(a, t)),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let n = lines.len().max(1);
    match m {
        Mutation::DeleteLine(i) if !lines.is_empty() => {
            lines.remove(i % n);
        }
        Mutation::DuplicateLine(i) if !lines.is_empty() => {
            let l = lines[i % n].clone();
            lines.insert(i % n, l);
        }
        Mutation::SwapLines(a, b) if !lines.is_empty() => lines.swap(a % n, b % n),
        Mutation::InsertText(at, t) => {
            let mut s = text.to_string();
            let mut at = at % (s.len() + 1);
            while !s.is_char_boundary(at) {
                at -= 1;
            }
            s.insert_str(at, t);
            return s;
        }
        Mutation::DeleteBytes(at, len) => {
            let mut s = text.as_bytes().to_vec();
            let at = at % (s.len() + 1);
            let end = (at + len).min(s.len());
            s.drain(at..end);
            return String::from_utf8_lossy(&s).into_owned();
        }
        Mutation::ReplaceNumber(i, t) => {
            // Replace the value of the i-th `key = number` line.
            let idx: Vec<usize> = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| {
                    l.split_once('=')
                        .is_some_and(|(_, v)| v.trim().starts_with(|c: char| c.is_ascii_digit() || c == '-'))
                })
                .map(|(k, _)| k)
                .collect();
            if !idx.is_empty() {
                let k = idx[i % idx.len()];
                let key = lines[k].split_once('=').map(|(k, _)| k.to_string()).unwrap_or_default();
                lines[k] = format!("{key}= {t}");
            }
        }
        _ => {}
    }
    lines.join("\n")
}

/// A base text (by index, modulo the number of bases) and the mutations
/// applied to it in turn.
fn mutated_case() -> impl Strategy<Value = (usize, Vec<Mutation>)> {
    (any::<usize>(), prop::collection::vec(mutation(), 1..6))
}

/// The text of a [`mutated_case`].
fn mutated_text(base: usize, muts: &[Mutation]) -> String {
    let bases = bases();
    muts.iter().fold(bases[base % bases.len()].clone(), |text, m| apply(&text, m))
}

/// Short text over the characters TOML graph files are made of.
const TEXT_CASE: &str = "[\\[\\]a-z0-9_.=\" \\n\\->$,{}#]{0,300}";

/// Arbitrary bytes, read as text lossily.
fn bytes_case() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(any::<u8>(), 0..200)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_graphs_never_panic((base, muts) in mutated_case()) {
        load_or_save("mutated_graphs_never_panic", &mutated_text(base, &muts));
    }

    #[test]
    fn arbitrary_text_never_panics(text in TEXT_CASE) {
        load_or_save("arbitrary_text_never_panics", &text);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in bytes_case()) {
        load_or_save("arbitrary_bytes_never_panic", &String::from_utf8_lossy(&bytes));
    }
}

/// What a corpus file expects beyond "no panic", from its comment lines:
/// `# expect: built` (the plan builds) or `# expect-error: TEXT` (the
/// loader refuses it with a message containing TEXT).
#[derive(Debug, PartialEq)]
enum Expect {
    Built,
    Error(String),
}

fn expectations(text: &str) -> Vec<Expect> {
    text.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            if l.trim_end() == "# expect: built" {
                Some(Expect::Built)
            } else {
                l.strip_prefix("# expect-error:").map(|m| Expect::Error(m.trim().to_string()))
            }
        })
        .collect()
}

/// Every corpus case: no panic, and the outcome its comments expect.
#[test]
fn corpus_cases_load_without_panic_and_as_expected() {
    let cases = corpus();
    assert!(cases.len() >= 10, "the corpus in {} has only {} cases", corpus_dir().display(), cases.len());
    let mut failures = Vec::new();
    for (path, text) in &cases {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let outcome = match std::panic::catch_unwind(|| load(text)) {
            Ok(o) => o,
            Err(_) => {
                failures.push(format!("{name}: panicked"));
                continue;
            }
        };
        for e in expectations(text) {
            let met = match (&e, &outcome) {
                (Expect::Built, Outcome::Built) => true,
                (Expect::Error(want), o) => o.message().is_some_and(|m| m.contains(want.as_str())),
                _ => false,
            };
            if !met {
                failures.push(format!("{name}: expected {e:?}, got {outcome:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{} corpus case(s) failed:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn expectations_are_read_from_comment_lines() {
    let text = "# a case\n  # expect-error: `type` is empty\n# expect: built\n# expect:built\nx = 1 # expect: built\n";
    assert_eq!(expectations(text), [Expect::Error("`type` is empty".into()), Expect::Built]);
}

/// Runs `strategy` through a proptest runner with `config` and returns
/// every case it drew, in order.
fn drawn<S: Strategy>(config: ProptestConfig, strategy: S) -> Vec<S::Value>
where
    S::Value: Clone,
{
    let seen = RefCell::new(Vec::new());
    TestRunner::new(config)
        .run(&strategy, |v| {
            seen.borrow_mut().push(v);
            Ok(())
        })
        .expect("recording cases cannot fail");
    seen.into_inner()
}

/// Fails at the first case where two draws differ (without printing
/// hundreds of graph files).
fn same_draws<T: PartialEq>(what: &str, a: &[T], b: &[T]) {
    assert_eq!(a.len(), b.len(), "{what}: case counts differ");
    if let Some(i) = a.iter().zip(b).position(|(x, y)| x != y) {
        panic!("{what}: case {i} differs between two runs of the CI configuration");
    }
}

/// The deterministic run is deterministic: two runners on the CI
/// configuration draw the same cases, case for case, for each property's
/// strategy — so a random seed slipping into `common::ci_config` fails here — and
/// `cargo test` uses that configuration unless fuzzing was asked for.
#[test]
fn the_ci_configuration_draws_the_same_cases_every_run() {
    let texts = || drawn(common::ci_config(CI_CASES), mutated_case().prop_map(|(b, m)| mutated_text(b, &m)));
    let first = texts();
    assert_eq!(first.len(), CI_CASES as usize);
    assert!(first.iter().any(|t| t != &first[0]), "the cases vary");
    same_draws("mutated graphs", &first, &texts());
    same_draws(
        "arbitrary text",
        &drawn(common::ci_config(CI_CASES), TEXT_CASE),
        &drawn(common::ci_config(CI_CASES), TEXT_CASE),
    );
    same_draws(
        "arbitrary bytes",
        &drawn(common::ci_config(CI_CASES), bytes_case()),
        &drawn(common::ci_config(CI_CASES), bytes_case()),
    );
    if common::fuzz_env("fuzz_loader", CI_CASES).is_none() {
        assert_eq!(config(), common::ci_config(CI_CASES));
    }
}
