//! The closed loop — what the `narx` node does per tick — never allocates.
//! Allocations are counted on the test's own thread only.

use evflow_nodes::narx::closed_loop::ClosedLoop;
use evflow_nodes::narx::mapminmax::MapMinMax;
use evflow_nodes::narx::net::Mlp;
use evflow_nodes::narx::taps::Taps;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Counting is on only on the thread under test (libtest's own threads allocate meanwhile).
    static WATCHED: Cell<bool> = const { Cell::new(false) };
    /// Allocations of this thread while watched.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    if WATCHED.with(|w| w.get()) {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
    }
}

fn allocations() -> usize {
    ALLOCATIONS.with(|a| a.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_an_allocation() {
    WATCHED.with(|w| w.set(true));
    let before = allocations();
    let v: Vec<f64> = std::hint::black_box(vec![1.0; 100]);
    let after = allocations();
    WATCHED.with(|w| w.set(false));
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
        net.init_nguyen_widrow(&mut evflow_nodes::lab::rng::Rng::new(1));
        let map = MapMinMax { min: -0.5, max: 0.5 };
        let mut cl = ClosedLoop::new(net, taps, map, MapMinMax { min: -1.0, max: 1.0 });
        let force: Vec<f64> =
            (0..5000).map(|i| (i as f64 * 0.1).sin() * if i % 97 == 0 { f64::NAN } else { 1.0 }).collect();
        let before = allocations();
        WATCHED.with(|w| w.set(true));
        let mut acc = 0.0;
        for &f in &force {
            acc += cl.step(f);
        }
        cl.reset();
        WATCHED.with(|w| w.set(false));
        let after = allocations();
        assert!(acc.is_finite());
        assert_eq!(after, before, "{taps:?}: {} allocations in 5000 steps", after - before);
    }
}
