//! The graph-file loader never panics: arbitrary text and mutated graph
//! files (every shipped graph, mutated line- and byte-wise) go through
//! parsing, validation and — when valid — plan construction. Bounded in
//! time for the normal test suite; `fuzz/` has a cargo-fuzz target for
//! longer runs.

use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions};
use proptest::prelude::*;

fn seeds() -> Vec<String> {
    evflow_tests::shipped_graphs().into_iter().map(|(_, text)| text).collect()
}

/// Loads, validates and (when valid) builds; must return, never panic.
fn load(text: &str) {
    let registry = evflow_nodes::registry();
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("fuzz.toml");
    if let Ok(g) = parse_graph(&file, text) {
        if let Ok(c) = check(&g, &registry, &[]) {
            // Building may fail (missing files) but must not panic; nodes
            // that write files write them into the temp dir.
            let _ = Plan::build(
                &c,
                &PlanOptions { max_block: 64, out_dir: Some(dir.path().to_path_buf()), ..Default::default() },
            );
        }
    }
}

#[derive(Debug, Clone)]
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

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, max_shrink_iters: 200, ..ProptestConfig::default() })]

    #[test]
    fn mutated_graphs_never_panic(seed in any::<usize>(), muts in prop::collection::vec(mutation(), 1..6)) {
        let seeds = seeds();
        let mut text = seeds[seed % seeds.len()].clone();
        for m in &muts {
            text = apply(&text, m);
        }
        load(&text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "[\\[\\]a-z0-9_.=\" \\n\\->$,{}#]{0,300}") {
        load(&text);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        load(&String::from_utf8_lossy(&bytes));
    }
}
