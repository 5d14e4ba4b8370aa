//! An allocation-counting global allocator for the real-time tests: it
//! forwards to the system allocator and, on threads that armed it, counts
//! every allocation, reallocation and free. A test binary installs it with
//! `#[global_allocator] static GLOBAL: evflow_tests::alloc_counter::Counting
//! = evflow_tests::alloc_counter::Counting;` and arms it from the live
//! runner's per-tick hook. Tests that measure a stretch of code on their own
//! thread (the nodes crate's allocation tests include this file with
//! `#[path]`) read [`thread_allocations`], which parallel tests in the same
//! binary do not disturb.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// The counting allocator.
pub struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    /// Allocations and frees counted on this thread while armed.
    static MINE: Cell<u64> = const { Cell::new(0) };
}
static ALLOCS: AtomicU64 = AtomicU64::new(0);
static ARMINGS: AtomicU64 = AtomicU64::new(0);

fn armed() -> bool {
    ARMED.try_with(|a| a.get()).unwrap_or(false)
}

fn count() {
    if armed() {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
        let _ = MINE.try_with(|m| m.set(m.get() + 1));
    }
}

// SAFETY: forwards to the system allocator; counting has no effect on memory.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for this method is passed on unchanged.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        count();
        // SAFETY: the caller's contract for this method is passed on unchanged.
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for this method is passed on unchanged.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        // SAFETY: the caller's contract for this method is passed on unchanged.
        unsafe { System.realloc(p, l, n) }
    }
}

/// Arms (or disarms) counting on the calling thread; arming is counted.
pub fn arm(on: bool) {
    if on {
        ARMINGS.fetch_add(1, Ordering::SeqCst);
    }
    ARMED.with(|a| a.set(on));
}

/// Allocations and frees counted so far, on every armed thread.
pub fn allocations() -> u64 {
    ALLOCS.load(Ordering::SeqCst)
}

/// Allocations and frees counted so far on the calling thread.
pub fn thread_allocations() -> u64 {
    MINE.with(|m| m.get())
}

/// Times any thread armed the counter.
pub fn armings() -> u64 {
    ARMINGS.load(Ordering::SeqCst)
}
