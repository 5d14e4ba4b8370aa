//! One table sample of `interp` (`nodes/src/texture/kernel.rs`): the
//! windowed-sinc evaluation of a mix of two cells, as the scalar loop
//! ([`SincKernel::eval`] with the mix as a closure) and as `interp` runs it
//! ([`eval_mix`]: four taps at a time on AVX2), side by side.
//! Shipped kernel (W = 16) at the cutoff of a ratio ≤ 1 (0.9: 36 taps) and
//! of a ratio of 2 (0.45: 72 taps). `cargo bench -p evflow-nodes --bench interp`.

use criterion::{criterion_group, criterion_main, Criterion};
use evflow_nodes::texture::kernel::SincKernel;
use evflow_nodes::texture::kernel_mix::eval_mix;
use std::hint::black_box;

fn sample(c: &mut Criterion) {
    let k = SincKernel::for_interp(16);
    let u0: Vec<f64> = (0..4000).map(|n| (n as f64 * 0.21).sin()).collect();
    let u1: Vec<f64> = (0..4000).map(|n| 0.5 * (n as f64 * 0.63).sin()).collect();
    let (a0, a1) = (0.3, 0.7);
    for cut in [0.9, 0.45] {
        let mut p = 100.0;
        c.bench_function(&format!("interp_sample/scalar, cutoff {cut}"), |b| {
            b.iter(|| {
                p = if p > 3800.0 { 100.0 } else { p + 1.37 };
                black_box(k.eval(black_box(p), cut, 4000, |q| a0 * u0[q] + a1 * u1[q]))
            })
        });
        let mut p = 100.0;
        c.bench_function(&format!("interp_sample/eval_mix, cutoff {cut}"), |b| {
            b.iter(|| {
                p = if p > 3800.0 { 100.0 } else { p + 1.37 };
                black_box(eval_mix(&k, black_box(p), cut, &u0, &u1, a0, a1))
            })
        });
    }
}

criterion_group!(benches, sample);
criterion_main!(benches);
