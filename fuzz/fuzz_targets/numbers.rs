//! Fuzz target: the numbers a user types — a case in the format of
//! `tests/fuzz_corpus/numbers/` (a graph with edits, `--block`,
//! `--duration`, `--sweep`, `--set`, `import --rate`) — go through what
//! `evflow check` and `evflow run` do with them without a panic or an
//! abort (`tests/fuzz_numbers.rs` runs the same code under `cargo test`).
#![no_main]

#[path = "../../tests/fuzz_numbers_case.rs"]
mod numbers;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(case) = numbers::Case::parse(&text) {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("the repository");
        let _ = numbers::exercise(root, &case);
    }
});
