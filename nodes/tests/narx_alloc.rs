//! The closed loop — what the `narx` node does per tick — never allocates.
//! Allocations are counted on the test's own thread only.

use evflow_nodes::narx::closed_loop::ClosedLoop;
use evflow_nodes::narx::mapminmax::MapMinMax;
use evflow_nodes::narx::net::Mlp;
use evflow_nodes::narx::taps::Taps;

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

#[test]
fn the_closed_loop_does_not_allocate_per_sample() {
    for taps in [
        Taps { feedback: 1, input: 10, lookahead: 3 },
        Taps { feedback: 10, input: 10, lookahead: -1 },
        Taps { feedback: 0, input: 0, lookahead: 0 },
    ] {
        let mut net = Mlp::new(taps.n_inputs(), &[15, 10, 5]).unwrap();
        net.init_nguyen_widrow(&mut evflow_nodes::rng::Rng::new(1));
        let map = MapMinMax { min: -0.5, max: 0.5 };
        let mut cl = ClosedLoop::new(net, taps, map, MapMinMax { min: -1.0, max: 1.0 });
        let force: Vec<f64> =
            (0..5000).map(|i| (i as f64 * 0.1).sin() * if i % 97 == 0 { f64::NAN } else { 1.0 }).collect();
        let before = allocations();
        arm(true);
        let mut acc = 0.0;
        for &f in &force {
            acc += cl.step(f);
        }
        cl.reset();
        arm(false);
        let after = allocations();
        assert!(acc.is_finite());
        assert_eq!(after, before, "{taps:?}: {} allocations in 5000 steps", after - before);
    }
}
