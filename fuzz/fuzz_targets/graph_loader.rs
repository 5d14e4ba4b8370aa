//! Fuzz target: the graph-file loader (parse + validate) never panics.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let registry = evflow_nodes::registry();
    if let Ok(g) = evflow_engine::graph::parse_graph(Path::new("fuzz.toml"), &text) {
        let _ = evflow_engine::check(&g, &registry, &[]);
        let _ = g.to_toml();
    }
});
