//! Four forward passes of the display's twin in the four lanes of one
//! AVX2 register ([`DisplayTwin::forward4`]). The floors' minimizations
//! run several starts along one path; two passes side by side
//! ([`DisplayTwin::forward2`]) are bound by their instruction count, four
//! in one register share every instruction.
//!
//! Each lane performs one pass's operations in their order — the circuit
//! rows summed product by product, the lag, the load, the contact's exact
//! map — with separate multiplies and adds where the scalar code has them,
//! so each force and each tape is the one [`DisplayTwin::forward`] gives,
//! bit for bit. Where the scalar code branches (stuck or sliding, the
//! clamps), every lane computes both sides and keeps its own; the sliding
//! friction's exponential is the scalar one's lanes
//! ([`evflow_nodes::exact_exp::lanes`]). On CPUs without AVX2 and FMA, the
//! four passes run as two pairs.

use super::{Branch, DisplayTwin, Step, Tape};

/// The most actuations [`DisplayTwin::objective_grad_each`] runs side by
/// side: the lanes of one AVX2 register.
pub const LANES: usize = 4;

/// One substep of four passes, lane k for pass k: what
/// [`super::Step`] records, as the lanes' backward pass reads it.
#[derive(Debug, Clone, Copy)]
struct LaneStep {
    xm0: [[f64; 4]; 2],
    vr: [f64; 4],
    npre: [f64; 4],
    req_sign: [f64; 4],
    slide: [f64; 4],
    slide_exp: [f64; 4],
    /// All bits set in the lanes whose contact stuck, in those clipped.
    stuck: [f64; 4],
    clipped: [f64; 4],
}

impl LaneStep {
    /// Pass k's step.
    fn step(&self, k: usize) -> Step {
        let set = |m: &[f64; 4]| m[k].to_bits() != 0;
        Step {
            xm0: [self.xm0[0][k], self.xm0[1][k]],
            vr: self.vr[k],
            npre: self.npre[k],
            branch: match (set(&self.stuck), set(&self.clipped)) {
                (true, _) => Branch::Stuck,
                (false, true) => Branch::Clipped,
                (false, false) => Branch::Slide,
            },
            req_sign: self.req_sign[k],
            slide: self.slide[k],
            slide_exp: self.slide_exp[k],
        }
    }

    /// The four passes' steps side by side.
    fn of(s: [&Step; 4]) -> Self {
        let flag = |b: Branch| s.map(|s| if s.branch == b { f64::from_bits(u64::MAX) } else { 0.0 });
        LaneStep {
            xm0: [s.map(|s| s.xm0[0]), s.map(|s| s.xm0[1])],
            vr: s.map(|s| s.vr),
            npre: s.map(|s| s.npre),
            req_sign: s.map(|s| s.req_sign),
            slide: s.map(|s| s.slide),
            slide_exp: s.map(|s| s.slide_exp),
            stuck: flag(Branch::Stuck),
            clipped: flag(Branch::Clipped),
        }
    }
}

/// The tapes of up to four forward passes side by side, for
/// [`DisplayTwin::objective_grad_each`]: each pass's own (its lag factors),
/// and the contact steps of four passes in lanes.
#[derive(Debug, Clone, Default)]
pub struct Tapes {
    each: [Tape; 4],
    steps: Vec<LaneStep>,
}

impl Tapes {
    /// The first pass's tape (for a pass run alone).
    pub fn first(&mut self) -> &mut Tape {
        &mut self.each[0]
    }
}

impl DisplayTwin {
    /// [`Self::forward`] of four actuations of one length along the same
    /// path at once, each with its own tape: each force (and tape) the one
    /// [`Self::forward`] gives, bit for bit.
    pub fn forward4(&self, u: [&[f64]; 4], load: &[f64], velocity: &[f64], tapes: [&mut Tape; 4]) -> [Vec<f64>; 4] {
        debug_assert!(u.iter().all(|x| x.len() == u[0].len()));
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            let mut steps = Vec::new();
            let [ta, tb, tc, td] = tapes;
            let mut tapes = [ta, tb, tc, td];
            // SAFETY: the CPU has AVX2 and FMA.
            let f = unsafe { avx2::forward4(self, u, load, velocity, &mut tapes, &mut steps) };
            for (k, tape) in tapes.iter_mut().enumerate() {
                tape.steps.extend(steps.iter().map(|s| s.step(k)));
            }
            return f;
        }
        let [ta, tb, tc, td] = tapes;
        let [fa, fb] = self.forward2([u[0], u[1]], load, velocity, [ta, tb]);
        let [fc, fd] = self.forward2([u[2], u[3]], load, velocity, [tc, td]);
        [fa, fb, fc, fd]
    }

    /// [`Self::backward`] of four recorded passes of one length at once
    /// (as [`Self::forward4`] ran them), in the lanes of one register; each
    /// gradient the one [`Self::backward`] gives, bit for bit.
    pub fn backward4(&self, tapes: [&Tape; 4], fbar: [&[f64]; 4], ubar: [&mut [f64]; 4]) {
        debug_assert!(tapes.iter().all(|t| t.samples.len() == tapes[0].samples.len()));
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            let steps: Vec<LaneStep> = (0..tapes[0].steps.len())
                .map(|i| LaneStep::of([&tapes[0].steps[i], &tapes[1].steps[i], &tapes[2].steps[i], &tapes[3].steps[i]]))
                .collect();
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { avx2::backward4(self, tapes, &steps, fbar, ubar) };
        }
        let [ga, gb, gc, gd] = ubar;
        self.backward2([tapes[0], tapes[1]], [fbar[0], fbar[1]], [ga, gb]);
        self.backward2([tapes[2], tapes[3]], [fbar[2], fbar[3]], [gc, gd]);
    }

    /// [`Self::objective_grad`] at each of up to four actuations of one
    /// length, values into `fx`: their passes side by side (three or four
    /// in lanes, the fourth lane then a copy of the third, their steps kept
    /// in lanes; two as [`Self::forward2`], [`Self::backward2`]); each value
    /// and gradient the one it gives alone. `adjoint(k, force)` is called
    /// for each actuation's force in order (`k` its index in `u`), so each
    /// may have an objective of its own.
    #[allow(clippy::too_many_arguments)]
    pub fn objective_grad_each(
        &self,
        u: &[&[f64]],
        (load, velocity): (&[f64], &[f64]),
        tapes: &mut Tapes,
        g: &mut [&mut [f64]],
        fx: &mut [f64],
        mut adjoint: impl FnMut(usize, Vec<f64>) -> (f64, Vec<f64>),
    ) {
        let m = u.len();
        assert!(m <= LANES && g.len() == m && fx.len() == m, "up to four actuations, each with its gradient and value");
        let [ta, tb, ..] = &mut tapes.each;
        let forces: Vec<Vec<f64>> = match u {
            [] => return,
            [x] => vec![self.forward(x, load, velocity, ta)],
            [x, y] => self.forward2([x, y], load, velocity, [ta, tb]).into(),
            [x, y, z, rest @ ..] => {
                let w = rest.first().unwrap_or(z);
                let mut f: Vec<Vec<f64>> = self.forward_lanes([x, y, z, w], load, velocity, tapes).into();
                f.truncate(m);
                f
            }
        };
        let mut bars = Vec::with_capacity(m);
        for (k, f) in forces.into_iter().enumerate() {
            let (j, bar) = adjoint(k, f);
            fx[k] = j;
            bars.push(bar);
        }
        g.iter_mut().for_each(|gk| gk.iter_mut().for_each(|v| *v = 0.0));
        let [ta, tb, ..] = &tapes.each;
        let mut spare = Vec::new();
        match (&mut *g, &bars[..]) {
            ([ga], [ba]) => self.backward(ta, ba, ga),
            ([ga, gb], [ba, bb]) => self.backward2([ta, tb], [ba, bb], [ga, gb]),
            ([ga, gb, gc], [ba, bb, bc]) => {
                spare.resize(gc.len(), 0.0);
                self.backward_lanes(tapes, [ba, bb, bc, bc], [ga, gb, gc, &mut spare]);
            }
            ([ga, gb, gc, gd], [ba, bb, bc, bd]) => self.backward_lanes(tapes, [ba, bb, bc, bd], [ga, gb, gc, gd]),
            _ => unreachable!("one gradient per actuation, up to four"),
        }
    }

    /// Four passes side by side into `tapes`: in lanes, their steps kept
    /// in lanes, on CPUs with AVX2 and FMA; else [`Self::forward4`].
    fn forward_lanes(&self, u: [&[f64]; 4], load: &[f64], velocity: &[f64], tapes: &mut Tapes) -> [Vec<f64>; 4] {
        let [ta, tb, tc, td] = &mut tapes.each;
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { avx2::forward4(self, u, load, velocity, &mut [ta, tb, tc, td], &mut tapes.steps) };
        }
        self.forward4(u, load, velocity, [ta, tb, tc, td])
    }

    /// The gradients of the four passes [`Self::forward_lanes`] recorded.
    fn backward_lanes(&self, tapes: &Tapes, fbar: [&[f64]; 4], ubar: [&mut [f64]; 4]) {
        let [ta, tb, tc, td] = &tapes.each;
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { avx2::backward4(self, [ta, tb, tc, td], &tapes.steps, fbar, ubar) };
        }
        self.backward4([ta, tb, tc, td], fbar, ubar)
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::super::electrical::{GAP, RELAX};
    use super::super::{DisplayTwin, Tape, NE};
    use super::LaneStep;
    use evflow_nodes::exact_exp::lanes::exp4;
    use evflow_nodes::lab::electrical;
    use std::arch::x86_64::*;

    /// Four lanes.
    type V = __m256d;

    // The helpers below run AVX2 instructions: they are called only from
    // `forward4` and `backward4` (compiled for AVX2 and FMA, entered on
    // CPUs with both) and the tests (after the same check), and inline
    // there. (Helpers compiled for AVX2 themselves inline later; the
    // objective at four actuations measured no faster with them, 596
    // against 574 µs in one pair of runs.)

    #[inline(always)]
    fn splat(x: f64) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_set1_pd(x) }
    }

    #[inline(always)]
    fn add(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_add_pd(a, b) }
    }

    #[inline(always)]
    fn sub(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_sub_pd(a, b) }
    }

    #[inline(always)]
    fn mul(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_mul_pd(a, b) }
    }

    #[inline(always)]
    fn div(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_div_pd(a, b) }
    }

    #[inline(always)]
    fn lanes(a: V) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: `out` holds four f64.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), a) };
        out
    }

    #[inline(always)]
    fn of(x: [f64; 4]) -> V {
        // SAFETY: `x` holds four f64.
        unsafe { _mm256_loadu_pd(x.as_ptr()) }
    }

    /// `a` where `mask` is set, else `b`.
    #[inline(always)]
    fn select(mask: V, a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_blendv_pd(b, a, mask) }
    }

    #[inline(always)]
    fn abs(a: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), a) }
    }

    #[inline(always)]
    fn neg(a: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_xor_pd(_mm256_set1_pd(-0.0), a) }
    }

    /// `f64::max` lane by lane: the other operand where one is NaN.
    #[inline(always)]
    pub(super) fn max(x: V, y: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { select(_mm256_cmp_pd::<_CMP_UNORD_Q>(x, x), y, _mm256_max_pd(y, x)) }
    }

    /// `f64::min` lane by lane: the other operand where one is NaN.
    #[inline(always)]
    pub(super) fn min(x: V, y: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { select(_mm256_cmp_pd::<_CMP_UNORD_Q>(x, x), y, _mm256_min_pd(y, x)) }
    }

    /// `f64::signum` lane by lane: ±1 by the sign bit, NaN where NaN.
    #[inline(always)]
    pub(super) fn signum(x: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe {
            let one = _mm256_or_pd(_mm256_and_pd(_mm256_set1_pd(-0.0), x), _mm256_set1_pd(1.0));
            select(_mm256_cmp_pd::<_CMP_UNORD_Q>(x, x), _mm256_set1_pd(f64::NAN), one)
        }
    }

    /// a ≤ b (false where either is NaN).
    #[inline(always)]
    fn le(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_cmp_pd::<_CMP_LE_OQ>(a, b) }
    }

    /// a > b (false where either is NaN).
    #[inline(always)]
    fn gt(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(a, b) }
    }

    /// Every bit set.
    #[inline(always)]
    fn all_ones() -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_castsi256_pd(_mm256_set1_epi64x(-1)) }
    }

    /// a < b (false where either is NaN).
    #[inline(always)]
    fn lt(a: V, b: V) -> V {
        // SAFETY: AVX2 and FMA are there (above).
        unsafe { _mm256_cmp_pd::<_CMP_LT_OQ>(a, b) }
    }

    /// The four passes' state, lane k for pass k.
    struct Runs {
        xe: [V; NE],
        fl: V,
        xm: [V; 2],
        /// All ones in the lanes whose contact is stuck.
        stuck: V,
    }

    /// The four passes (`DisplayTwin::forward4`), their steps into
    /// `steps`, each pass's lag factors into its tape.
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn forward4(
        t: &DisplayTwin,
        u: [&[f64]; 4],
        load: &[f64],
        velocity: &[f64],
        tapes: &mut [&mut Tape; 4],
        steps: &mut Vec<LaneStep>,
    ) -> [Vec<f64>; 4] {
        let len = u[0].len();
        // Each pass's tape keeps its lag factors; the steps go to `steps`.
        for tape in tapes.iter_mut() {
            tape.steps.clear();
            tape.samples.truncate(len);
            tape.velocity.truncate(len);
        }
        steps.clear();
        steps.reserve(len * t.sub);
        // The scalar sums start where `Iterator::sum` starts.
        let sum0 = splat(std::iter::empty::<f64>().sum());
        let vr0 = electrical::force_voltage(&t.x0);
        let mut xe = [sum0; NE];
        for (x, x0) in xe.iter_mut().zip(t.x0) {
            *x = splat(x0);
        }
        let mut r = Runs { xe, fl: splat(t.ke * vr0 * vr0), xm: [splat(0.0); 2], stuck: all_ones() };
        let mut out: [Vec<f64>; 4] = Default::default();
        for o in out.iter_mut() {
            o.reserve(len);
        }
        for n in 0..len {
            let ld = if load[n].is_finite() { load[n].max(0.0) } else { 0.0 };
            let v = if velocity[n].is_finite() { velocity[n] } else { 0.0 };
            let (mut vcmd, mut a) = ([0.0; 4], [0.0; 4]);
            for k in 0..4 {
                (vcmd[k], a[k]) = t.drive(u[k], n, v, tapes[k]);
            }
            let (vcmd, a) = (of(vcmd), of(a));
            let one_minus_a = sub(splat(1.0), a);
            // The holder's term of the contact's free motion: one path, one value.
            let g = super::super::matvec(&t.gam_m, &[v, 0.0]);
            for _ in 0..t.sub {
                steps.push(substep(t, &mut r, sum0, vcmd, a, one_minus_a, ld, v, g));
            }
            let f = lanes(add(mul(splat(t.k), r.xm[0]), mul(splat(t.c), sub(splat(v), r.xm[1]))));
            for k in 0..4 {
                out[k].push(f[k]);
            }
        }
        out
    }

    /// One substep of the four passes: circuit, lag, load, contact;
    /// recorded in lanes.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn substep(
        t: &DisplayTwin,
        r: &mut Runs,
        sum0: V,
        vcmd: V,
        a: V,
        one_minus_a: V,
        ld: f64,
        v: f64,
        g: [f64; 3],
    ) -> LaneStep {
        let ds_df = t.gam_m[2][1];
        // (No closures here: they would not be compiled for AVX2.)
        let mut y = [sum0; NE];
        for (i, yi) in y.iter_mut().enumerate() {
            for j in 0..NE {
                *yi = add(*yi, mul(splat(t.phi_e[i][j]), r.xe[j]));
            }
        }
        for ((x, yi), ge) in r.xe.iter_mut().zip(y).zip(t.gam_e) {
            *x = add(yi, mul(splat(ge), vcmd));
        }
        let vr = sub(r.xe[electrical::GAP], r.xe[electrical::RELAX]);
        let fe = mul(mul(splat(t.ke), vr), vr);
        r.fl = add(mul(a, r.fl), mul(one_minus_a, fe));
        let npre = add(splat(ld), r.fl);
        let nf = max(npre, splat(0.0));
        // The sliding friction at this speed and load, in every lane (the
        // scalar pass takes it where the contact slides or starts to).
        let speed = abs(r.xm[1]);
        let q = div(speed, splat(t.v_s));
        // SAFETY: AVX2 and FMA are there (`forward4`'s condition).
        let e = unsafe { exp4(mul(neg(q), q)) };
        let fs_slide = add(mul(add(splat(t.mu_k), mul(splat(t.mu_s - t.mu_k), e)), nf), mul(splat(t.viscous), speed));
        let limit = select(r.stuck, mul(splat(t.mu_s), nf), fs_slide);
        let xa = [r.xm[0], r.xm[1], splat(0.0)];
        let mut free = [sum0; 3];
        for (i, fi) in free.iter_mut().enumerate() {
            for (j, x) in xa.iter().enumerate() {
                *fi = add(*fi, mul(splat(t.phi_m[i][j]), *x));
            }
            *fi = add(*fi, splat(g[i]));
        }
        let required = if ds_df != 0.0 { div(neg(free[2]), splat(ds_df)) } else { splat(0.0) };
        let req_abs = abs(required);
        let stick = le(req_abs, max(limit, splat(0.0)));
        let fs = max(fs_slide, splat(0.0));
        let sign = signum(required);
        let force = mul(min(fs, req_abs), sign);
        let xm0 = r.xm;
        let zero = splat(0.0);
        r.xm = [
            select(stick, add(xm0[0], splat(v * t.hs)), add(free[0], mul(splat(t.gam_m[0][1]), force))),
            select(stick, splat(0.0), add(free[1], mul(splat(t.gam_m[1][1]), force))),
        ];
        r.stuck = stick;
        // SAFETY: as above.
        let clipped = unsafe { _mm256_andnot_pd(_mm256_or_pd(stick, lt(fs, req_abs)), all_ones()) };
        LaneStep {
            xm0: [lanes(xm0[0]), lanes(xm0[1])],
            vr: lanes(vr),
            npre: lanes(npre),
            req_sign: lanes(sign),
            slide: lanes(select(stick, zero, fs_slide)),
            slide_exp: lanes(select(stick, zero, e)),
            stuck: lanes(stick),
            clipped: lanes(clipped),
        }
    }

    /// The four passes' adjoints, lane k for pass k.
    struct Adjoints {
        bxe: [V; NE],
        bfl: V,
        bxm: [V; 2],
    }

    /// The four passes' gradients (`DisplayTwin::backward4`) from their
    /// steps in lanes and their tapes' lag factors.
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn backward4(
        t: &DisplayTwin,
        tapes: [&Tape; 4],
        steps: &[LaneStep],
        fbar: [&[f64]; 4],
        ubar: [&mut [f64]; 4],
    ) {
        let zero = splat(0.0);
        let mut b = Adjoints { bxe: [zero; NE], bfl: zero, bxm: [zero; 2] };
        let [ga, gb, gc, gd] = ubar;
        let mut ubar = [ga, gb, gc, gd];
        for n in (0..tapes[0].samples.len()).rev() {
            let fb = of([fbar[0][n], fbar[1][n], fbar[2][n], fbar[3][n]]);
            b.bxm[0] = add(b.bxm[0], mul(splat(t.k), fb));
            b.bxm[1] = sub(b.bxm[1], mul(splat(t.c), fb));
            let a = of([0, 1, 2, 3].map(|k| tapes[k].samples[n].0));
            let mut bvcmd = zero;
            for j in (0..t.sub).rev() {
                substep_adjoint(t, &mut b, &steps[n * t.sub + j], a, &mut bvcmd);
            }
            let bv = lanes(bvcmd);
            for (k, ub) in ubar.iter_mut().enumerate() {
                if !tapes[k].samples[n].1 && n >= t.delay {
                    ub[n - t.delay] += bv[k] * t.gain;
                }
            }
        }
    }

    /// One substep of the four passes transposed, each lane as
    /// `DisplayTwin::substep_adjoint` (both sides of its branches taken,
    /// each lane keeping its own).
    #[inline(always)]
    fn substep_adjoint(t: &DisplayTwin, b: &mut Adjoints, s: &LaneStep, a: V, bvcmd: &mut V) {
        let zero = splat(0.0);
        let ds_df = t.gam_m[2][1];
        let (stuck, clipped) = (of(s.stuck), of(s.clipped));
        let slide = of(s.slide);
        // Sliding with a positive friction (neither stuck nor clipped).
        // SAFETY: AVX2 and FMA are there (`backward4`'s condition).
        let sliding = unsafe { _mm256_andnot_pd(_mm256_or_pd(stuck, clipped), gt(slide, zero)) };
        let xm01 = of(s.xm0[1]);
        let npre = of(s.npre);
        let req_sign = of(s.req_sign);
        let slide_exp = of(s.slide_exp);
        let vr = of(s.vr);
        // (5) contact step, sliding side.
        let bforce = add(mul(b.bxm[0], splat(t.gam_m[0][1])), mul(b.bxm[1], splat(t.gam_m[1][1])));
        let bfree2 = select(clipped, add(zero, div(neg(bforce), splat(ds_df))), zero);
        let bfree = [b.bxm[0], b.bxm[1], bfree2];
        // The Stribeck friction's slopes (`DisplayTwin::slide_grad`).
        let w = abs(xm01);
        let nf = max(npre, zero);
        let r = div(w, splat(t.v_s));
        let dmu = mul(splat(t.mu_s - t.mu_k), slide_exp);
        let dw = add(mul(mul(dmu, div(mul(splat(-2.0), r), splat(t.v_s))), nf), splat(t.viscous));
        let dn = add(splat(t.mu_k), dmu);
        let bs = mul(bforce, req_sign);
        let bn = select(sliding, add(zero, mul(bs, dn)), zero);
        let mut slid = [zero, select(sliding, add(zero, mul(mul(bs, dw), signum(xm01))), zero)];
        for (jj, bm) in slid.iter_mut().enumerate() {
            for (i, bf) in bfree.iter().enumerate() {
                *bm = add(*bm, mul(*bf, splat(t.phi_m[i][jj])));
            }
        }
        b.bxm = [select(stuck, b.bxm[0], slid[0]), select(stuck, zero, slid[1])];
        // (3) N = max(0, F_n + F_l).
        b.bfl = select(gt(npre, zero), add(b.bfl, bn), b.bfl);
        // (2) lag and square law.
        let bfe = mul(sub(splat(1.0), a), b.bfl);
        b.bfl = mul(b.bfl, a);
        let mut bxe1 = b.bxe;
        let square = mul(mul(mul(bfe, splat(2.0)), splat(t.ke)), vr);
        bxe1[GAP] = add(bxe1[GAP], square);
        bxe1[RELAX] = sub(bxe1[RELAX], square);
        // (1) circuit.
        let mut b0 = [zero; NE];
        for (i, bi) in bxe1.iter().enumerate() {
            for (jj, bj) in b0.iter_mut().enumerate() {
                *bj = add(*bj, mul(*bi, splat(t.phi_e[i][jj])));
            }
            *bvcmd = add(*bvcmd, mul(*bi, splat(t.gam_e[i])));
        }
        b.bxe = b0;
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{actuation, bits, pass, shipped, two_actuations};
    use super::super::{Branch, DisplayTwin, Tape};

    #[test]
    fn four_passes_in_lanes_are_each_the_single_pass_bit_for_bit() {
        // On every shipped profile: four actuations (one past the
        // amplifier's range, one with non-finite samples), fresh and
        // reused tapes; forces and tapes as each pass alone.
        for (name, profile) in shipped() {
            let (load, vel, ua, ub) = two_actuations(&profile);
            let n = load.len();
            let uc: Vec<f64> = ua.iter().map(|v| 40.0 * v).collect();
            let ud: Vec<f64> =
                ua.iter().enumerate().map(|(k, v)| if k % 97 == 5 { f64::NAN } else { -0.3 * v }).collect();
            let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
            let us = [&ua, &ub, &uc, &ud];
            let mut want_tapes: Vec<Tape> = (0..4).map(|_| Tape::default()).collect();
            let want: Vec<Vec<f64>> =
                us.iter().zip(&mut want_tapes).map(|(u, t)| twin.forward(u, &load, &vel, t)).collect();
            let mut kept = want_tapes[1].clone();
            let (mut t0, mut t2, mut t3) = (Tape::default(), Tape::default(), Tape::default());
            let got = twin.forward4([&ua, &ub, &uc, &ud], &load, &vel, [&mut t0, &mut kept, &mut t2, &mut t3]);
            for (k, tape) in [&t0, &kept, &t2, &t3].into_iter().enumerate() {
                assert_eq!(bits(&got[k]), bits(&want[k]), "{name}: force {k}");
                // The tape gives the single pass's gradient.
                let fbar: Vec<f64> = (0..n).map(|j| ((j * 5 % 11) as f64 - 5.0) * 0.2).collect();
                let (mut g, mut g0) = (vec![0.0; n], vec![0.0; n]);
                twin.backward(tape, &fbar, &mut g);
                twin.backward(&want_tapes[k], &fbar, &mut g0);
                assert_eq!(bits(&g), bits(&g0), "{name}: gradient {k}");
            }
            // The four gradients in lanes.
            let fbars: Vec<Vec<f64>> =
                (0..4).map(|k| (0..n).map(|j| ((j * (k + 3) % 11) as f64 - 5.0) * 0.2).collect()).collect();
            let mut gs: Vec<Vec<f64>> = (0..4).map(|_| vec![0.5; n]).collect();
            let want_g: Vec<Vec<f64>> = (0..4)
                .map(|k| {
                    let mut g = vec![0.5; n];
                    twin.backward(&want_tapes[k], &fbars[k], &mut g);
                    g
                })
                .collect();
            let [g0, g1, g2, g3] = &mut gs[..] else { unreachable!() };
            twin.backward4([&t0, &kept, &t2, &t3], [&fbars[0], &fbars[1], &fbars[2], &fbars[3]], [g0, g1, g2, g3]);
            for k in 0..4 {
                assert_eq!(bits(&gs[k]), bits(&want_g[k]), "{name}: backward4 gradient {k}");
            }
            let branches = |t: &Tape, b: Branch| t.steps.iter().filter(|s| s.branch == b).count();
            assert!(branches(&t0, Branch::Slide) > 0 && branches(&t0, Branch::Stuck) > 0, "{name}");
        }
    }

    #[test]
    fn objectives_side_by_side_are_each_the_objective_alone() {
        // One to four actuations: values and gradients as each alone.
        let profile = evflow_nodes::lab::profile::LabProfile::default();
        let (load, vel) = pass(&profile, 85.0, 5.0);
        let n = load.len();
        let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
        let us: Vec<Vec<f64>> =
            (0..4).map(|k| actuation(n).iter().map(|v| v * (1.0 - 0.3 * k as f64)).collect()).collect();
        // J = Σ w·F², ∂J/∂F = 2·w·F, the weights w of each actuation its own.
        let adjoint = |which: usize, f: Vec<f64>| {
            let w = |k: usize| 1.0 + ((k + 2 * which) % 5) as f64;
            let j = f.iter().enumerate().map(|(k, x)| w(k) * x * x).sum();
            (j, f.iter().enumerate().map(|(k, x)| 2.0 * w(k) * x).collect())
        };
        let alone: Vec<(f64, Vec<f64>)> = us
            .iter()
            .enumerate()
            .map(|(which, u)| {
                let mut g = vec![0.0; n];
                let j = twin.objective_grad(u, (&load, &vel), &mut Tape::default(), &mut g, |f| adjoint(which, f));
                (j, g)
            })
            .collect();
        for m in 1..=4 {
            let mut tapes = super::Tapes::default();
            let mut gs: Vec<Vec<f64>> = (0..m).map(|_| vec![7.0; n]).collect();
            let mut g: Vec<&mut [f64]> = gs.iter_mut().map(|g| g.as_mut_slice()).collect();
            let mut fx = vec![0.0; m];
            let u: Vec<&[f64]> = us[..m].iter().map(|u| u.as_slice()).collect();
            twin.objective_grad_each(&u, (&load, &vel), &mut tapes, &mut g, &mut fx, adjoint);
            for k in 0..m {
                assert_eq!(fx[k].to_bits(), alone[k].0.to_bits(), "{m} side by side: value {k}");
                assert_eq!(bits(&gs[k]), bits(&alone[k].1), "{m} side by side: gradient {k}");
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_lanes_max_min_and_signum_are_the_scalar_ones() {
        use std::arch::x86_64::*;
        use std::hint::black_box;
        if !evflow_nodes::cpu::has_avx2_fma() {
            return;
        }
        let special = [0.0, -0.0, 1.0, -1.0, f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 5e-324, -2.5];
        let bits4 = |v: __m256d| {
            let mut o = [0.0; 4];
            // SAFETY: AVX is there (checked above).
            unsafe { _mm256_storeu_pd(o.as_mut_ptr(), v) };
            o.map(f64::to_bits)
        };
        for &x in &special {
            for &y in &special {
                // SAFETY: AVX2 and FMA are there (checked above).
                let (vx, vy) = unsafe { (_mm256_set1_pd(x), _mm256_set1_pd(y)) };
                let (x, y) = (black_box(x), black_box(y));
                assert_eq!(bits4(super::avx2::max(vx, vy))[0], x.max(y).to_bits(), "max({x:?}, {y:?})");
                assert_eq!(bits4(super::avx2::min(vx, vy))[0], x.min(y).to_bits(), "min({x:?}, {y:?})");
            }
            // SAFETY: as above.
            let vx = unsafe { _mm256_set1_pd(x) };
            assert_eq!(bits4(super::avx2::signum(vx))[0], black_box(x).signum().to_bits(), "signum({x:?})");
        }
    }
}
