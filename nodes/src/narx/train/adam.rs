//! Adam training (Kingma & Ba 2015, "Adam: a method for stochastic
//! optimization", Algorithm 1, with β1 = 0.9, β2 = 0.999, ε = 1e−8): an
//! alternative to Levenberg–Marquardt for networks too large for its
//! P × P system. Mini-batches of `batch` rows in an order reshuffled every
//! epoch (seeded); one epoch is one pass over the training block; early
//! stopping on the validation block as for LM.

use super::epochs::{self, Stepped};
use super::{mse, Data, Epoch, Options, Report, StopReason};
use crate::narx::net::Mlp;
use crate::rng::Rng;

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPS: f64 = 1e-8;

/// Trains `net` in place on `train`, stopping early on `val`.
pub fn train(
    net: &mut Mlp,
    train: &Data<'_>,
    val: &Data<'_>,
    opts: &Options,
    progress: &mut dyn FnMut(&Epoch),
) -> Report {
    let p = net.n_params();
    let n = train.len();
    let mut ws = net.workspace();
    let (mut m, mut v, mut g, mut row) = (vec![0.0; p], vec![0.0; p], vec![0.0; p], vec![0.0; p]);
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = Rng::new(opts.seed);
    let batch = opts.batch.max(1);
    let mut t = 0i32;
    epochs::run(net, train, val, opts, progress, |net, perf| {
        // Fisher–Yates shuffle.
        for i in (1..n).rev() {
            let j = (rng.uniform() * (i + 1) as f64) as usize;
            order.swap(i, j.min(i));
        }
        let mut gnorm = 0.0;
        for chunk in order.chunks(batch) {
            g.fill(0.0);
            for &i in chunk {
                let y = net.jacobian_row(train.row(i), &mut ws, &mut row);
                let e = y - train.target(i);
                for (gk, rk) in g.iter_mut().zip(&row) {
                    *gk += 2.0 * e * rk / chunk.len() as f64;
                }
            }
            gnorm = g.iter().map(|x| x * x).sum::<f64>().sqrt();
            t += 1;
            let (c1, c2) = (1.0 - BETA1.powi(t), 1.0 - BETA2.powi(t));
            for (k, w) in net.weights_mut().iter_mut().enumerate() {
                m[k] = BETA1 * m[k] + (1.0 - BETA1) * g[k];
                v[k] = BETA2 * v[k] + (1.0 - BETA2) * g[k] * g[k];
                *w -= opts.learning_rate * (m[k] / c1) / ((v[k] / c2).sqrt() + EPS);
            }
        }
        *perf = mse(net, train);
        let stop = if !perf.is_finite() {
            Some(StopReason::MuMax)
        } else if gnorm < opts.min_grad {
            Some(StopReason::MinGradient)
        } else {
            None
        };
        Ok(Stepped { gradient: gnorm, mu: 0.0, stop })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{Array1, Array2};

    #[test]
    fn fits_a_smooth_function() {
        let mut r = Rng::new(1);
        let n = 400;
        let mut x = Array2::zeros((n, 2));
        let mut t = Array1::zeros(n);
        for i in 0..n {
            let (a, b) = (2.0 * r.uniform() - 1.0, 2.0 * r.uniform() - 1.0);
            x[(i, 0)] = a;
            x[(i, 1)] = b;
            t[i] = (1.5 * a).sin() * b + 0.3 * a * a;
        }
        let d = Data::new(x.slice(ndarray::s![..300, ..]), t.slice(ndarray::s![..300])).unwrap();
        let v = Data::new(x.slice(ndarray::s![300.., ..]), t.slice(ndarray::s![300..])).unwrap();
        let mut net = Mlp::new(2, &[8]).unwrap();
        net.init_nguyen_widrow(&mut Rng::new(5));
        let before = mse(&net, &d);
        let opts = Options { max_epochs: 300, learning_rate: 0.01, batch: 16, max_fail: 1000, ..Options::default() };
        let rep = train(&mut net, &d, &v, &opts, &mut |_| {});
        assert!(rep.train_mse < before / 20.0 && rep.train_mse < 2e-3, "{rep:?} (before {before})");
        assert!(rep.val_mse < 4e-3, "{rep:?}");
    }
}
