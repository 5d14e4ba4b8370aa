//! Levenberg–Marquardt training, as MATLAB `trainlm`.
//!
//! Each epoch forms the Jacobian J of the network outputs with respect to
//! the weights over the training block and the errors e = y − t, then tries
//! the step
//!
//! ```text
//! dX = −(JᵀJ + μI)⁻¹ Jᵀe
//! ```
//!
//! If the step lowers the training MSE it is taken and μ is multiplied by
//! `mu_dec` (0.1); otherwise μ is multiplied by `mu_inc` (10) and the step
//! recomputed, until μ exceeds `mu_max` (1e10), which stops training.
//! JᵀJ + μI is factored by Cholesky (LLᵀ, `crate::linalg`); a factorization that
//! fails (the matrix not numerically positive definite) is treated like a
//! step that did not improve: μ is raised. Training also stops after
//! `max_epochs`, when the MSE gradient norm 2‖Jᵀe‖/N falls below
//! `min_grad`, and after `max_fail` epochs in a row whose validation error
//! rose (the weights of the best validation epoch are returned). Parameter
//! names and defaults are MATLAB's (`trainlm` documentation, Neural Network
//! Toolbox). JᵀJ is accumulated over blocks of rows so memory stays
//! O(P² + block·P) for any recording length; backpropagation writes each
//! block's Jᵀ column by column in place, and only the lower triangle of
//! the symmetric JᵀJ — the half the Cholesky factorization reads — is
//! formed (half the multiply-adds of the full product).

use super::epochs::{self, Stepped};
use super::{mse, Data, Epoch, Options, Report, StopReason};
use crate::linalg::{add_lower_gram, Cholesky};
use crate::narx::net::{Mlp, Workspace};
use ndarray::linalg::general_mat_vec_mul;
use ndarray::{s, Array1, Array2};

/// Rows of the Jacobian formed at once.
const BLOCK: usize = 512;

/// Trains `net` in place on `train`, stopping early on `val` (may be
/// empty); `progress` sees every epoch. Returns the training summary.
pub fn train(
    net: &mut Mlp,
    train: &Data<'_>,
    val: &Data<'_>,
    opts: &Options,
    progress: &mut dyn FnMut(&Epoch),
) -> Report {
    let n = train.len();
    let mut ws = net.workspace();
    let mut mu = opts.mu;
    let mut normal = Normal::new(net.n_params());
    epochs::run(net, train, val, opts, progress, |net, perf| {
        normal.form(net, train, &mut ws);
        let gradient = normal.gradient(n);
        if gradient.is_nan() || gradient < opts.min_grad {
            return Err(StopReason::MinGradient);
        }
        let improved = normal.step(net, train, perf, &mut mu, opts);
        Ok(Stepped { gradient, mu, stop: (!improved).then_some(StopReason::MuMax) })
    })
}

/// The normal equations of an epoch, JᵀJ and Jᵀe, and the buffers they
/// are formed and solved in (allocated once for the whole training).
struct Normal {
    /// JᵀJ: only its lower triangle is formed and read (Cholesky of the lower half).
    jtj: Array2<f64>,
    /// JᵀJ's diagonal, before μ is added.
    diag: Vec<f64>,
    /// Jᵀe.
    jte: Array1<f64>,
    /// J of a block of rows: row i holds ∂y/∂w of row i, written in place.
    j_block: Array2<f64>,
    /// The errors of a block of rows.
    eblock: Array1<f64>,
    /// The weights of a trial step.
    trial: Vec<f64>,
}

impl Normal {
    fn new(p: usize) -> Self {
        Self {
            jtj: Array2::<f64>::zeros((p, p)),
            diag: vec![0.0; p],
            jte: Array1::<f64>::zeros(p),
            j_block: Array2::<f64>::zeros((BLOCK, p)),
            eblock: Array1::<f64>::zeros(BLOCK),
            trial: vec![0.0; p],
        }
    }

    /// Forms JᵀJ and Jᵀe over `train`, block by block.
    fn form(&mut self, net: &Mlp, train: &Data<'_>, ws: &mut Workspace) {
        let n = train.len();
        let mut first = true;
        let mut s = 0;
        while s < n {
            let m = BLOCK.min(n - s);
            for i in 0..m {
                let mut row = self.j_block.row_mut(i);
                let row = row.as_slice_mut().expect("rows of a standard-layout array are contiguous");
                let y = net.jacobian_row(train.row(s + i), ws, row);
                self.eblock[i] = y - train.target(s + i);
            }
            let (jb, eb) = (self.j_block.slice(s![0..m, ..]), self.eblock.slice(s![0..m]));
            add_lower_gram(&mut self.jtj, jb, !first);
            general_mat_vec_mul(1.0, &jb.t(), &eb, if first { 0.0 } else { 1.0 }, &mut self.jte);
            first = false;
            s += m;
        }
    }

    /// The MSE gradient norm 2‖Jᵀe‖/N over `n` rows.
    fn gradient(&self, n: usize) -> f64 {
        let p = self.diag.len();
        2.0 * (0..p).map(|k| self.jte[k] * self.jte[k]).sum::<f64>().sqrt() / n as f64
    }

    /// Raises μ until a step lowers the training error `perf`: true when
    /// one did (the net holds its weights, `perf` and `mu` are updated),
    /// false once μ passed `mu_max` (the net keeps its weights).
    fn step(&mut self, net: &mut Mlp, train: &Data<'_>, perf: &mut f64, mu: &mut f64, opts: &Options) -> bool {
        let p = self.diag.len();
        for (k, d) in self.diag.iter_mut().enumerate() {
            *d = self.jtj[(k, k)];
        }
        while *mu <= opts.mu_max {
            for (k, d) in self.diag.iter().enumerate() {
                self.jtj[(k, k)] = d + *mu;
            }
            if let Ok(llt) = Cholesky::factor(&self.jtj) {
                let dx = llt.solve(self.jte.as_slice().expect("a vector is contiguous"));
                let w = net.weights();
                let ok = dx.iter().all(|d| d.is_finite());
                if ok {
                    for k in 0..p {
                        self.trial[k] = w[k] - dx[k];
                    }
                    let saved: Vec<f64> = w.to_vec();
                    net.weights_mut().copy_from_slice(&self.trial);
                    let perf2 = mse(net, train);
                    if perf2 < *perf {
                        *perf = perf2;
                        *mu *= opts.mu_dec;
                        return true;
                    }
                    net.weights_mut().copy_from_slice(&saved);
                }
            }
            *mu *= opts.mu_inc;
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use ndarray::{Array1, Array2};

    /// Samples of a smooth nonlinear function of two inputs.
    fn problem(n: usize, seed: u64) -> (Array2<f64>, Array1<f64>) {
        let mut r = Rng::new(seed);
        let mut x = Array2::zeros((n, 2));
        let mut t = Array1::zeros(n);
        for i in 0..n {
            let (a, b) = (2.0 * r.uniform() - 1.0, 2.0 * r.uniform() - 1.0);
            x[(i, 0)] = a;
            x[(i, 1)] = b;
            t[i] = (1.5 * a).sin() * b + 0.3 * a * a;
        }
        (x, t)
    }

    #[test]
    fn fits_a_smooth_function_to_small_error() {
        let (x, t) = problem(300, 1);
        let (xv, tv) = problem(100, 2);
        let (d, v) = (Data::new(x.view(), t.view()).unwrap(), Data::new(xv.view(), tv.view()).unwrap());
        let mut net = Mlp::new(2, &[8]).unwrap();
        net.init_nguyen_widrow(&mut Rng::new(5));
        let before = mse(&net, &d);
        let mut seen = Vec::new();
        let opts = Options { max_epochs: 200, ..Options::default() };
        let r = train(&mut net, &d, &v, &opts, &mut |e| seen.push(*e));
        assert!(r.train_mse < 1e-5 && r.val_mse < 1e-4, "{r:?} (before {before})");
        // The training error never rises from epoch to epoch.
        for w in seen.windows(2) {
            assert!(w[1].train_mse <= w[0].train_mse, "{:?}", w);
        }
        assert_eq!(r.train_mse, mse(&net, &d));
    }

    #[test]
    fn a_linear_problem_is_solved_in_one_step_at_small_mu() {
        // Without hidden layers the network is linear in its weights: one
        // Gauss–Newton step (μ → 0) lands on the least-squares solution.
        let (x, _) = problem(50, 3);
        let t: Array1<f64> = x.rows().into_iter().map(|r| 0.7 * r[0] - 1.2 * r[1] + 0.4).collect();
        let d = Data::new(x.view(), t.view()).unwrap();
        let empty = Data::new(x.slice(ndarray::s![0..0, ..]), t.slice(ndarray::s![0..0])).unwrap();
        let mut net = Mlp::new(2, &[]).unwrap();
        let opts = Options { max_epochs: 1, mu: 1e-12, ..Options::default() };
        let r = train(&mut net, &d, &empty, &opts, &mut |_| {});
        let w = net.weights();
        assert!((w[0] - 0.7).abs() < 1e-9 && (w[1] + 1.2).abs() < 1e-9 && (w[2] - 0.4).abs() < 1e-9, "{w:?}");
        assert!(r.val_mse.is_nan());
    }

    #[test]
    fn validation_failures_stop_training_and_keep_the_best_weights() {
        // Pure noise targets: the network can only overfit, so the
        // validation error rises and training stops after max_fail epochs.
        let (x, _) = problem(40, 4);
        let mut r = Rng::new(9);
        let t: Array1<f64> = (0..40).map(|_| r.gaussian()).collect();
        let (xv, _) = problem(40, 6);
        let tv: Array1<f64> = (0..40).map(|_| r.gaussian()).collect();
        let (d, v) = (Data::new(x.view(), t.view()).unwrap(), Data::new(xv.view(), tv.view()).unwrap());
        let mut net = Mlp::new(2, &[12]).unwrap();
        net.init_nguyen_widrow(&mut Rng::new(2));
        let mut seen = Vec::new();
        let rep = train(&mut net, &d, &v, &Options::default(), &mut |e| seen.push(*e));
        assert_eq!(rep.stop, StopReason::ValidationStop, "{rep:?}");
        let best = seen.iter().map(|e| e.val_mse).fold(f64::INFINITY, f64::min);
        assert!(rep.val_mse <= best && (mse(&net, &v) - rep.val_mse).abs() < 1e-12);
        assert!(rep.epochs >= rep.best_epoch + 6 && rep.epochs < 1000);
    }
}
