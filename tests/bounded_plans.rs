//! Numbers a user gives never size memory without a bound (issue 27,
//! point 1): a fast node in a graph of a slow base rate and a huge block
//! shrink the plan's block until every buffer fits (2²⁴ samples each, 2²⁷ in
//! all), and a graph whose smallest block cannot fit is refused with the
//! node named; run lengths that would never end are refused too.

use evflow_engine::plan::{MAX_BUFFER_SAMPLES, MAX_POOL_SAMPLES};
use evflow_engine::{check, check_duration, run_offline, Plan, PlanOptions, RunOptions};
use std::path::Path;

fn plan(base_rate: &str, node_rate: &str, block: usize) -> Result<Plan, String> {
    let doc = format!(
        "[graph]\nformat = 1\nname = \"slow\"\nrate = {base_rate}\nconnections = [\"s.out -> st.in\"]\n\
         [nodes.s]\ntype = \"sine\"\nrate = {node_rate}\n[nodes.st]\ntype = \"stats\"\n"
    );
    let g = evflow_engine::graph::parse_graph(Path::new("slow.toml"), &doc).map_err(|e| e.to_string())?;
    let checked = check(&g, &evflow_nodes::registry(), &[]).map_err(|e| e.to_string())?;
    Plan::build(&checked, &PlanOptions { max_block: block, ..PlanOptions::default() }).map_err(|e| e.to_string())
}

#[test]
fn a_fast_node_in_a_slow_graph_or_a_huge_block_shrinks_the_block_to_fit() {
    // 10 kHz in a graph of 0.01 Hz: a million samples per base tick; the
    // default block of 1024 ticks would need 8 GB per buffer.
    for block in [1024, 10_000_000_000, usize::MAX] {
        let mut p = plan("0.01", "10000.0", block).unwrap();
        assert!(p.max_block() * 1_000_000 <= MAX_BUFFER_SAMPLES, "block {}", p.max_block());
        assert!(p.max_block() >= 1);
        // And it runs: 3 base ticks = 300 s of signal, 3 million samples.
        let r = run_offline(&mut p, RunOptions { duration: Some(300.0), progress: None }).unwrap();
        assert_eq!(r.value("st", "samples"), Some(3_000_000.0));
    }
    // A plain graph keeps the block it asked for.
    assert_eq!(plan("1000.0", "1000.0", 4096).unwrap().max_block(), 4096);
    // A huge block of a plain graph is cut to what the pool holds.
    let p = plan("1000.0", "1000.0", usize::MAX).unwrap();
    assert!(p.max_block() * 2 <= MAX_POOL_SAMPLES && p.max_block() <= MAX_BUFFER_SAMPLES, "{}", p.max_block());
}

#[test]
fn a_graph_whose_smallest_block_cannot_fit_is_refused_naming_the_node() {
    // 10 MHz in a graph of 0.5 Hz: 2·10⁷ samples per base tick, more than a buffer holds.
    let e = plan("0.5", "10000000.0", 1024).err().expect("refused");
    assert!(e.contains("`s`") && e.contains("raise [graph] rate") && e.contains("128 MiB"), "{e}");
}

#[test]
fn run_lengths_that_would_never_end_are_refused() {
    for bad in [f64::INFINITY, 1e308, -1.0, 0.0, f64::NAN] {
        assert!(check_duration(bad).is_err(), "{bad}");
    }
}
