//! One tick of the live synthesis' receding horizon (`synth.live`,
//! `nodes/src/synth/live/horizon.rs`) at the shipped size: memory 20,
//! horizon 16, 4 iterations — the part of the texture tick the synthesis
//! takes. `cargo bench -p evflow-nodes --bench horizon`.

use criterion::{criterion_group, criterion_main, Criterion};
use evflow_nodes::synth::live::envelope::EnvelopeModel;
use evflow_nodes::synth::live::horizon::Horizon;
use evflow_nodes::synth::volterra::Volterra;
use std::hint::black_box;

/// A memory-20 model with a decaying, sign-alternating kernel (a display
/// with a short electrical memory) and a small linear term.
fn model() -> EnvelopeModel {
    let m = 20;
    let mut upper = Vec::new();
    for i in 0..m {
        for j in i..m {
            let d = (i + j) as f64;
            upper.push(0.04 * (-0.25 * d).exp() * if (i + j) % 3 == 0 { 1.0 } else { 0.7 });
        }
    }
    let l: Vec<f64> = (0..m).map(|i| 1e-3 * (-(i as f64) / 4.0).exp()).collect();
    EnvelopeModel::of(&Volterra::from_upper(&upper, l, 0.0).expect("a valid kernel"), 1e-4)
}

fn tick(c: &mut Criterion) {
    let model = model();
    let (m, h) = (20, 16);
    // A texture force ahead: two sines, as a grating and its harmonic.
    let target: Vec<f64> =
        (0..4096 + h).map(|k| 0.05 * (k as f64 * 0.21).sin() + 0.02 * (k as f64 * 0.63).sin()).collect();
    for iterations in [0, 4] {
        let mut hz = Horizon::new(m, h);
        let mut n = 0u64;
        c.bench_function(&format!("horizon_tick/M 20, H 16, {iterations} iterations"), |b| {
            b.iter(|| {
                let k = (n % 4096) as usize;
                let out = hz.step(n, black_box(&target[k..k + h]), 0.08, &model, 1.0, iterations, None);
                hz.commit(out.envelope);
                n += 1;
                black_box(out.envelope)
            })
        });
    }
}

criterion_group!(benches, tick);
criterion_main!(benches);
