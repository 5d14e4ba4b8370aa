//! The numbers a user types never crash evflow, never size memory past its
//! bounds and never run for ever: `[graph] rate`, `[vars]` defaults,
//! `[sweep]` values, `--sweep`, `--set`, `--block`, `--duration` and
//! `evflow import --rate`, drawn from extremes (0, ±1e308, NaN, ±inf,
//! 2⁶⁴−1, 1e-300, text where a number goes) over the shipped graphs, go
//! through what `evflow check` and `evflow run` do with them: the sweep
//! expanded, counted and validated run by run, each valid run built as
//! `check` builds it and as `run` does, then run for at most 10 ms of
//! signal. Every refusal must be an error, never a panic or an abort.
//!
//! Deterministic under `cargo test` (the seed of `fuzz_common.rs`), with
//! every case of `tests/fuzz_corpus/numbers/` replayed and held to its
//! `# expect-error:` / `# expect: ok` lines; `EVFLOW_FUZZ_CASES=N` and
//! `EVFLOW_FUZZ_SEED=S` as for `fuzz_loader.rs` (README.md, "Fuzzing").

use crate::fuzz_common as common;

#[path = "fuzz_numbers_case.rs"]
mod numbers;

use numbers::{Case, Edit};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Cases per property in the deterministic run.
const CI_CASES: u32 = 96;

/// Numbers from the edges: zero, signs, the largest and smallest floats,
/// not-a-number, infinities, the largest integers, text.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "0",
            "-0",
            "-1",
            "0.01",
            "0.5",
            "1",
            "3",
            "1000",
            "10000.0",
            "1e7",
            "1e-300",
            "5e-324",
            "1e308",
            "-1e308",
            "1.7976931348623157e308",
            "nan",
            "inf",
            "-inf",
            "18446744073709551615",
            "9223372036854775807",
            "10000000000",
            "\"text\"",
            "[]",
            "[1, 2]",
            "true",
            "\"\"",
            "1_000",
            "0x10",
        ])
        .prop_map(str::to_string),
        any::<f64>().prop_map(|x| format!("{x:?}")),
        any::<u64>().prop_map(|x| x.to_string()),
    ]
}

/// Lists of numbers for a sweep: a few, some extreme.
fn values() -> impl Strategy<Value = String> {
    prop::collection::vec(number(), 0..4).prop_map(|v| format!("[{}]", v.join(", ")))
}

/// The shipped graphs the cases start from: each family, sweeps included.
const GRAPHS: &[&str] = &[
    "characterize.toml",
    "excitation.toml",
    "forward-build.toml",
    "lab-work-precision.toml",
    "mesh-scan.toml",
    "model-build.toml",
    "record-textures.toml",
    "synthesize.toml",
    "texture-quality.toml",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        number().prop_map(Edit::GraphRate),
        (any::<usize>(), number()).prop_map(|(i, v)| Edit::Var(i, v)),
        (any::<usize>(), values()).prop_map(|(i, v)| Edit::Sweep(i, v)),
    ]
}

/// `--sweep NAME=…` and `--set NAME=…` over a graph's variables (by name
/// where the graph has them, else arbitrary).
fn cli_pair() -> impl Strategy<Value = String> {
    let name = prop_oneof![
        prop::sample::select(vec!["mass", "speed", "intensity", "gain", "rate", "scheme", "substeps", "nope", "a.b"])
            .prop_map(str::to_string),
        "[a-z_.]{0,6}",
    ];
    let list = prop::collection::vec(number(), 1..4).prop_map(|v| v.join(","));
    (name, list).prop_map(|(n, v)| format!("{n}={v}"))
}

fn case() -> impl Strategy<Value = Case> {
    (
        prop::sample::select(GRAPHS),
        prop::collection::vec(edit(), 0..3),
        prop::option::of(number()),
        prop::option::of(number()),
        prop::collection::vec(cli_pair(), 0..2),
        prop::collection::vec(cli_pair(), 0..2),
        prop::option::weighted(0.2, number()),
    )
        .prop_map(|(g, edits, block, duration, sweep, set, import_rate)| Case {
            graph: g.to_string(),
            edits,
            block,
            duration,
            sweep,
            set,
            import_rate,
        })
}

proptest! {
    #![proptest_config(common::config("fuzz_numbers", CI_CASES))]

    #[test]
    fn numbers_a_user_types_are_refused_or_run_never_crash(c in case()) {
        common::or_save("fuzz_numbers", "numbers", "txt", &c.to_text(), || numbers::exercise(&evflow_tests::root(), &c));
    }
}

/// The folder of the number cases.
fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz_corpus").join("numbers")
}

/// The deterministic draw is not vacuous: a share of its cases get past
/// the refusals to plans built and run, and a share are refused.
#[test]
fn the_ci_cases_reach_every_stage() {
    let counts = std::cell::Cell::new((0, 0, 0));
    let mut runner = proptest::test_runner::TestRunner::new(common::ci_config(CI_CASES));
    runner
        .run(&case(), |c| {
            let r = numbers::exercise(&evflow_tests::root(), &c);
            let (b, n, e) = counts.get();
            counts.set((
                b + usize::from(r.built > 0),
                n + usize::from(r.ran > 0),
                e + usize::from(!r.errors.is_empty()),
            ));
            Ok(())
        })
        .unwrap();
    let (built, ran, refused) = counts.get();
    assert!(built >= 10 && ran >= 10 && refused >= 10, "built {built}, ran {ran}, refused {refused} of {CI_CASES}");
}

/// The corpus of number cases: every file of `tests/fuzz_corpus/numbers/`.
fn corpus() -> Vec<(PathBuf, String)> {
    let dir = corpus_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

/// Every corpus case (each input of issue 27 among them) runs without a
/// panic and as its comment lines expect: `# expect-error: TEXT` (some
/// refusal contains TEXT), `# expect-no-error: TEXT` (none does),
/// `# expect: ok` (nothing refused).
#[test]
fn corpus_cases_are_refused_or_run_as_expected() {
    let cases = corpus();
    assert!(cases.len() >= 8, "only {} number cases", cases.len());
    let mut failures = Vec::new();
    for (path, text) in &cases {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let case = Case::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(Case::parse(&case.to_text()).as_ref(), Ok(&case), "{name}: the format round-trips");
        let errors = match std::panic::catch_unwind(|| numbers::exercise(&evflow_tests::root(), &case)) {
            Ok(r) => r.errors,
            Err(_) => {
                failures.push(format!("{name}: panicked"));
                continue;
            }
        };
        for l in text.lines().map(str::trim) {
            if let Some(want) = l.strip_prefix("# expect-error:").map(str::trim) {
                if !errors.iter().any(|e| e.contains(want)) {
                    failures.push(format!("{name}: no error contains `{want}`: {errors:#?}"));
                }
            } else if let Some(not) = l.strip_prefix("# expect-no-error:").map(str::trim) {
                if let Some(e) = errors.iter().find(|e| e.contains(not)) {
                    failures.push(format!("{name}: an error contains `{not}`: {e}"));
                }
            } else if l == "# expect: ok" && !errors.is_empty() {
                failures.push(format!("{name}: expected no error: {errors:#?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{} case(s) failed:\n{}", failures.len(), failures.join("\n"));
}
