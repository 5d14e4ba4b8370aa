//! `decimate` and `resample` never allocate while processing: a whole
//! plan around each (feed → node → tap, the engine's own `step`) runs
//! block after block, one tick and large blocks, with allocations counted
//! on the test's own thread.

use evflow_engine::harness::Single;
use evflow_nodes::rate::{decimate, resample};

#[path = "../../tests/alloc_counter.rs"]
#[allow(dead_code)] // the live tests' parts of the shared counter are not used here
mod alloc_counter;

use alloc_counter::{arm, thread_allocations as allocations, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_an_allocation() {
    arm(true);
    let before = allocations();
    let v: Vec<f64> = std::hint::black_box(vec![1.0; 100]);
    let after = allocations();
    arm(false);
    assert!(after > before && v.len() == 100);
}

/// Steps the plan of `single` to its end with counting on; returns the
/// allocations counted and the samples of the node's output.
fn count_steps(single: &Single<'_>) -> (u64, usize) {
    let (mut plan, _) = single.plan().unwrap();
    let mut samples = 0;
    let mut done = 0u64;
    let before = allocations();
    arm(true);
    while done < single.ticks {
        let n = (plan.max_block() as u64).min(single.ticks - done);
        plan.step(n as usize).unwrap();
        samples += plan.output("dut", 0).map_or(0, <[f64]>::len);
        done += n;
    }
    plan.reset();
    arm(false);
    (allocations() - before, samples)
}

#[test]
fn decimate_and_resample_do_not_allocate_while_processing() {
    let x: Vec<f64> = (0..20_000).map(|n| (n as f64 * 0.013).sin()).collect();
    let cases: [(&'static evflow_engine::NodeSpec, &str, f64, f64); 6] = [
        (&decimate::SPEC, "rate = 1000.0", 10_000.0, 1000.0),
        (&decimate::SPEC, "rate = 40.0", 1000.0, 1000.0),
        (&resample::SPEC, "rate = 1000.0\nquality = \"fast\"", 40.0, 1000.0),
        (&resample::SPEC, "rate = 1000.0\nquality = \"balanced\"", 44_100.0, 100.0),
        (&resample::SPEC, "rate = 200.0\nquality = \"best\"", 300.0, 100.0),
        (&resample::SPEC, "rate = 3000.0\nquality = \"balanced\"", 1000.0, 1000.0),
    ];
    for (spec, params, fs_in, base) in cases {
        for block in [1, 64, 4096] {
            let ticks = (x.len() as f64 / fs_in * base) as u64;
            let single = Single::new(spec, params)
                .input("in", x.clone(), fs_in)
                .output("out")
                .base_rate(base)
                .ticks(ticks)
                .block(block);
            let (n, samples) = count_steps(&single);
            assert!(samples > 0, "{} {params}: no output", spec.name);
            assert_eq!(n, 0, "{} {params} from {fs_in} Hz, block {block}: {n} allocations", spec.name);
        }
    }
}
