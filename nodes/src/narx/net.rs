//! The multilayer perceptron of the NARX network: tanh hidden layers
//! (MATLAB `tansig`), one linear output (`purelin`), as the dissertation's
//! network (§5.2.1: three hidden layers of 15, 10 and 5 neurons).
//!
//! Weights live in one flat vector, layer after layer: the weight matrix of
//! layer l (s_l rows × s_{l−1} columns, row-major) followed by its biases.
//! [`Mlp::jacobian_row`] gives ∂y/∂w for one input by backpropagation — the
//! row of the Jacobian Levenberg–Marquardt needs; it is checked against
//! central finite differences in the tests. The hidden layers' tanh is
//! [`super::exact_tanh::tanh`] (glibc's, written out), a layer's neurons
//! four at a time.

use super::error::NarxError;
use super::exact_tanh_avx2;
use crate::rng::Rng;

/// A tanh-hidden, linear-output network with one output.
#[derive(Debug, Clone, PartialEq)]
pub struct Mlp {
    /// Layer sizes: inputs, hidden layers…, 1.
    sizes: Vec<usize>,
    /// All weights and biases, layer after layer.
    w: Vec<f64>,
    /// Where each layer's weights start in `w` (one entry per layer after the input).
    offsets: Vec<usize>,
}

/// Scratch memory for one forward or backward pass, sized once by
/// [`Mlp::workspace`] so the passes never allocate.
#[derive(Debug, Clone)]
pub struct Workspace {
    /// Activations of every layer, the input layer included, one after another.
    act: Vec<f64>,
    /// Backpropagated sensitivities, same layout.
    delta: Vec<f64>,
    /// Where each layer starts in `act`/`delta`.
    starts: Vec<usize>,
}

impl Mlp {
    /// A network with `inputs` inputs, the given hidden layer sizes and one
    /// linear output; weights zero (see [`Mlp::init_nguyen_widrow`]).
    pub fn new(inputs: usize, hidden: &[usize]) -> Result<Self, NarxError> {
        if inputs == 0 {
            return Err(NarxError::Config("the network needs at least one input".into()));
        }
        if hidden.contains(&0) {
            return Err(NarxError::Config(format!("a hidden layer has no neuron: {hidden:?}")));
        }
        let mut sizes = Vec::with_capacity(hidden.len() + 2);
        sizes.push(inputs);
        sizes.extend_from_slice(hidden);
        sizes.push(1);
        let mut offsets = Vec::with_capacity(sizes.len() - 1);
        let mut n = 0;
        for l in 1..sizes.len() {
            offsets.push(n);
            n += sizes[l] * (sizes[l - 1] + 1);
        }
        Ok(Self { sizes, w: vec![0.0; n], offsets })
    }

    /// A network with the given weights (e.g. read from a model file).
    pub fn with_weights(inputs: usize, hidden: &[usize], w: Vec<f64>) -> Result<Self, NarxError> {
        let mut m = Self::new(inputs, hidden)?;
        if w.len() != m.w.len() {
            return Err(NarxError::Config(format!(
                "{} weights given, the architecture {inputs}-{hidden:?}-1 has {}",
                w.len(),
                m.w.len()
            )));
        }
        m.w = w;
        Ok(m)
    }

    /// Nguyen–Widrow initialization (Nguyen & Widrow 1990, as MATLAB
    /// `initnw` for inputs in [−1, 1]): each tanh layer of S neurons and R
    /// inputs gets random weight rows of norm 0.7·S^(1/R) and biases spread
    /// evenly over ±that norm, so the neurons' active regions tile the input
    /// range. The linear output layer gets uniform weights in ±1/√R.
    pub fn init_nguyen_widrow(&mut self, rng: &mut Rng) {
        let layers = self.sizes.len() - 1;
        for l in 0..layers {
            let (r, s) = (self.sizes[l], self.sizes[l + 1]);
            let off = self.offsets[l];
            let (wl, rest) = self.w[off..].split_at_mut(s * r);
            let bl = &mut rest[..s];
            for v in wl.iter_mut() {
                *v = 2.0 * rng.uniform() - 1.0;
            }
            if l + 1 == layers {
                let scale = 1.0 / (r as f64).sqrt();
                for v in wl.iter_mut() {
                    *v *= scale;
                }
                for b in bl.iter_mut() {
                    *b = (2.0 * rng.uniform() - 1.0) * scale;
                }
                continue;
            }
            let mag = 0.7 * (s as f64).powf(1.0 / r as f64);
            for i in 0..s {
                let row = &mut wl[i * r..(i + 1) * r];
                let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
                for v in row.iter_mut() {
                    *v *= mag / norm;
                }
                let spread = if s == 1 { 0.0 } else { -1.0 + 2.0 * i as f64 / (s - 1) as f64 };
                bl[i] = mag * spread * row[0].signum();
            }
        }
    }

    /// Number of inputs.
    pub fn inputs(&self) -> usize {
        self.sizes[0]
    }

    /// Hidden layer sizes.
    pub fn hidden(&self) -> &[usize] {
        &self.sizes[1..self.sizes.len() - 1]
    }

    /// Number of weights and biases.
    pub fn n_params(&self) -> usize {
        self.w.len()
    }

    /// All weights and biases.
    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// All weights and biases, to change in place.
    pub fn weights_mut(&mut self) -> &mut [f64] {
        &mut self.w
    }

    /// Scratch memory for this network's passes.
    pub fn workspace(&self) -> Workspace {
        let mut starts = Vec::with_capacity(self.sizes.len());
        let mut n = 0;
        for &s in &self.sizes {
            starts.push(n);
            n += s;
        }
        Workspace { act: vec![0.0; n], delta: vec![0.0; n], starts }
    }

    /// The output for input `x` (length [`Mlp::inputs`]).
    #[inline]
    pub fn forward(&self, x: &[f64], ws: &mut Workspace) -> f64 {
        let n0 = self.sizes[0];
        ws.act[..n0].copy_from_slice(&x[..n0]);
        let layers = self.sizes.len() - 1;
        for l in 0..layers {
            let (r, s) = (self.sizes[l], self.sizes[l + 1]);
            let off = self.offsets[l];
            let wl = &self.w[off..off + s * r];
            let bl = &self.w[off + s * r..off + s * r + s];
            let (prev, next) = ws.act.split_at_mut(ws.starts[l + 1]);
            let input = &prev[ws.starts[l]..ws.starts[l] + r];
            let out = &mut next[..s];
            for i in 0..s {
                let row = &wl[i * r..(i + 1) * r];
                out[i] = bl[i] + row.iter().zip(input).map(|(a, b)| a * b).sum::<f64>();
            }
            if l + 1 < layers {
                exact_tanh_avx2::tanh_in_place(out);
            }
        }
        ws.act[ws.starts[layers]]
    }

    /// The output for `x` and its derivative with respect to every weight
    /// (written to `row`, length [`Mlp::n_params`], in the layout of
    /// [`Mlp::weights`]).
    pub fn jacobian_row(&self, x: &[f64], ws: &mut Workspace, row: &mut [f64]) -> f64 {
        let y = self.forward(x, ws);
        let layers = self.sizes.len() - 1;
        // Sensitivity of the output to the pre-activation of each layer.
        ws.delta[ws.starts[layers]] = 1.0;
        for l in (0..layers).rev() {
            let (r, s) = (self.sizes[l], self.sizes[l + 1]);
            let off = self.offsets[l];
            let (sl, sn) = (ws.starts[l], ws.starts[l + 1]);
            // ∂y/∂W_l[i][j] = δ_l[i]·a_{l−1}[j], ∂y/∂b_l[i] = δ_l[i].
            for i in 0..s {
                let d = ws.delta[sn + i];
                let dst = &mut row[off + i * r..off + (i + 1) * r];
                for (o, a) in dst.iter_mut().zip(&ws.act[sl..sl + r]) {
                    *o = d * a;
                }
                row[off + s * r + i] = d;
            }
            if l == 0 {
                break;
            }
            // δ_{l−1}[j] = (1 − a_{l−1}[j]²)·Σ_i W_l[i][j]·δ_l[i].
            let wl = &self.w[off..off + s * r];
            for j in 0..r {
                let mut acc = 0.0;
                for i in 0..s {
                    acc += wl[i * r + j] * ws.delta[sn + i];
                }
                let a = ws.act[sl + j];
                ws.delta[sl + j] = acc * (1.0 - a * a);
            }
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn net(inputs: usize, hidden: &[usize], seed: u64) -> Mlp {
        let mut m = Mlp::new(inputs, hidden).unwrap();
        m.init_nguyen_widrow(&mut Rng::new(seed));
        m
    }

    #[test]
    fn parameter_count_matches_the_architecture() {
        // 20 inputs, 15-10-5, 1 output: 20·15+15 + 15·10+10 + 10·5+5 + 5+1.
        assert_eq!(Mlp::new(20, &[15, 10, 5]).unwrap().n_params(), 315 + 160 + 55 + 6);
        assert_eq!(Mlp::new(3, &[]).unwrap().n_params(), 4);
        assert!(Mlp::new(0, &[4]).is_err());
        assert!(Mlp::new(3, &[4, 0]).is_err());
        assert!(Mlp::with_weights(3, &[2], vec![0.0; 5]).is_err());
    }

    #[test]
    fn forward_matches_a_hand_computed_network() {
        // 2 inputs, one hidden layer of 2, linear output.
        let w = vec![0.5, -1.0, 0.25, 2.0, 0.1, -0.2, 1.5, -0.5, 0.3];
        let m = Mlp::with_weights(2, &[2], w).unwrap();
        let x = [0.4, -0.7];
        let h1 = (0.5 * 0.4 - 1.0 * -0.7 + 0.1f64).tanh();
        let h2 = (0.25 * 0.4 + 2.0 * -0.7 - 0.2f64).tanh();
        let want = 1.5 * h1 - 0.5 * h2 + 0.3;
        let got = m.forward(&x, &mut m.workspace());
        assert!((got - want).abs() < 1e-15, "{got} vs {want}");
    }

    #[test]
    fn jacobian_matches_central_differences() {
        for (inputs, hidden) in [(5, vec![15, 10, 5]), (3, vec![4]), (2, vec![])] {
            let mut m = net(inputs, &hidden, 7);
            let x: Vec<f64> = (0..inputs).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut ws = m.workspace();
            let mut row = vec![0.0; m.n_params()];
            let y = m.jacobian_row(&x, &mut ws, &mut row);
            assert_eq!(y, m.forward(&x, &mut ws));
            let h = 1e-6;
            for (k, &dk) in row.iter().enumerate() {
                let w0 = m.weights()[k];
                m.weights_mut()[k] = w0 + h;
                let yp = m.forward(&x, &mut ws);
                m.weights_mut()[k] = w0 - h;
                let ym = m.forward(&x, &mut ws);
                m.weights_mut()[k] = w0;
                let fd = (yp - ym) / (2.0 * h);
                assert!((fd - dk).abs() < 1e-8 * (1.0 + fd.abs()), "{hidden:?} w[{k}]: {dk} vs {fd}");
            }
        }
    }

    #[test]
    fn nguyen_widrow_rows_have_the_prescribed_norm_and_outputs_are_bounded() {
        let m = net(20, &[15, 10, 5], 3);
        let r = 20;
        let mag = 0.7 * 15f64.powf(1.0 / 20.0);
        for i in 0..15 {
            let norm = m.weights()[i * r..(i + 1) * r].iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((norm - mag).abs() < 1e-12, "row {i}: {norm} vs {mag}");
        }
        // tanh layers bound every hidden value by 1: the output is bounded by
        // the output layer's absolute weights, whatever the input.
        let out_off = m.n_params() - 6;
        let bound: f64 = m.weights()[out_off..].iter().map(|v| v.abs()).sum();
        let mut ws = m.workspace();
        for big in [1e3, -1e6, 1e300] {
            let y = m.forward(&[big; 20], &mut ws);
            assert!(y.is_finite() && y.abs() <= bound, "{y}");
        }
        // Same seed, same network; another seed, another.
        assert_eq!(net(20, &[15, 10, 5], 3), m);
        assert_ne!(net(20, &[15, 10, 5], 4), m);
    }
}
