//! Benchmarks of the Volterra forward model (`synth::volterra`): `eval` and
//! `eval_grad` per sample at memory 20, beside the per-row dot products the
//! model used before (issue 13, point 6), measured in the same run.
//!
//! `cargo bench -p evflow-nodes --bench volterra`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use evflow_nodes::rng::Rng;
use evflow_nodes::synth::volterra::Volterra;
use std::hint::black_box;

const MEMORY: usize = 20;
const SAMPLES: usize = 3000;

fn model() -> Volterra {
    let mut r = Rng::new(1);
    let upper: Vec<f64> = (0..MEMORY * (MEMORY + 1) / 2).map(|_| r.gaussian()).collect();
    let l: Vec<f64> = (0..MEMORY).map(|_| r.gaussian()).collect();
    Volterra::from_upper(&upper, l, 0.1).unwrap()
}

/// `eval` as it was: one dot product of a row of H with the window per i.
fn eval_before(v: &Volterra, h: &[f64], u: &[f64], y: &mut [f64]) {
    let m = v.memory();
    let mut w = vec![0.0; m];
    for (n, yn) in y.iter_mut().enumerate().take(u.len()) {
        for (i, wi) in w.iter_mut().enumerate() {
            *wi = if i <= n { u[n - i] } else { 0.0 };
        }
        let mut acc = v.constant();
        for i in 0..m {
            let zi: f64 = h[i * m..(i + 1) * m].iter().zip(&w).map(|(a, b)| a * b).sum();
            acc += w[i] * (zi + v.linear()[i]);
        }
        *yn = acc;
    }
}

fn volterra(c: &mut Criterion) {
    let v = model();
    let m = v.memory();
    let h: Vec<f64> = (0..m * m).map(|k| v.quadratic(k / m, k % m)).collect();
    let mut r = Rng::new(2);
    let u: Vec<f64> = (0..SAMPLES).map(|_| 2.0 * r.uniform() - 1.0).collect();
    let ybar: Vec<f64> = (0..SAMPLES).map(|_| r.gaussian()).collect();
    let (mut y, mut du) = (vec![0.0; SAMPLES], vec![0.0; SAMPLES]);
    let mut g = c.benchmark_group(format!("volterra/memory {MEMORY}, {SAMPLES} samples"));
    g.throughput(Throughput::Elements(SAMPLES as u64));
    g.bench_function("eval before (row dot products)", |b| b.iter(|| eval_before(&v, &h, black_box(&u), &mut y)));
    g.bench_function("eval", |b| b.iter(|| v.eval(black_box(&u), &mut y)));
    g.bench_function("eval_grad", |b| {
        b.iter(|| {
            du.fill(0.0);
            v.eval_grad(black_box(&u), &ybar, &mut y, &mut du)
        })
    });
    g.finish();
}

criterion_group!(benches, volterra);
criterion_main!(benches);
