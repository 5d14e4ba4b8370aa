//! History windows and delay lines: the hand-written rings the nodes use
//! beside ringbuf 0.4's `LocalRb` (single-threaded) and `HeapRb` (its
//! thread-safe ring), in the same run (issue 14, point 5). Three access
//! patterns:
//!
//! * **delay line** — the `delay` node: per block, read the d-old samples
//!   out and write the block's inputs in (chunks of at most d);
//! * **tap window** — NARX closed loop: per sample, push one value and read
//!   the last n values newest first (here: a dot product with n weights);
//! * **FOAW window** — the `foaw` estimator: per sample, push one position
//!   and read positions j back at random, O(N²) reads per sample.
//!
//! Every variant computes the same numbers (checked before timing, on
//! integer-valued data so that sums in any order agree exactly).
//!
//! `cargo bench -p evflow-nodes --bench histories`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use evflow_nodes::filters::foaw::estimator::{Fit, Foaw};
use ringbuf::storage::Heap;
use ringbuf::traits::{Consumer, Observer, Producer, RingBuffer};
use ringbuf::{HeapRb, LocalRb};
use std::hint::black_box;

/// Samples per timed call.
const SAMPLES: usize = 4096;

/// Integer-valued input, so every summation order gives the same bits.
fn input() -> Vec<f64> {
    (0..SAMPLES).map(|k| ((k * 7919) % 23) as f64 - 11.0).collect()
}

// ---------------------------------------------------------------- delay line

/// A delay line of d samples: `run` pushes `x` through it in blocks.
trait DelayLine {
    /// Writes y[n] = x[n − d] for one block of at most d samples.
    fn chunk(&mut self, x: &[f64], y: &mut [f64]);
}

/// The `delay` node's ring (`nodes/src/filters/delay.rs`): a Vec of d
/// samples and the position of the oldest; two `copy_from_slice` each way.
struct HandDelay {
    ring: Vec<f64>,
    pos: usize,
}

impl HandDelay {
    fn new(d: usize) -> Self {
        HandDelay { ring: vec![0.0; d], pos: 0 }
    }
}

impl DelayLine for HandDelay {
    fn chunk(&mut self, x: &[f64], y: &mut [f64]) {
        let d = self.ring.len();
        let first = y.len().min(d - self.pos);
        let (a, b) = y.split_at_mut(first);
        a.copy_from_slice(&self.ring[self.pos..self.pos + first]);
        b.copy_from_slice(&self.ring[..b.len()]);
        let first = x.len().min(d - self.pos);
        self.ring[self.pos..self.pos + first].copy_from_slice(&x[..first]);
        let rest = &x[first..];
        self.ring[..rest.len()].copy_from_slice(rest);
        self.pos = (self.pos + x.len()) % d;
    }
}

/// ringbuf's single-threaded ring, kept full, as the `delay` node would use
/// it (its `emit` reads without consuming, its `absorb` writes later):
/// `peek_slice` the oldest samples out, `push_slice_overwrite` the new ones
/// in.
struct LocalDelay(LocalRb<Heap<f64>>);

impl LocalDelay {
    fn new(d: usize) -> Self {
        LocalDelay(LocalRb::from(vec![0.0; d]))
    }
}

impl DelayLine for LocalDelay {
    fn chunk(&mut self, x: &[f64], y: &mut [f64]) {
        self.0.peek_slice(y);
        self.0.push_slice_overwrite(x);
    }
}

/// The same ring consumed and refilled: `pop_slice` out, `push_slice` in
/// (the ring is full again after each chunk; usable in `process`, where
/// the read and the write come together, not across `emit` / `absorb`).
struct LocalPopPush(LocalRb<Heap<f64>>);

impl DelayLine for LocalPopPush {
    fn chunk(&mut self, x: &[f64], y: &mut [f64]) {
        self.0.pop_slice(y);
        self.0.push_slice(x);
    }
}

/// ringbuf's thread-safe ring (atomic indices), used the same way.
struct SharedDelay(HeapRb<f64>);

impl SharedDelay {
    fn new(d: usize) -> Self {
        SharedDelay(HeapRb::from(vec![0.0; d]))
    }
}

impl DelayLine for SharedDelay {
    fn chunk(&mut self, x: &[f64], y: &mut [f64]) {
        self.0.peek_slice(y);
        self.0.push_slice_overwrite(x);
    }
}

/// Runs `x` through `line` in blocks of `block`, each split into chunks of
/// at most d, as the node does.
fn run_delay(line: &mut impl DelayLine, d: usize, block: usize, x: &[f64], y: &mut [f64]) {
    for (xb, yb) in x.chunks(block).zip(y.chunks_mut(block)) {
        for (xc, yc) in xb.chunks(d).zip(yb.chunks_mut(d)) {
            line.chunk(xc, yc);
        }
    }
}

fn delay_line(c: &mut Criterion) {
    let x = input();
    let mut y = vec![0.0; SAMPLES];
    let mut g = c.benchmark_group(format!("delay line/{SAMPLES} samples"));
    g.throughput(Throughput::Elements(SAMPLES as u64));
    for (d, block) in [(1, 1), (100, 1), (100, 64), (10_000, 1024)] {
        // All four agree with y[n] = x[n − d].
        let want: Vec<f64> = (0..SAMPLES).map(|n| if n >= d { x[n - d] } else { 0.0 }).collect();
        for got in [
            {
                run_delay(&mut HandDelay::new(d), d, block, &x, &mut y);
                y.clone()
            },
            {
                run_delay(&mut LocalDelay::new(d), d, block, &x, &mut y);
                y.clone()
            },
            {
                run_delay(&mut LocalPopPush(LocalRb::from(vec![0.0; d])), d, block, &x, &mut y);
                y.clone()
            },
            {
                run_delay(&mut SharedDelay::new(d), d, block, &x, &mut y);
                y.clone()
            },
        ] {
            assert_eq!(got, want, "d {d} block {block}");
        }
        let case = format!("d {d}, block {block}");
        let mut hand = HandDelay::new(d);
        g.bench_function(BenchmarkId::new("hand ring (delay node)", &case), |b| {
            b.iter(|| run_delay(&mut hand, d, block, black_box(&x), &mut y))
        });
        let mut local = LocalDelay::new(d);
        g.bench_function(BenchmarkId::new("ringbuf LocalRb peek/overwrite", &case), |b| {
            b.iter(|| run_delay(&mut local, d, block, black_box(&x), &mut y))
        });
        let mut pop_push = LocalPopPush(LocalRb::from(vec![0.0; d]));
        g.bench_function(BenchmarkId::new("ringbuf LocalRb pop/push", &case), |b| {
            b.iter(|| run_delay(&mut pop_push, d, block, black_box(&x), &mut y))
        });
        let mut shared = SharedDelay::new(d);
        g.bench_function(BenchmarkId::new("ringbuf HeapRb", &case), |b| {
            b.iter(|| run_delay(&mut shared, d, block, black_box(&x), &mut y))
        });
    }
    g.finish();
}

// ---------------------------------------------------------------- tap window

/// A window of the last n samples: push one, then the dot product of the
/// window, newest first, with `w` (w[0] for the newest).
trait TapWindow {
    fn push_dot(&mut self, v: f64, w: &[f64]) -> f64;
}

/// The NARX closed loop's mirrored ring (`nodes/src/narx/closed_loop.rs`):
/// each sample written at p and p + n, p moving backwards, so the window
/// newest first is the contiguous slice [p, p + n).
struct Mirrored {
    h: Vec<f64>,
    n: usize,
    p: usize,
}

impl Mirrored {
    fn new(n: usize) -> Self {
        Mirrored { h: vec![0.0; 2 * n], n, p: 0 }
    }
}

impl TapWindow for Mirrored {
    #[inline]
    fn push_dot(&mut self, v: f64, w: &[f64]) -> f64 {
        self.p = if self.p == 0 { self.n - 1 } else { self.p - 1 };
        self.h[self.p] = v;
        self.h[self.p + self.n] = v;
        self.h[self.p..self.p + self.n].iter().zip(w).map(|(a, b)| a * b).sum()
    }
}

/// A plain ring read with a modulo per tap (the NARX loop before issue 13;
/// `foaw`'s `back(j)` today).
struct Modulo {
    h: Vec<f64>,
    head: usize,
}

impl Modulo {
    fn new(n: usize) -> Self {
        Modulo { h: vec![0.0; n], head: 0 }
    }
}

impl TapWindow for Modulo {
    #[inline]
    fn push_dot(&mut self, v: f64, w: &[f64]) -> f64 {
        let n = self.h.len();
        self.head = (self.head + 1) % n;
        self.h[self.head] = v;
        (0..n).map(|j| self.h[(self.head + n - j) % n] * w[j]).sum()
    }
}

/// ringbuf's `LocalRb`, kept full: `push_overwrite`, then `as_slices`
/// (oldest first, in two pieces) against the weights reversed.
struct Local {
    rb: LocalRb<Heap<f64>>,
}

impl Local {
    fn new(n: usize) -> Self {
        let mut rb = LocalRb::new(n);
        rb.push_iter(std::iter::repeat_n(0.0, n));
        Local { rb }
    }
}

impl TapWindow for Local {
    #[inline]
    fn push_dot(&mut self, v: f64, w_rev: &[f64]) -> f64 {
        self.rb.push_overwrite(v);
        let (a, b) = self.rb.as_slices();
        let (wa, wb) = w_rev.split_at(a.len());
        a.iter().zip(wa).map(|(x, w)| x * w).sum::<f64>() + b.iter().zip(wb).map(|(x, w)| x * w).sum::<f64>()
    }
}

/// A shift register: `copy_within` by one, then the contiguous window.
struct Shift {
    h: Vec<f64>,
}

impl TapWindow for Shift {
    #[inline]
    fn push_dot(&mut self, v: f64, w: &[f64]) -> f64 {
        let n = self.h.len();
        self.h.copy_within(0..n - 1, 1);
        self.h[0] = v;
        self.h.iter().zip(w).map(|(a, b)| a * b).sum()
    }
}

fn run_taps(win: &mut impl TapWindow, x: &[f64], w: &[f64]) -> f64 {
    let mut acc = 0.0;
    for &v in x {
        acc += win.push_dot(v, w);
    }
    acc
}

fn tap_window(c: &mut Criterion) {
    let x = input();
    let mut g = c.benchmark_group(format!("tap window/{SAMPLES} samples"));
    g.throughput(Throughput::Elements(SAMPLES as u64));
    for n in [5usize, 16, 64] {
        let w: Vec<f64> = (0..n).map(|j| ((j * 5) % 7) as f64 - 3.0).collect();
        let w_rev: Vec<f64> = w.iter().rev().copied().collect();
        let want = run_taps(&mut Mirrored::new(n), &x, &w);
        assert_eq!(run_taps(&mut Modulo::new(n), &x, &w), want, "n {n}");
        assert_eq!(run_taps(&mut Local::new(n), &x, &w_rev), want, "n {n}");
        assert_eq!(run_taps(&mut Shift { h: vec![0.0; n] }, &x, &w), want, "n {n}");
        let case = format!("n {n}");
        let mut m = Mirrored::new(n);
        g.bench_function(BenchmarkId::new("mirrored ring (narx)", &case), |b| {
            b.iter(|| run_taps(&mut m, black_box(&x), &w))
        });
        let mut r = Modulo::new(n);
        g.bench_function(BenchmarkId::new("modulo ring", &case), |b| b.iter(|| run_taps(&mut r, black_box(&x), &w)));
        let mut l = Local::new(n);
        g.bench_function(BenchmarkId::new("ringbuf LocalRb", &case), |b| {
            b.iter(|| run_taps(&mut l, black_box(&x), &w_rev))
        });
        let mut s = Shift { h: vec![0.0; n] };
        g.bench_function(BenchmarkId::new("shift register", &case), |b| b.iter(|| run_taps(&mut s, black_box(&x), &w)));
    }
    g.finish();
}

// ---------------------------------------------------------------- FOAW window

/// The positions an estimator looks back on.
trait Positions {
    /// Appends the newest position (the oldest falls out when full).
    fn push(&mut self, y: f64);
    /// The position `j` samples before the newest (j < `len`).
    fn back(&self, j: usize) -> f64;
    /// Positions held.
    fn len(&self) -> usize;
}

/// `foaw`'s ring (`nodes/src/filters/foaw/estimator.rs`): head, length and a
/// modulo per read.
struct FoawRing {
    ring: Vec<f64>,
    head: usize,
    len: usize,
}

impl Positions for FoawRing {
    #[inline]
    fn push(&mut self, y: f64) {
        let cap = self.ring.len();
        self.head = (self.head + 1) % cap;
        self.ring[self.head] = y;
        self.len = (self.len + 1).min(cap);
    }
    #[inline]
    fn back(&self, j: usize) -> f64 {
        let cap = self.ring.len();
        self.ring[(self.head + cap - j) % cap]
    }
    #[inline]
    fn len(&self) -> usize {
        self.len
    }
}

/// A mirrored ring: the window newest first is one slice.
struct FoawMirrored {
    h: Vec<f64>,
    n: usize,
    p: usize,
    len: usize,
}

impl Positions for FoawMirrored {
    #[inline]
    fn push(&mut self, y: f64) {
        self.p = if self.p == 0 { self.n - 1 } else { self.p - 1 };
        self.h[self.p] = y;
        self.h[self.p + self.n] = y;
        self.len = (self.len + 1).min(self.n);
    }
    #[inline]
    fn back(&self, j: usize) -> f64 {
        self.h[self.p + j]
    }
    #[inline]
    fn len(&self) -> usize {
        self.len
    }
}

/// ringbuf's `LocalRb`: `push_overwrite`, and a read j back from
/// `as_slices` (oldest first).
struct FoawLocal(LocalRb<Heap<f64>>);

impl Positions for FoawLocal {
    #[inline]
    fn push(&mut self, y: f64) {
        self.0.push_overwrite(y);
    }
    #[inline]
    fn back(&self, j: usize) -> f64 {
        let (a, b) = self.0.as_slices();
        let i = a.len() + b.len() - 1 - j;
        if i < a.len() {
            a[i]
        } else {
            b[i - a.len()]
        }
    }
    #[inline]
    fn len(&self) -> usize {
        self.0.occupied_len()
    }
}

/// The best-fit FOAW step of the estimator, over any [`Positions`] (the
/// same arithmetic, in the same order, as `Foaw::push`).
fn foaw_step(h: &mut impl Positions, y: f64, noise: f64, t: f64) -> f64 {
    h.push(y);
    let len = h.len();
    if len < 2 {
        return 0.0;
    }
    let mut accepted = (y - h.back(1)) / t;
    let (mut s0, mut s1) = (h.back(1) - y, h.back(1) - y);
    for n in 2..len {
        let yn = h.back(n);
        s0 += yn - y;
        s1 += n as f64 * (yn - y);
        let nf = n as f64;
        let b = (nf * s0 - 2.0 * s1) / (t * nf * (nf + 1.0) * (nf + 2.0) / 6.0);
        if !(1..n).all(|j| (h.back(j) - (y - b * j as f64 * t)).abs() <= noise) {
            break;
        }
        accepted = b;
    }
    if accepted.is_finite() {
        accepted
    } else {
        0.0
    }
}

fn run_foaw(h: &mut impl Positions, x: &[f64], noise: f64, t: f64) -> f64 {
    x.iter().map(|&y| foaw_step(h, y, noise, t)).sum()
}

fn foaw_window(c: &mut Criterion) {
    // A slow ramp quantized to 0.5 mm at 40 Hz: long windows, the costly case.
    let (t, noise) = (0.025, 0.0004);
    let x: Vec<f64> = (0..SAMPLES).map(|k| (0.03 * k as f64 * t / 0.0005).round() * 0.0005).collect();
    let mut g = c.benchmark_group(format!("foaw window/{SAMPLES} samples"));
    g.throughput(Throughput::Elements(SAMPLES as u64));
    for window in [4usize, 16] {
        let cap = window + 1;
        let shipped = |x: &[f64]| {
            let mut f = Foaw::new(Fit::Best, noise, t, window);
            x.iter().map(|&y| f.push(y)).sum::<f64>()
        };
        let ring = || FoawRing { ring: vec![0.0; cap], head: 0, len: 0 };
        let mirrored = || FoawMirrored { h: vec![0.0; 2 * cap], n: cap, p: 0, len: 0 };
        let local = || FoawLocal(LocalRb::new(cap));
        let want = shipped(&x);
        assert_eq!(run_foaw(&mut ring(), &x, noise, t), want, "window {window}");
        assert_eq!(run_foaw(&mut mirrored(), &x, noise, t), want, "window {window}");
        assert_eq!(run_foaw(&mut local(), &x, noise, t), want, "window {window}");
        let case = format!("N {window}");
        g.bench_function(BenchmarkId::new("Foaw::push (shipped)", &case), |b| b.iter(|| shipped(black_box(&x))));
        g.bench_function(BenchmarkId::new("modulo ring", &case), |b| {
            b.iter(|| run_foaw(&mut ring(), black_box(&x), noise, t))
        });
        g.bench_function(BenchmarkId::new("mirrored ring", &case), |b| {
            b.iter(|| run_foaw(&mut mirrored(), black_box(&x), noise, t))
        });
        g.bench_function(BenchmarkId::new("ringbuf LocalRb", &case), |b| {
            b.iter(|| run_foaw(&mut local(), black_box(&x), noise, t))
        });
    }
    g.finish();
}

criterion_group!(benches, delay_line, tap_window, foaw_window);
criterion_main!(benches);
