//! The forward model of the display: a second-order Volterra series with
//! finite memory (a polynomial NFIR model), actuation u → lateral force.
//!
//! ```text
//! y[n] = c + Σ_i l_i·u[n−i] + Σ_i Σ_j H_ij·u[n−i]·u[n−j],   i, j = 0 … M−1
//! ```
//!
//! with H symmetric and u\[k\] = 0 before the first sample. Why this class:
//! an electrovibration display is a square law between linear dynamics —
//! amplifier and circuit before it (u → gap voltage v_g), the
//! electroadhesion lag, the contact mechanics and the force sensor after it
//! (F_e = k_e·v_g² → lateral force) — and a linear system, a square and a
//! linear system sampled with the input held is *exactly* a second-order
//! Volterra system (the product of two held-input responses, filtered;
//! Schetzen, *The Volterra and Wiener Theories of Nonlinear Systems*, 1980,
//! ch. 3). An amplifier offset adds the linear term. So the class holds
//! the display's physics with M(M+1)/2 + M + 1 parameters that enter
//! linearly — identified by least squares with a unique optimum and no
//! initial weights ([`super::volterra_fit`]) — and, unlike the inverse
//! model, the problem is well posed: every u has one force.
//!
//! What it leaves out: stick–slip of the contact, saturation and
//! everything above second order; identification at moderate actuation
//! levels keeps the data in the range where those stay small.

use super::error::SynthError;

/// Largest memory the model accepts, samples.
pub const MAX_MEMORY: usize = 256;

/// A second-order Volterra model with memory M.
#[derive(Debug, Clone, PartialEq)]
pub struct Volterra {
    memory: usize,
    /// H, symmetric, M × M row-major.
    h: Vec<f64>,
    /// Hᵀ, row-major (H's columns contiguous): z = H·w is computed as
    /// Σ_j w_j·Hᵀ[j], a sum over contiguous rows that vectorizes over i and
    /// adds the terms of each z_i in the same order as the row dot product
    /// (equal results, bit for bit, even for an H symmetric only to 1e-12).
    ht: Vec<f64>,
    /// l, M.
    l: Vec<f64>,
    c: f64,
}

impl Volterra {
    /// A model from its symmetric quadratic kernel `h` (M × M, row-major),
    /// linear kernel `l` (M) and constant `c`.
    pub fn new(h: Vec<f64>, l: Vec<f64>, c: f64) -> Result<Self, SynthError> {
        let m = l.len();
        if m == 0 || m > MAX_MEMORY {
            return Err(SynthError::Config(format!("the memory must be 1 ..= {MAX_MEMORY} samples, not {m}")));
        }
        if h.len() != m * m {
            return Err(SynthError::Config(format!(
                "the quadratic kernel has {} values, memory {m} needs {}",
                h.len(),
                m * m
            )));
        }
        if !(h.iter().chain(&l).all(|v| v.is_finite()) && c.is_finite()) {
            return Err(SynthError::Config("the kernels hold a non-finite value".into()));
        }
        for i in 0..m {
            for j in 0..i {
                let (a, b) = (h[i * m + j], h[j * m + i]);
                if (a - b).abs() > 1e-12 * (a.abs() + b.abs()).max(f64::MIN_POSITIVE) {
                    return Err(SynthError::Config(format!("the quadratic kernel is not symmetric at ({i}, {j})")));
                }
            }
        }
        let mut ht = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                ht[j * m + i] = h[i * m + j];
            }
        }
        Ok(Self { memory: m, h, ht, l, c })
    }

    /// A model from the upper triangle of H (row by row: H_00, H_01 … H_0,M−1,
    /// H_11 …, as [`upper_index`] numbers them), l and c.
    pub fn from_upper(upper: &[f64], l: Vec<f64>, c: f64) -> Result<Self, SynthError> {
        let m = l.len();
        if upper.len() != m * (m + 1) / 2 {
            return Err(SynthError::Config(format!(
                "the quadratic kernel's upper triangle has {} values, memory {m} needs {}",
                upper.len(),
                m * (m + 1) / 2
            )));
        }
        let mut h = vec![0.0; m * m];
        for i in 0..m {
            for j in i..m {
                let v = upper[upper_index(m, i, j)];
                h[i * m + j] = v;
                h[j * m + i] = v;
            }
        }
        Self::new(h, l, c)
    }

    /// The upper triangle of H in the order of [`upper_index`].
    pub fn upper(&self) -> Vec<f64> {
        let m = self.memory;
        let mut out = Vec::with_capacity(m * (m + 1) / 2);
        for i in 0..m {
            out.extend_from_slice(&self.h[i * m + i..(i + 1) * m]);
        }
        out
    }

    /// Memory M, samples.
    pub fn memory(&self) -> usize {
        self.memory
    }

    /// The linear kernel l.
    pub fn linear(&self) -> &[f64] {
        &self.l
    }

    /// The constant c.
    pub fn constant(&self) -> f64 {
        self.c
    }

    /// H_ij.
    pub fn quadratic(&self, i: usize, j: usize) -> f64 {
        self.h[i * self.memory + j]
    }

    /// Number of free parameters, M(M+1)/2 + M + 1.
    pub fn n_params(&self) -> usize {
        self.memory * (self.memory + 1) / 2 + self.memory + 1
    }

    /// The force added per a² by a Nyquist-rate carrier u\[n\] = (−1)ⁿ·a held
    /// at amplitude a: κ = Σ_ij H_ij (−1)^(i+j). For a square-law display
    /// this is the friction raised by a full-swing carrier of unit
    /// amplitude (N) — the constant of the square-law start
    /// ([`super::start`]).
    pub fn carrier_gain(&self) -> f64 {
        let m = self.memory;
        let mut k = 0.0;
        for i in 0..m {
            for j in 0..m {
                let s = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
                k += s * self.h[i * m + j];
            }
        }
        k
    }

    /// The force for the actuation `u` (zero before its first sample) into
    /// `y` (same length).
    pub fn eval(&self, u: &[f64], y: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above), all
            // that `eval_avx2` needs.
            return unsafe { self.eval_avx2(u, y) };
        }
        self.eval_portable(u, y)
    }

    /// [`Volterra::eval`] compiled for AVX2 (the same code; no fused
    /// multiply-add is written, so the results are the portable build's).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_avx2(&self, u: &[f64], y: &mut [f64]) {
        self.eval_portable(u, y)
    }

    #[inline(always)]
    fn eval_portable(&self, u: &[f64], y: &mut [f64]) {
        let mut z = vec![0.0; self.memory];
        let mut w = vec![0.0; self.memory];
        for (n, yn) in y.iter_mut().enumerate().take(u.len()) {
            *yn = self.sample(u, n, &mut w, &mut z);
        }
    }

    /// y[n] for the actuation `u`, with w ← the window and z ← H·w.
    #[inline(always)]
    fn sample(&self, u: &[f64], n: usize, w: &mut [f64], z: &mut [f64]) -> f64 {
        let m = self.memory;
        for (i, wi) in w.iter_mut().enumerate() {
            *wi = if i <= n { u[n - i] } else { 0.0 };
        }
        // z = H·w, each z_i summed over j in order from −0 (as
        // `Iterator::sum`), one contiguous column of H per j, up to 16
        // sums at a time held in registers.
        let mut c0 = 0;
        while c0 < m {
            c0 += match m - c0 {
                16.. => block::<16>(&self.ht, m, c0, w, z),
                8.. => block::<8>(&self.ht, m, c0, w, z),
                4.. => block::<4>(&self.ht, m, c0, w, z),
                3 => block::<3>(&self.ht, m, c0, w, z),
                2 => block::<2>(&self.ht, m, c0, w, z),
                _ => block::<1>(&self.ht, m, c0, w, z),
            };
        }
        let mut y = self.c;
        for ((wi, zi), li) in w.iter().zip(z.iter()).zip(&self.l) {
            y += wi * (zi + li);
        }
        y
    }

    /// The force for `u` into `y`, and the gradient of Σ_n ȳ\[n\]·y\[n\] with
    /// respect to every u\[k\] *added* to `du` (reverse mode: each window's
    /// sensitivity 2·H·w + l scattered back onto the samples it read).
    pub fn eval_grad(&self, u: &[f64], ybar: &[f64], y: &mut [f64], du: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::has_avx2_fma() {
            // SAFETY: as in `eval`.
            return unsafe { self.eval_grad_avx2(u, ybar, y, du) };
        }
        self.eval_grad_portable(u, ybar, y, du)
    }

    /// [`Volterra::eval_grad`] compiled for AVX2 (same results).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_grad_avx2(&self, u: &[f64], ybar: &[f64], y: &mut [f64], du: &mut [f64]) {
        self.eval_grad_portable(u, ybar, y, du)
    }

    #[inline(always)]
    fn eval_grad_portable(&self, u: &[f64], ybar: &[f64], y: &mut [f64], du: &mut [f64]) {
        let m = self.memory;
        let mut z = vec![0.0; m];
        let mut w = vec![0.0; m];
        for n in 0..u.len() {
            y[n] = self.sample(u, n, &mut w, &mut z);
            let g = ybar[n];
            if g == 0.0 {
                continue;
            }
            for i in 0..m.min(n + 1) {
                du[n - i] += g * (2.0 * z[i] + self.l[i]);
            }
        }
    }
}

/// z[c0 .. c0 + L] = Σ_j w_j·Hᵀ[j][c0 .. c0 + L], the L sums in registers,
/// each over j in order from −0. Returns L.
#[inline(always)]
fn block<const L: usize>(ht: &[f64], m: usize, c0: usize, w: &[f64], z: &mut [f64]) -> usize {
    let mut acc = [-0.0f64; L];
    for (wj, col) in w.iter().zip(ht.chunks_exact(m)) {
        let col = &col[c0..c0 + L];
        for l in 0..L {
            acc[l] += col[l] * wj;
        }
    }
    z[c0..c0 + L].copy_from_slice(&acc);
    L
}

/// Index of H_ij (i ≤ j) in the upper triangle stored row by row.
pub fn upper_index(m: usize, i: usize, j: usize) -> usize {
    debug_assert!(i <= j && j < m);
    // Rows 0 … i−1 hold m + (m − 1) + … + (m − i + 1) = i·m − i(i−1)/2 values.
    i * m - i * i.saturating_sub(1) / 2 + (j - i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn random(m: usize, seed: u64) -> Volterra {
        let mut r = Rng::new(seed);
        let upper: Vec<f64> = (0..m * (m + 1) / 2).map(|_| r.gaussian()).collect();
        let l: Vec<f64> = (0..m).map(|_| r.gaussian()).collect();
        Volterra::from_upper(&upper, l, r.gaussian()).unwrap()
    }

    #[test]
    fn upper_index_numbers_the_triangle_row_by_row() {
        for m in 1..8 {
            let mut k = 0;
            for i in 0..m {
                for j in i..m {
                    assert_eq!(upper_index(m, i, j), k, "m {m} ({i}, {j})");
                    k += 1;
                }
            }
        }
    }

    #[test]
    fn eval_matches_the_double_sum() {
        let v = random(5, 1);
        let mut r = Rng::new(2);
        let u: Vec<f64> = (0..40).map(|_| r.gaussian()).collect();
        let mut y = vec![0.0; u.len()];
        v.eval(&u, &mut y);
        for (n, yn) in y.iter().enumerate() {
            let at = |k: isize| if k >= 0 { u[k as usize] } else { 0.0 };
            let mut want = v.constant();
            for i in 0..5 {
                want += v.linear()[i] * at(n as isize - i as isize);
                for j in 0..5 {
                    want += v.quadratic(i, j) * at(n as isize - i as isize) * at(n as isize - j as isize);
                }
            }
            assert!((yn - want).abs() < 1e-12 * (1.0 + want.abs()), "n {n}: {yn} vs {want}");
        }
        assert_eq!(Volterra::from_upper(&v.upper(), v.linear().to_vec(), v.constant()).unwrap(), v);
    }

    #[test]
    fn eval_equals_the_row_dot_products_bit_for_bit() {
        // The column layout adds each z_i's terms in the order of the dot
        // product of row i with the window: results must not move at all.
        let v = random(20, 5);
        let mut r = Rng::new(6);
        let u: Vec<f64> = (0..300).map(|_| r.gaussian()).collect();
        let mut y = vec![0.0; u.len()];
        v.eval(&u, &mut y);
        for (n, yn) in y.iter().enumerate() {
            let w: Vec<f64> = (0..20).map(|i| if i <= n { u[n - i] } else { 0.0 }).collect();
            let mut want = v.constant();
            for i in 0..20 {
                let zi: f64 = (0..20).map(|j| v.quadratic(i, j) * w[j]).sum();
                want += w[i] * (zi + v.linear()[i]);
            }
            assert_eq!(yn.to_bits(), want.to_bits(), "n {n}: {yn} vs {want}");
        }
    }

    #[test]
    fn gradient_matches_central_differences() {
        let v = random(7, 3);
        let mut r = Rng::new(4);
        let u: Vec<f64> = (0..60).map(|_| r.gaussian()).collect();
        let ybar: Vec<f64> = (0..60).map(|_| r.gaussian()).collect();
        let (mut y, mut du) = (vec![0.0; 60], vec![0.0; 60]);
        v.eval_grad(&u, &ybar, &mut y, &mut du);
        let f = |u: &[f64]| {
            let mut y = vec![0.0; u.len()];
            v.eval(u, &mut y);
            y.iter().zip(&ybar).map(|(a, b)| a * b).sum::<f64>()
        };
        let h = 1e-6;
        for k in 0..60 {
            let (mut up, mut um) = (u.clone(), u.clone());
            up[k] += h;
            um[k] -= h;
            let fd = (f(&up) - f(&um)) / (2.0 * h);
            assert!((fd - du[k]).abs() < 1e-6 * (1.0 + fd.abs()), "u[{k}]: {} vs {fd}", du[k]);
        }
    }

    #[test]
    fn a_square_law_after_a_filter_has_the_carrier_gain_of_its_squared_nyquist_response() {
        // y = (g0·u[n] + g1·u[n−1])²: H = g gᵀ, κ = (g0 − g1)².
        let (g0, g1) = (0.8, 0.3);
        let h = vec![g0 * g0, g0 * g1, g0 * g1, g1 * g1];
        let v = Volterra::new(h, vec![0.0, 0.0], 0.0).unwrap();
        assert!((v.carrier_gain() - (g0 - g1) * (g0 - g1)).abs() < 1e-15);
        // A held carrier of amplitude a gives κ·a² after the first sample.
        let u: Vec<f64> = (0..10).map(|n| if n % 2 == 0 { 0.7 } else { -0.7 }).collect();
        let mut y = vec![0.0; 10];
        v.eval(&u, &mut y);
        assert!(y[1..].iter().all(|&y| (y - v.carrier_gain() * 0.49).abs() < 1e-12));
    }

    #[test]
    fn bad_kernels_are_refused() {
        assert!(Volterra::new(vec![], vec![], 0.0).is_err());
        assert!(Volterra::new(vec![1.0, 2.0, 3.0, 4.0], vec![0.0, 0.0], 0.0).is_err(), "not symmetric");
        assert!(Volterra::new(vec![1.0; 3], vec![0.0, 0.0], 0.0).is_err());
        assert!(Volterra::new(vec![f64::NAN], vec![0.0], 0.0).is_err());
        assert!(Volterra::from_upper(&[1.0, 2.0], vec![0.0, 0.0], 0.0).is_err());
    }
}
