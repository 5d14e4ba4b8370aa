//! The multilayer perceptron of the NARX model (dissertation §5.2.1,
//! Eq. 5.1: y[n] = f(y[n−1..n−k_y], x[n…])): tanh hidden layers, a linear
//! output, all parameters in one flat vector (the layout the trainers and
//! model files share: per layer, the weights row by row, then the biases).

use crate::lab::rng::Rng;
use serde::{Deserialize, Serialize};

/// Layer sizes and parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Net {
    /// Sizes: inputs, hidden layers…, 1 output.
    pub sizes: Vec<usize>,
    /// All weights and biases, flat.
    pub params: Vec<f64>,
}

/// Reusable buffers for one forward/backward pass (no allocation per sample).
#[derive(Debug, Clone)]
pub struct Work {
    /// Activations per layer (layer 0: the input).
    act: Vec<Vec<f64>>,
    /// Back-propagated sensitivities per layer.
    delta: Vec<Vec<f64>>,
}

impl Net {
    /// A network with `inputs` inputs, the `hidden` layer sizes and one
    /// output, weights drawn uniformly in ±1/√fan-in from `seed`, biases 0.
    pub fn new(inputs: usize, hidden: &[usize], seed: u64) -> Self {
        let mut sizes = vec![inputs];
        sizes.extend_from_slice(hidden);
        sizes.push(1);
        let mut rng = Rng::substream(seed, 0x6e6172);
        let mut params = Vec::new();
        for w in sizes.windows(2) {
            let scale = 1.0 / (w[0].max(1) as f64).sqrt();
            for _ in 0..w[0] * w[1] {
                params.push(scale * (2.0 * rng.uniform() - 1.0));
            }
            params.extend(std::iter::repeat_n(0.0, w[1]));
        }
        Net { sizes, params }
    }

    /// Number of inputs.
    pub fn inputs(&self) -> usize {
        self.sizes[0]
    }

    /// Number of parameters the sizes call for.
    pub fn param_count(sizes: &[usize]) -> usize {
        sizes.windows(2).map(|w| w[0] * w[1] + w[1]).sum()
    }

    /// Buffers for [`Net::forward`] and [`Net::gradient`].
    pub fn work(&self) -> Work {
        Work {
            act: self.sizes.iter().map(|&n| vec![0.0; n]).collect(),
            delta: self.sizes.iter().map(|&n| vec![0.0; n]).collect(),
        }
    }

    /// The output for input `x` (length [`Net::inputs`]).
    pub fn forward(&self, x: &[f64], w: &mut Work) -> f64 {
        w.act[0].copy_from_slice(&x[..self.sizes[0]]);
        let mut off = 0;
        let last = self.sizes.len() - 2;
        for l in 0..=last {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let (before, after) = w.act.split_at_mut(l + 1);
            let (a_in, a_out) = (&before[l], &mut after[0]);
            let weights = &self.params[off..off + n_in * n_out];
            let bias = &self.params[off + n_in * n_out..off + n_in * n_out + n_out];
            for (j, out) in a_out.iter_mut().enumerate() {
                let row = &weights[j * n_in..(j + 1) * n_in];
                let z = bias[j] + row.iter().zip(a_in).map(|(a, b)| a * b).sum::<f64>();
                *out = if l == last { z } else { z.tanh() };
            }
            off += n_in * n_out + n_out;
        }
        w.act[last + 1][0]
    }

    /// The output for `x` and its gradient with respect to every parameter
    /// (written into `grad`, length = `params`): one row of the Jacobian.
    pub fn gradient(&self, x: &[f64], w: &mut Work, grad: &mut [f64]) -> f64 {
        let y = self.forward(x, w);
        let layers = self.sizes.len() - 1;
        // Walk the layers backwards; `end` is where the current block ends.
        let mut end = self.params.len();
        w.delta[layers][0] = 1.0;
        for l in (0..layers).rev() {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let start = end - (n_in * n_out + n_out);
            let (wg, bg) = grad[start..end].split_at_mut(n_in * n_out);
            for j in 0..n_out {
                let d = w.delta[l + 1][j];
                bg[j] = d;
                for (g, a) in wg[j * n_in..(j + 1) * n_in].iter_mut().zip(&w.act[l]) {
                    *g = d * a;
                }
            }
            if l > 0 {
                let weights = &self.params[start..start + n_in * n_out];
                for i in 0..n_in {
                    let s: f64 = (0..n_out).map(|j| weights[j * n_in + i] * w.delta[l + 1][j]).sum();
                    let a = w.act[l][i];
                    w.delta[l][i] = s * (1.0 - a * a);
                }
            }
            end = start;
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_finite_differences() {
        let net = Net::new(4, &[5, 3], 7);
        let mut w = net.work();
        let x = [0.3, -0.7, 0.1, 0.9];
        let mut g = vec![0.0; net.params.len()];
        let y = net.gradient(&x, &mut w, &mut g);
        assert_eq!(y, net.forward(&x, &mut w));
        for (k, gk) in g.iter().enumerate() {
            let mut p = net.clone();
            let h = 1e-6;
            p.params[k] += h;
            let up = p.forward(&x, &mut w);
            p.params[k] -= 2.0 * h;
            let down = p.forward(&x, &mut w);
            let fd = (up - down) / (2.0 * h);
            assert!((fd - gk).abs() < 1e-8, "param {k}: {fd} vs {gk}");
        }
    }

    #[test]
    fn layout_and_seeding() {
        let a = Net::new(20, &[15, 10, 5], 1);
        assert_eq!(a.params.len(), Net::param_count(&[20, 15, 10, 5, 1]));
        assert_eq!(a.params.len(), 20 * 15 + 15 + 15 * 10 + 10 + 10 * 5 + 5 + 5 + 1);
        assert_eq!(a, Net::new(20, &[15, 10, 5], 1));
        assert_ne!(a, Net::new(20, &[15, 10, 5], 2));
        // No hidden layer: a linear model.
        let lin = Net { sizes: vec![2, 1], params: vec![2.0, -3.0, 0.5] };
        assert_eq!(lin.forward(&[1.0, 1.0], &mut lin.work()), -0.5);
    }
}
