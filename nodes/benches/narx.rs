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
use evflow_nodes::narx::packed::{PackedMlp, Tanh};
use evflow_nodes::narx::taps::Taps;
use evflow_nodes::narx::train::{lm, Data, Options};
use std::hint::black_box;

fn network(taps: Taps, hidden: &[usize]) -> Mlp {
    let mut net = Mlp::new(taps.n_inputs(), hidden).unwrap();
    net.init_nguyen_widrow(&mut evflow_nodes::rng::Rng::new(1));
    net
}

/// The closed loop as it ran before the blocked layout (issue 13, point 6):
/// `Mlp::forward` on a row filled through modulo-indexed rings — the
/// baseline the new loop is measured against, in the same run.
struct Reference {
    net: Mlp,
    ws: evflow_nodes::narx::net::Workspace,
    taps: Taps,
    xh: Vec<f64>,
    yh: Vec<f64>,
    xpos: usize,
    ypos: usize,
    row: Vec<f64>,
}

impl Reference {
    fn new(net: Mlp, taps: Taps) -> Self {
        let ws = net.workspace();
        let row = vec![0.0; taps.n_inputs()];
        let nx = taps.input + taps.latency() + 1;
        Self { net, ws, taps, xh: vec![0.0; nx], yh: vec![0.0; taps.feedback.max(1)], xpos: 0, ypos: 0, row }
    }

    fn step(&mut self, x: f64) -> f64 {
        let nx = self.xh.len();
        self.xpos = if self.xpos + 1 == nx { 0 } else { self.xpos + 1 };
        self.xh[self.xpos] = x;
        let skip = (self.taps.latency() as i64 - self.taps.lookahead) as usize;
        let (xh, xpos, yh, ypos) = (&self.xh, self.xpos, &self.yh, self.ypos);
        let ny = yh.len();
        self.taps.fill(&mut self.row, |k| yh[(ypos + ny + 1 - k) % ny], |j| xh[(xpos + 2 * nx - skip - j) % nx]);
        let y = self.net.forward(&self.row, &mut self.ws).clamp(-1.0, 1.0);
        if self.taps.feedback > 0 {
            self.ypos = if self.ypos + 1 == ny { 0 } else { self.ypos + 1 };
            self.yh[self.ypos] = y;
        }
        y
    }
}

/// One closed-loop sample of the shipped model size (15-10-5, taps 1/10/3,
/// as graphs/data/models/*.json) and of the dissertation's (taps 10/10/−1):
/// the loop before this layout, and the loop now with the exact and the
/// fast tanh. Throughput = 1 / time per sample.
fn closed_loop(c: &mut Criterion) {
    let map = MapMinMax { min: -1.0, max: 1.0 };
    let force: Vec<f64> = (0..1024).map(|i| (i as f64 * 0.37).sin() * 0.3).collect();
    for (name, taps) in [
        ("15-10-5, taps 1-10-3 (shipped)", Taps { feedback: 1, input: 10, lookahead: 3 }),
        ("15-10-5, taps 10-10--1 (dissertation)", Taps { feedback: 10, input: 10, lookahead: -1 }),
    ] {
        let mut g = c.benchmark_group(format!("closed_loop_sample/{name}"));
        let mut reference = Reference::new(network(taps, &[15, 10, 5]), taps);
        let mut i = 0;
        g.bench_function("before (Mlp::forward, modulo rings)", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(reference.step(black_box(force[i])))
            })
        });
        for tanh in [Tanh::Exact, Tanh::Fast] {
            let mut cl = ClosedLoop::with_tanh(network(taps, &[15, 10, 5]), taps, map, map, tanh);
            g.bench_function(format!("blocked, {} tanh", tanh.name()), |b| {
                b.iter(|| {
                    i = (i + 1) & 1023;
                    black_box(cl.step(black_box(force[i])))
                })
            });
        }
        g.finish();
    }
}

/// The forward pass alone on independent rows (open loop, as in training
/// and evaluation): no sample waits for the one before, so this is the
/// throughput bound of the closed loop, which must wait.
fn forward(c: &mut Criterion) {
    let taps = Taps { feedback: 1, input: 10, lookahead: 3 };
    let net = network(taps, &[15, 10, 5]);
    let mut r = evflow_nodes::rng::Rng::new(3);
    let rows: Vec<f64> = (0..1024 * 15).map(|_| 2.0 * r.uniform() - 1.0).collect();
    let mut g = c.benchmark_group("forward_sample/15-10-5, 15 inputs");
    let mut ws = net.workspace();
    let mut i = 0;
    g.bench_function("Mlp::forward (exact tanh)", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(net.forward(black_box(&rows[i * 15..(i + 1) * 15]), &mut ws))
        })
    });
    for tanh in [Tanh::Exact, Tanh::Fast] {
        let mut p = PackedMlp::new(&net, tanh);
        g.bench_function(format!("blocked, {} tanh", tanh.name()), |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(p.forward(black_box(&rows[i * 15..(i + 1) * 15]), &[]))
            })
        });
    }
    g.finish();
}

/// The tanh alone: four values per call, independent of each other from
/// call to call (throughput) or each call's input the last call's output
/// (latency: what one hidden layer adds to a closed-loop sample's chain of
/// dependent work), beside `f64::tanh` on the same four values.
fn tanh(c: &mut Criterion) {
    use evflow_nodes::narx::fast_tanh::tanh_lanes;
    let xs: Vec<[f64; 4]> = (0..1024).map(|i| [0.01 * i as f64 - 5.0, 0.3, -1.7 + 0.001 * i as f64, 2.5]).collect();
    let mut g = c.benchmark_group("tanh/4 values");
    let mut i = 0;
    g.bench_function("f64::tanh, independent", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(black_box(xs[i]).map(f64::tanh))
        })
    });
    g.bench_function("exact written out, one at a time, independent", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(black_box(xs[i]).map(evflow_nodes::narx::exact_tanh::tanh))
        })
    });
    #[cfg(target_arch = "x86_64")]
    if evflow_nodes::cpu::has_avx2_fma() {
        use evflow_nodes::narx::exact_tanh_avx2::tanh4;
        g.bench_function("exact written out, four lanes (AVX2), independent", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                // SAFETY: AVX2 and FMA checked above.
                black_box(unsafe { tanh4(black_box(xs[i])) })
            })
        });
        // Each call waits on the last: the latency a hidden layer's tanh
        // adds to a closed-loop sample (docs/benchmarks.md, "the closed
        // loop's floor").
        let mut v = [0.1, 0.2, 0.3, 0.4];
        g.bench_function("exact written out, four lanes (AVX2), dependent chain", |b| {
            b.iter(|| {
                // SAFETY: AVX2 and FMA checked above.
                let y = unsafe { tanh4(v) };
                v = [y[0] + 0.5, y[1] - 0.5, y[2] * 2.0, y[3] + 0.25];
            })
        });
        black_box(v);
    }
    g.bench_function("fast, independent", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(tanh_lanes(black_box(xs[i])))
        })
    });
    let mut v = [0.1, 0.2, 0.3, 0.4];
    g.bench_function("fast, dependent chain", |b| {
        b.iter(|| {
            let y = tanh_lanes(v);
            v = [y[0] + 0.5, y[1] - 0.5, y[2] * 2.0, y[3] + 0.25];
        })
    });
    g.finish();
    black_box(v);
}

fn lm_epoch(c: &mut Criterion) {
    let taps = Taps { feedback: 1, input: 10, lookahead: 3 };
    let n = 3000;
    let mut r = evflow_nodes::rng::Rng::new(2);
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

criterion_group!(benches, closed_loop, forward, tanh, lm_epoch, default_training);
criterion_main!(benches);
