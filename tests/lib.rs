//! Shared helpers for the end-to-end tests.

use std::path::{Path, PathBuf};

#[path = "alloc_counter.rs"]
pub mod alloc_counter;

/// The repository's root folder.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ sits in the root").to_path_buf()
}

/// Every shipped graph file (`graphs/**/*.toml` except lab profiles), with its text.
pub fn shipped_graphs() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    let dir = root().join("graphs");
    let mut entries: Vec<PathBuf> =
        std::fs::read_dir(&dir).map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect()).unwrap_or_default();
    entries.sort();
    for p in entries {
        if p.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            out.push((p, text));
        }
    }
    out
}
