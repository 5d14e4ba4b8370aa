//! One evaluation of the achievable floors' objective through the display's
//! twin (`study/src/twin/`): a forward pass over a tribometer stroke
//! (85 g at 5 cm/s, the nominal profile, 4 substeps) and the backward pass
//! of its gradient — the loop `report live` and `report textures` spend
//! most of their time in; and both passes of two actuations side by side
//! (`forward2`, `backward2`), and four passes in the lanes of one
//! register (`forward4`, `backward4`); and the objective's value and
//! gradient at one, two and four actuations (`objective_grad_each`).
//! `cargo bench -p evflow-study --bench twin`.

use criterion::{criterion_group, criterion_main, Criterion};
use evflow_nodes::lab::integrator::Method;
use evflow_nodes::lab::profile::LabProfile;
use evflow_nodes::lab::tribometer_model::TribometerModel;
use evflow_study::twin::{DisplayTwin, Tape, Tapes};
use std::hint::black_box;

/// The nominal profile's twin and its tribometer stroke (load, velocity).
fn stroke() -> (DisplayTwin, Vec<f64>, Vec<f64>) {
    let profile = LabProfile::default();
    let mut t = TribometerModel::new(&profile, 1000.0, 0.05, 0.085, 1, Method::Exact, 4).expect("a valid stroke");
    let n = t.total_samples().expect("a finite stroke") as usize;
    let (mut load, mut vel) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        let (_, v, l) = t.step();
        vel.push(v);
        load.push(l);
    }
    (DisplayTwin::new(&profile, 1000.0, 4).expect("the nominal profile"), load, vel)
}

fn passes(c: &mut Criterion) {
    let (twin, load, vel) = stroke();
    let n = load.len();
    let mut r = evflow_nodes::rng::Rng::new(4);
    let u: Vec<f64> =
        (0..n).map(|k| if k % 2 == 0 { 0.6 } else { -0.6 } * (1.0 + 0.4 * (2.0 * r.uniform() - 1.0))).collect();
    let fbar: Vec<f64> = (0..n).map(|k| ((k * 7 % 13) as f64 - 6.0) * 0.1).collect();
    let mut tape = Tape::default();
    c.bench_function(&format!("twin/forward, {n} samples"), |b| {
        b.iter(|| black_box(twin.forward(black_box(&u), &load, &vel, &mut tape)))
    });
    let mut g = vec![0.0; n];
    c.bench_function(&format!("twin/backward, {n} samples"), |b| {
        b.iter(|| {
            twin.backward(&tape, black_box(&fbar), &mut g);
            black_box(g[0])
        })
    });
    // Two actuations side by side (two floors' starts in lockstep): time
    // per pair, against twice the single pass above.
    let u2: Vec<f64> = u.iter().map(|v| -0.8 * v).collect();
    let mut tape2 = Tape::default();
    c.bench_function(&format!("twin/forward2, two passes of {n} samples"), |b| {
        b.iter(|| black_box(twin.forward2([black_box(&u), &u2], &load, &vel, [&mut tape, &mut tape2])))
    });
    // Four in the lanes of one register (`forward4`): time per four.
    let (u3, u4): (Vec<f64>, Vec<f64>) = (u.iter().map(|v| 0.5 * v).collect(), u.iter().map(|v| -v).collect());
    let (mut tape3, mut tape4) = (Tape::default(), Tape::default());
    c.bench_function(&format!("twin/forward4, four passes of {n} samples"), |b| {
        b.iter(|| {
            let tapes = [&mut tape, &mut tape2, &mut tape3, &mut tape4];
            black_box(twin.forward4([black_box(&u), &u2, &u3, &u4], &load, &vel, tapes))
        })
    });
    let mut g2 = vec![0.0; n];
    c.bench_function(&format!("twin/backward2, two passes of {n} samples"), |b| {
        b.iter(|| {
            twin.backward2([&tape, &tape2], [black_box(&fbar), &fbar], [&mut g, &mut g2]);
            black_box(g[0] + g2[0])
        })
    });
    let (mut g3, mut g4) = (vec![0.0; n], vec![0.0; n]);
    c.bench_function(&format!("twin/backward4, four passes of {n} samples"), |b| {
        b.iter(|| {
            let tapes = [&tape, &tape2, &tape3, &tape4];
            twin.backward4(tapes, [black_box(&fbar), &fbar, &fbar, &fbar], [&mut g, &mut g2, &mut g3, &mut g4]);
            black_box(g[0] + g4[0])
        })
    });
}

/// An objective's value and gradient (J = Σ f̄·F) at one, two and four
/// actuations side by side (`objective_grad_each`): time per call.
fn objectives(c: &mut Criterion) {
    let (twin, load, vel) = stroke();
    let n = load.len();
    let mut r = evflow_nodes::rng::Rng::new(4);
    let us: Vec<Vec<f64>> = (0..4)
        .map(|k| {
            (0..n).map(|j| if j % 2 == 0 { 0.6 } else { -0.6 } * (1.0 - 0.2 * k as f64 + 0.3 * r.uniform())).collect()
        })
        .collect();
    let fbar: Vec<f64> = (0..n).map(|k| ((k * 7 % 13) as f64 - 6.0) * 0.1).collect();
    let mut tapes = Tapes::default();
    let mut gs: Vec<Vec<f64>> = (0..4).map(|_| vec![0.0; n]).collect();
    for m in [1, 2, 4] {
        c.bench_function(&format!("twin/objective, {m} side by side"), |b| {
            b.iter(|| {
                let u: Vec<&[f64]> = us[..m].iter().map(|u| black_box(u.as_slice())).collect();
                let mut g: Vec<&mut [f64]> = gs[..m].iter_mut().map(|g| g.as_mut_slice()).collect();
                let mut fx = [0.0; 4];
                twin.objective_grad_each(&u, (&load, &vel), &mut tapes, &mut g, &mut fx[..m], |_, f| {
                    (f.iter().zip(&fbar).map(|(a, b)| a * b).sum(), fbar.clone())
                });
                black_box(fx)
            })
        });
    }
}

criterion_group!(benches, passes, objectives);
criterion_main!(benches);
