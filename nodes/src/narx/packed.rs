//! The forward pass of a trained [`Mlp`] laid out for speed: what the
//! closed loop runs once per sample.
//!
//! # Layout
//!
//! Each layer's weight matrix is stored transposed (Wᵀ, row-major: the
//! weights of input j to every neuron are contiguous), its rows padded with
//! zeros to a multiple of [`LANES`] neurons. A layer is then one pass over
//! its inputs that adds `x[j]·Wᵀ[j]` to up to 16 running sums held in
//! registers — no horizontal sum, no gather — which the compiler turns into
//! packed SIMD instructions. The activations go through the tanh four
//! neurons at a time ([`exact_tanh_avx2::tanh4`], [`fast_tanh::tanh_lanes`]).
//! On x86-64 CPUs with AVX2
//! and FMA (detected once, at construction) the same code runs compiled
//! for AVX2: one 4-wide register per block instead of two SSE2 ones.
//!
//! # Results
//!
//! Each neuron's sum runs over its inputs in the same order as
//! [`Mlp::forward`] (from −0, then + bias), without fused multiply-adds:
//! with [`Tanh::Exact`] the output equals [`Mlp::forward`]'s bit for bit
//! (a test checks it). [`Tanh::Fast`] replaces each tanh by
//! [`fast_tanh::tanh`], |error| ≤ [`fast_tanh::MAX_ABS_ERROR`] per neuron,
//! and on the AVX2 build also sums with fused multiply-adds in two partial
//! sums per neuron (inputs of even and odd rank): other roundings, of the
//! order of 1e-16 of the sum of |terms| (the test bounds both effects).
//!
//! Nothing allocates after [`PackedMlp::new`].

use super::net::Mlp;
use super::{exact_tanh, exact_tanh_avx2, fast_tanh, fast_tanh_avx2};
use std::str::FromStr;

/// Neurons per block: the width of the vectors the sums run in.
pub const LANES: usize = 4;

/// Which tanh the hidden layers use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tanh {
    /// [`exact_tanh::tanh`]: glibc's `tanh` written out (within 1 ulp; the
    /// standard library's bits on Linux x86-64 with FMA, the same bits on
    /// every platform), four neurons at a time on AVX2.
    #[default]
    Exact,
    /// [`fast_tanh::tanh`]: within [`fast_tanh::MAX_ABS_ERROR`] = 1e-15,
    /// branch-free, vectorized over a neuron block.
    Fast,
}

impl Tanh {
    /// The parameter value naming this choice (`exact` or `fast`).
    pub fn name(self) -> &'static str {
        match self {
            Tanh::Exact => "exact",
            Tanh::Fast => "fast",
        }
    }
}

impl FromStr for Tanh {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "exact" => Ok(Tanh::Exact),
            "fast" => Ok(Tanh::Fast),
            _ => Err(format!("`{s}` is not a tanh (exact or fast)")),
        }
    }
}

/// One layer in the transposed, padded layout (module documentation).
#[derive(Debug, Clone)]
struct Layer {
    /// Inputs.
    r: usize,
    /// Neurons rounded up to a multiple of LANES: the row stride of `w`.
    sp: usize,
    /// Wᵀ, row-major: the sp weights of input j from `w[j·sp]`.
    w: Vec<f64>,
    /// Biases, sp of them (zero in the padding).
    b: Vec<f64>,
}

/// A network's forward pass in the blocked layout, with its own scratch.
#[derive(Debug, Clone)]
pub struct PackedMlp {
    inputs: usize,
    layers: Vec<Layer>,
    tanh: Tanh,
    /// The CPU has AVX2 and FMA: run the AVX2 build of the same code.
    avx2: bool,
    /// Activations of two consecutive layers (padded), alternately.
    a: Vec<f64>,
    b: Vec<f64>,
}

impl PackedMlp {
    /// The blocked copy of `net`, its hidden layers using `tanh`.
    pub fn new(net: &Mlp, tanh: Tanh) -> Self {
        let mut sizes = vec![net.inputs()];
        sizes.extend_from_slice(net.hidden());
        sizes.push(1);
        let w = net.weights();
        let mut off = 0;
        let mut layers = Vec::with_capacity(sizes.len() - 1);
        let mut widest = 0;
        for l in 1..sizes.len() {
            let (r, s) = (sizes[l - 1], sizes[l]);
            let sp = s.div_ceil(LANES) * LANES;
            let (wl, bl) = (&w[off..off + s * r], &w[off + s * r..off + s * r + s]);
            let mut pw = vec![0.0; r * sp];
            let mut pb = vec![0.0; sp];
            for i in 0..s {
                for j in 0..r {
                    pw[j * sp + i] = wl[i * r + j];
                }
                pb[i] = bl[i];
            }
            widest = widest.max(sp);
            layers.push(Layer { r, sp, w: pw, b: pb });
            off += s * r + s;
        }
        Self {
            inputs: net.inputs(),
            layers,
            tanh,
            avx2: crate::cpu::has_avx2_fma(),
            a: vec![0.0; widest],
            b: vec![0.0; widest],
        }
    }

    /// Number of inputs.
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// The tanh in use.
    pub fn tanh(&self) -> Tanh {
        self.tanh
    }

    /// Switches the tanh of the hidden layers.
    pub fn set_tanh(&mut self, tanh: Tanh) {
        self.tanh = tanh;
    }

    /// The output for the input vector `head` followed by `tail` (together
    /// [`PackedMlp::inputs`] values; two slices so that a caller holding
    /// feedback and force histories apart need not copy them into one row).
    #[inline]
    pub fn forward(&mut self, head: &[f64], tail: &[f64]) -> f64 {
        debug_assert_eq!(head.len() + tail.len(), self.inputs);
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `cpu::has_avx2_fma` found AVX2 and FMA on this CPU when `self`
            // was built; the function only needs those.
            return unsafe { self.forward_avx2(head, tail) };
        }
        self.forward_impl::<false, false>(head, tail)
    }

    /// The forward pass compiled for AVX2 and FMA: the same code, with
    /// fused multiply-adds in the sums and the tanh when the tanh is fast
    /// (the exact tanh keeps separate roundings, equal to the portable build).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn forward_avx2(&mut self, head: &[f64], tail: &[f64]) -> f64 {
        match self.tanh {
            Tanh::Exact => self.forward_impl::<false, true>(head, tail),
            Tanh::Fast => self.forward_impl::<true, true>(head, tail),
        }
    }

    #[inline(always)]
    fn forward_impl<const FUSED: bool, const AVX2: bool>(&mut self, head: &[f64], tail: &[f64]) -> f64 {
        let last = self.layers.len() - 1;
        let tanh: Act = self.tanh.into();
        let (first, rest) = self.layers.split_first().expect("a network has an output layer");
        layer::<FUSED, AVX2>(first, head, tail, if last == 0 { Act::Linear } else { tanh }, &mut self.a);
        let (mut cur, mut next) = (&mut self.a, &mut self.b);
        for (k, lay) in rest.iter().enumerate() {
            let act = if k + 1 == last { Act::Linear } else { tanh };
            layer::<FUSED, AVX2>(lay, &cur[..lay.r], &[], act, next);
            std::mem::swap(&mut cur, &mut next);
        }
        cur[0]
    }
}

/// The activation of a layer.
#[derive(Clone, Copy)]
enum Act {
    Linear,
    Exact,
    Fast,
}

impl From<Tanh> for Act {
    fn from(t: Tanh) -> Act {
        match t {
            Tanh::Exact => Act::Exact,
            Tanh::Fast => Act::Fast,
        }
    }
}

/// Neuron blocks one pass over the inputs serves: their sums stay in
/// registers (four blocks of four: 16 neurons, 8 SSE2 or 4 AVX registers).
const GROUP: usize = 4;

/// One layer: `out[i] = act(b[i] + Σ_j w[i][j]·x[j])`, x = head ++ tail,
/// every neuron of the padded output written.
#[inline(always)]
fn layer<const FUSED: bool, const AVX2: bool>(lay: &Layer, head: &[f64], tail: &[f64], act: Act, out: &mut [f64]) {
    let mut c0 = 0;
    while c0 < lay.sp {
        match (lay.sp - c0) / LANES {
            1 => group::<1, FUSED, AVX2>(lay, c0, head, tail, act, out),
            2 => group::<2, FUSED, AVX2>(lay, c0, head, tail, act, out),
            3 => group::<3, FUSED, AVX2>(lay, c0, head, tail, act, out),
            _ => group::<GROUP, FUSED, AVX2>(lay, c0, head, tail, act, out),
        }
        c0 += GROUP * LANES;
    }
}

/// B neuron blocks from column c0: one pass over the inputs, B·LANES sums.
#[inline(always)]
fn group<const B: usize, const FUSED: bool, const AVX2: bool>(
    lay: &Layer,
    c0: usize,
    head: &[f64],
    tail: &[f64],
    act: Act,
    out: &mut [f64],
) {
    let sp = lay.sp;
    // −0.0 as `Iterator::sum` starts, so that signed zeros come out as in
    // `Mlp::forward`.
    let mut acc = [[-0.0f64; LANES]; B];
    if FUSED {
        // Two partial sums per neuron (inputs of even and odd rank), added
        // at the end: half the length of the chain of dependent adds, which
        // is what a layer's time is bound by at these sizes.
        let mut odd = [[0.0f64; LANES]; B];
        let mut rows = lay.w.chunks_exact(sp);
        let mut xs = head.iter().chain(tail);
        while let (Some(w0), Some(&x0)) = (rows.next(), xs.next()) {
            let w0 = &w0[c0..c0 + B * LANES];
            for (a, w) in acc.iter_mut().zip(w0.chunks_exact(LANES)) {
                for l in 0..LANES {
                    a[l] = w[l].mul_add(x0, a[l]);
                }
            }
            let (Some(w1), Some(&x1)) = (rows.next(), xs.next()) else { break };
            let w1 = &w1[c0..c0 + B * LANES];
            for (a, w) in odd.iter_mut().zip(w1.chunks_exact(LANES)) {
                for l in 0..LANES {
                    a[l] = w[l].mul_add(x1, a[l]);
                }
            }
        }
        for (a, o) in acc.iter_mut().zip(&odd) {
            for l in 0..LANES {
                a[l] += o[l];
            }
        }
    } else {
        for (wj, &x) in lay.w.chunks_exact(sp).zip(head.iter().chain(tail)) {
            let wj = &wj[c0..c0 + B * LANES];
            for (a, w) in acc.iter_mut().zip(wj.chunks_exact(LANES)) {
                for l in 0..LANES {
                    a[l] += w[l] * x;
                }
            }
        }
    }
    for (k, a) in acc.iter().enumerate() {
        let c = c0 + k * LANES;
        let bc = &lay.b[c..c + LANES];
        let mut z = [0.0; LANES];
        for l in 0..LANES {
            z[l] = bc[l] + a[l];
        }
        let y = match act {
            Act::Linear => z,
            // SAFETY: AVX2 is instantiated only by `forward_avx2` (as FUSED).
            Act::Exact if AVX2 => unsafe { exact_tanh_avx2::tanh4_avx2(z) },
            Act::Exact => z.map(exact_tanh::tanh),
            // SAFETY: FUSED is instantiated only by `forward_avx2`, which
            // runs after `cpu::has_avx2_fma` found AVX2 and FMA.
            Act::Fast if FUSED => unsafe { fast_tanh_avx2::tanh4_fused(z) },
            Act::Fast => fast_tanh::tanh_lanes(z),
        };
        out[c..c + LANES].copy_from_slice(&y);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn net(inputs: usize, hidden: &[usize], seed: u64) -> Mlp {
        let mut m = Mlp::new(inputs, hidden).unwrap();
        m.init_nguyen_widrow(&mut Rng::new(seed));
        m
    }

    #[test]
    fn exact_equals_the_reference_forward_bit_for_bit() {
        let mut r = Rng::new(5);
        for (inputs, hidden) in
            [(15, vec![15, 10, 5]), (21, vec![15, 10, 5]), (3, vec![4]), (2, vec![]), (6, vec![9, 1])]
        {
            let m = net(inputs, &hidden, 3);
            let mut p = PackedMlp::new(&m, Tanh::Exact);
            let mut ws = m.workspace();
            for split in [0, 1, inputs / 2, inputs] {
                for _ in 0..200 {
                    let x: Vec<f64> = (0..inputs).map(|_| 3.0 * r.gaussian()).collect();
                    let want = m.forward(&x, &mut ws);
                    let got = p.forward(&x[..split], &x[split..]);
                    assert_eq!(got.to_bits(), want.to_bits(), "{hidden:?} split {split}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn fast_stays_within_the_propagated_tanh_error() {
        // Each hidden value moves by at most ε = MAX_ABS_ERROR plus what the
        // errors of the layer before carry through |W|: δ_l ≤ ε + ‖W_l‖∞·δ_{l−1}
        // (tanh is 1-Lipschitz), and the output by ‖W_out‖∞·δ_last. On the
        // AVX2 build the fast path also rounds its sums differently (fused,
        // two partial sums): each sum of r terms of either path is within
        // (r + 1)·2⁻⁵³·(‖W_l‖∞·max|a| + max|b|) of the true one (recursive
        // summation), so the two differ by at most twice that.
        let m = net(15, &[15, 10, 5], 9);
        let (mut exact, mut fast) = (PackedMlp::new(&m, Tanh::Exact), PackedMlp::new(&m, Tanh::Fast));
        const XMAX: f64 = 6.0;
        let mut bound = 0.0;
        let mut off = 0;
        let sizes = [15, 15, 10, 5, 1];
        for l in 1..sizes.len() {
            let (r, s) = (sizes[l - 1], sizes[l]);
            let w = &m.weights()[off..off + s * r];
            let b = &m.weights()[off + s * r..off + s * r + s];
            let norm = (0..s).map(|i| w[i * r..(i + 1) * r].iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
            let amax = if l == 1 { XMAX } else { 1.0 };
            let bmax = b.iter().map(|v| v.abs()).fold(0.0, f64::max);
            let sums = 2.0 * (r + 1) as f64 * f64::EPSILON / 2.0 * (norm * amax + bmax);
            bound = norm * bound + sums + if l + 1 < sizes.len() { fast_tanh::MAX_ABS_ERROR } else { 0.0 };
            off += s * r + s;
        }
        let mut r = Rng::new(1);
        let mut worst = 0.0f64;
        for _ in 0..20_000 {
            let x: Vec<f64> = (0..15).map(|_| r.gaussian().clamp(-XMAX, XMAX)).collect();
            let d = (exact.forward(&x, &[]) - fast.forward(&[], &x)).abs();
            worst = worst.max(d);
        }
        assert!(worst <= bound, "{worst:e} > {bound:e}");
        assert!(bound < 1e-12, "{bound:e}");
    }

    #[test]
    fn tanh_names_round_trip() {
        for t in [Tanh::Exact, Tanh::Fast] {
            assert_eq!(t.name().parse::<Tanh>(), Ok(t));
        }
        assert!("approx".parse::<Tanh>().is_err());
        assert_eq!(Tanh::default(), Tanh::Exact);
    }
}
