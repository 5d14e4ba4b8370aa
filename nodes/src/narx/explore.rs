//! Exploration (not a test of record).
use super::eval;
use super::fit::{fit, FitConfig};
use super::taps::choose_lookahead;
use super::testdata::{prbs, rbs, Lab};
use super::train::Options;

fn env(name: &str, d: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(d)
}

#[test]
#[ignore]
fn explore() {
    let lab = Lab { noise: env("NOISE", 10) as f64 / 10.0, ..Lab::default() };
    let n = env("N", 4000);
    let u = if std::env::var("TRAIN").as_deref() == Ok("prbs9") { prbs(9, n) } else { rbs(n, 1) };
    let x = lab.force(&u);
    let a = choose_lookahead(&u, &x, 10).unwrap();
    eprintln!(
        "xcorr {:?} peak {} d {}",
        a.correlation.iter().map(|c| format!("{c:.3}")).collect::<Vec<_>>(),
        a.peak,
        a.lookahead
    );
    let hidden: Vec<usize> =
        std::env::var("H").unwrap_or("15,10,5".into()).split(',').map(|s| s.parse().unwrap()).collect();
    let cfg = FitConfig {
        hidden,
        feedback: env("KY", 2),
        input: env("KX", 10),
        lookahead: std::env::var("D").ok().map(|v| v.parse().unwrap()),
        options: Options { max_epochs: env("EP", 50), ..Options::default() },
        ..FitConfig::default()
    };
    let t0 = std::time::Instant::now();
    let m = fit(&x, &u, &cfg, &mut |e| {
        eprintln!("epoch {} train {:.4} val {:.4} mu {:.0e} t {:.1}", e.epoch, e.train_mse, e.val_mse, e.mu, e.seconds)
    })
    .unwrap();
    eprintln!(
        "trained in {:.1}s: {:?} closed {:?}",
        t0.elapsed().as_secs_f64(),
        m.training.stop,
        m.training.closed_loop
    );
    for (name, v) in
        [("rbs", rbs(3000, 77)), ("prbs7", prbs(7, 3000)), ("prbs9", prbs(9, 3000)), ("prbs11", prbs(11, 3000))]
    {
        let xv = Lab { seed: 99, ..lab }.force(&v);
        let est = m.closed_loop().unwrap().run(&xv);
        let s = eval::score(&est, &v).unwrap();
        let tr = eval::transition_agreement(&est, &v).unwrap();
        // noise in place of force
        let mut r = crate::lab::rng::Rng::new(5);
        let sd = (xv.iter().map(|a| a * a).sum::<f64>() / xv.len() as f64).sqrt();
        let xn: Vec<f64> = (0..xv.len()).map(|_| sd * r.gaussian()).collect();
        let en = m.closed_loop().unwrap().run(&xn);
        let sn = eval::score(&en, &v).unwrap();
        eprintln!(
            "{name}: sign {:.3} rms {:.3} transitions {:.3} | noise-force sign {:.3}",
            s.sign_agreement, s.rms, tr, sn.sign_agreement
        );
    }
}

#[test]
#[ignore]
fn explore_transitions() {
    let lab = Lab { noise: env("NOISE", 10) as f64 / 10.0, ..Lab::default() };
    let n = env("N", 4000);
    let u = rbs(n, 1);
    let x = lab.force(&u);
    let s: Vec<f64> = (0..n).map(|i| if i == 0 { 1.0 } else { u[i] * u[i - 1] }).collect();
    let hidden: Vec<usize> =
        std::env::var("H").unwrap_or("15,10,5".into()).split(',').map(|s| s.parse().unwrap()).collect();
    let cfg = FitConfig {
        hidden,
        feedback: 0,
        input: env("KX", 10),
        lookahead: Some(env("D", 3) as i64),
        options: Options { max_epochs: env("EP", 50), ..Options::default() },
        ..FitConfig::default()
    };
    let m = fit(&x, &s, &cfg, &mut |_| {}).unwrap();
    eprintln!(
        "train {:.4} val {:?} stop {:?} ep {}",
        m.training.train_mse, m.training.validation_mse, m.training.stop, m.training.epochs
    );
    let v = rbs(3000, 77);
    let xv = Lab { seed: 99, ..lab }.force(&v);
    let sv: Vec<f64> = (0..3000).map(|i| if i == 0 { 1.0 } else { v[i] * v[i - 1] }).collect();
    let est = m.closed_loop().unwrap().run(&xv);
    let sc = eval::score(&est, &sv).unwrap();
    eprintln!("transition detection: {:.4}", sc.sign_agreement);
}

#[test]
#[ignore]
fn explore_signal() {
    for noise in [0.0, 1.0] {
        let lab = Lab { noise, ..Lab::default() };
        let u = rbs(4000, 1);
        let x = lab.force(&u);
        for lag in 0..4usize {
            // statistic: x[n+lag] - x[n-1]
            let mut a = Vec::new();
            let mut b = Vec::new();
            for n in 20..3990 {
                let st = x[n + lag] - x[n - 1];
                if u[n] != u[n - 1] {
                    a.push(st)
                } else {
                    b.push(st)
                }
            }
            let mean = |v: &Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
            let sd = |v: &Vec<f64>| {
                let m = mean(v);
                (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
            };
            // best threshold accuracy
            let mut all: Vec<(f64, bool)> = a.iter().map(|&v| (v, true)).chain(b.iter().map(|&v| (v, false))).collect();
            all.sort_by(|p, q| p.0.total_cmp(&q.0));
            let tot = all.len() as f64;
            let mut best = 0.0f64;
            let ntrue = a.len() as f64;
            let mut below_true = 0.0;
            let mut below_false = 0.0;
            for (_, t) in &all {
                if *t {
                    below_true += 1.0
                } else {
                    below_false += 1.0
                };
                let acc1 = (below_false + (ntrue - below_true)) / tot;
                best = best.max(acc1).max(1.0 - acc1);
            }
            eprintln!(
                "noise {noise} lag {lag}: trans {:.4}±{:.4} none {:.4}±{:.4} best-threshold acc {:.3}",
                mean(&a),
                sd(&a),
                mean(&b),
                sd(&b),
                best
            );
        }
        eprintln!("x[0..40] {:?}", &x[100..130].iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>());
        eprintln!("u        {:?}", &u[100..130].iter().map(|v| if *v > 0.0 { "+" } else { "-" }).collect::<String>());
    }
}
