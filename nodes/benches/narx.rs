//! Benchmarks of the NARX family: closed-loop time per sample (what the
//! `narx` node costs per tick), one Levenberg–Marquardt epoch, and the whole
//! training of the default network on 3066 samples of the simulated lab
//! (issue 6, point 12; `evflow bench narx` reports the same with the
//! closed-loop error it reaches, and `bench/narx_peer.py` sets it beside
//! Python).
//!
//! `cargo bench -p evflow-nodes --bench narx`

use criterion::{criterion_group, criterion_main, Criterion};
use evflow_nodes::narx::closed_loop::ClosedLoop;
use evflow_nodes::narx::mapminmax::MapMinMax;
use evflow_nodes::narx::net::Mlp;
use evflow_nodes::narx::taps::Taps;
use evflow_nodes::narx::train::{lm, Data, Options};
use std::hint::black_box;

fn network(taps: Taps, hidden: &[usize]) -> Mlp {
    let mut net = Mlp::new(taps.n_inputs(), hidden).unwrap();
    net.init_nguyen_widrow(&mut evflow_nodes::lab::rng::Rng::new(1));
    net
}

fn closed_loop(c: &mut Criterion) {
    let map = MapMinMax { min: -1.0, max: 1.0 };
    let force: Vec<f64> = (0..1024).map(|i| (i as f64 * 0.37).sin() * 0.3).collect();
    for (name, taps) in [
        ("closed_loop_sample/15-10-5, taps 1/10/3", Taps { feedback: 1, input: 10, lookahead: 3 }),
        ("closed_loop_sample/15-10-5, taps 10/10/-1 (dissertation)", Taps { feedback: 10, input: 10, lookahead: -1 }),
    ] {
        let mut cl = ClosedLoop::new(network(taps, &[15, 10, 5]), taps, map, map);
        let mut i = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(cl.step(black_box(force[i])))
            })
        });
    }
}

fn lm_epoch(c: &mut Criterion) {
    let taps = Taps { feedback: 1, input: 10, lookahead: 3 };
    let n = 3000;
    let mut r = evflow_nodes::lab::rng::Rng::new(2);
    let x = ndarray::Array2::from_shape_fn((n, taps.n_inputs()), |_| 2.0 * r.uniform() - 1.0);
    let t = ndarray::Array1::from_shape_fn(n, |i| x[(i, 0)] * x[(i, 3)].tanh());
    let data = Data::new(x.view(), t.view()).unwrap();
    let empty = data.slice(0..0);
    let opts = Options { max_epochs: 1, ..Options::default() };
    let mut g = c.benchmark_group("lm");
    g.sample_size(10);
    g.bench_function("epoch/15-10-5, 15 inputs, 3000 rows", |b| {
        b.iter(|| {
            let mut net = network(taps, &[15, 10, 5]);
            black_box(lm::train(&mut net, &data, &empty, &opts, &mut |_| {}))
        })
    });
    g.finish();
}

/// The default network (15-10-5, k_y = 1, k_x = 10, d from the
/// cross-correlation, LM with early stopping) on 3066 samples of a random
/// binary sequence through the nominal simulated lab, as `evflow bench narx`.
fn default_training(c: &mut Criterion) {
    use evflow_nodes::narx::fit::{fit, FitConfig};
    use evflow_nodes::narx::labdata::{rbs, Lab};
    let u = rbs(3066, 1);
    let x = Lab::default().force(&u);
    let cfg = FitConfig { feedback: 1, input: 10, ..FitConfig::default() };
    let mut g = c.benchmark_group("fit");
    g.sample_size(10);
    g.bench_function("default network, 3066 lab samples, LM to the validation stop", |b| {
        b.iter(|| black_box(fit(&x, &u, &cfg, &mut |_| {}).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, closed_loop, lm_epoch, default_training);
criterion_main!(benches);
