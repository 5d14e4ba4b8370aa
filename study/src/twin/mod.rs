//! Differentiable twins of the simulated display and force sensor: the same
//! equations, the same exact maps and the same arithmetic as
//! [`evflow_nodes::lab::display_model::DisplayModel`] and
//! [`evflow_nodes::lab::sensor_model::SensorModel`] with their noise off, run
//! forward while recording a tape, then backward (reverse mode) to give the
//! gradient of any function of the output force with respect to every
//! actuation sample. The achievable floor ([`super::floor`]) optimizes
//! through them — through the display itself, not a model of it.
//!
//! Forward: the actuation delayed by the display's latency (whole
//! samples), then per substep (exact integrator): circuit with its charge
//! relaxation state q (electrical.rs) x_e ← Φ_e x_e + Γ_e V_cmd;
//! F_e = k_e v_r², v_r = v_g − q (q ≡ 0 without relaxation); lag F_l ← a F_l + (1 − a) F_e; N = max(0, F_n + F_l); the
//! tip's augmented exact map gives the free motion and the slip s; the
//! contact sticks if the force that keeps s = 0 is within the static limit,
//! else it slides with the Stribeck friction (or with that force, if
//! smaller). Backward: the same steps transposed; the stick/slide branch and
//! the clamps (amplifier limit, N ≥ 0, sensor full scale) are held as the
//! forward pass took them (their derivative where they switch is taken as
//! that of the branch taken), the sensor's quantization is exact forward and
//! passed straight through backward (its derivative is 0 almost everywhere,
//! which would stop every gradient; the straight-through estimate treats the
//! rounding as the identity, off by at most half a converter step). The tests check the twin against the lab's models sample by
//! sample and the gradient against central differences.

use evflow_nodes::exact_exp;
use evflow_nodes::lab::electrical::{self, Circuit};
use evflow_nodes::lab::expm::zoh;
use evflow_nodes::lab::profile::LabProfile;

mod lanes;
pub use lanes::{Tapes, LANES};

/// States of the circuit with its relaxation state.
const NE: usize = electrical::NR;

/// How a substep's contact step went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Branch {
    /// Held: the slip is 0.
    Stuck,
    /// Sliding with the Stribeck friction.
    Slide,
    /// Sliding with the smaller force that keeps the slip 0 (the friction
    /// can stop the tip within the step, but the contact was not stuck).
    Clipped,
}

#[derive(Debug, Clone, Copy)]
struct Step {
    xm0: [f64; 2],
    /// The square-law voltage v_r = v_g − q after the circuit step.
    vr: f64,
    npre: f64,
    branch: Branch,
    req_sign: f64,
    /// On a sliding step (`Slide`, `Clipped`), the sliding friction at the
    /// step's speed and load and its exp(−(speed/v_s)²), kept so that the
    /// backward pass does not evaluate them again (0 when stuck).
    slide: f64,
    slide_exp: f64,
}

/// What the forward pass of the display keeps for the backward pass.
#[derive(Debug, Clone, Default)]
pub struct Tape {
    steps: Vec<Step>,
    /// Per sample: the lag factor a and whether V_cmd was clamped.
    samples: Vec<(f64, bool)>,
    /// Per sample, the velocity the lag factor was computed for. An
    /// optimization passes the same velocity in every evaluation, so the
    /// next forward pass reuses the factor (an `exp`) wherever the velocity
    /// is bit for bit the same.
    velocity: Vec<f64>,
}

/// The display's twin.
#[derive(Debug, Clone)]
pub struct DisplayTwin {
    sub: usize,
    hs: f64,
    phi_e: [[f64; NE]; NE],
    gam_e: [f64; NE],
    ke: f64,
    gain: f64,
    vmax: f64,
    offset: f64,
    mu_s: f64,
    mu_k: f64,
    v_s: f64,
    viscous: f64,
    lag0: f64,
    lag_slope: f64,
    k: f64,
    c: f64,
    /// Augmented tip map: states (δ, v_tip, s), inputs (v_holder, f).
    phi_m: [[f64; 3]; 3],
    gam_m: [[f64; 2]; 3],
    x0: [f64; NE],
    /// The actuation path's latency, samples.
    delay: usize,
}

/// y = M·x, each row's products summed in order. The sizes are fixed, so
/// the loops unroll without bounds checks.
#[inline(always)]
fn matvec<const R: usize, const C: usize>(m: &[[f64; C]; R], x: &[f64; C]) -> [f64; R] {
    std::array::from_fn(|i| m[i].iter().zip(x).map(|(a, b)| a * b).sum())
}

/// The `R` × `C` matrix stored row by row in `flat`.
fn rows<const R: usize, const C: usize>(flat: &[f64]) -> [[f64; C]; R] {
    std::array::from_fn(|i| std::array::from_fn(|j| flat[i * C + j]))
}

impl DisplayTwin {
    /// The twin of `sim.display` on `profile` at `rate` Hz with `substeps`.
    pub fn new(profile: &LabProfile, rate: f64, substeps: usize) -> Result<Self, String> {
        profile.validate()?;
        let sub = substeps.max(1);
        let hs = 1.0 / rate / sub as f64;
        let circuit = Circuit::of(profile);
        let (ae, be) = circuit.relaxed_matrices();
        let (phi_e, gam_e) = zoh(&ae, &be, NE, 1, hs).ok_or("the circuit's matrix exponential is not finite")?;
        let ct = &profile.display.contact;
        let (k, c, m) = (ct.stiffness_n_per_m, ct.damping_ns_per_m, ct.tip_mass_g * 1e-3);
        // As CoulombLti::new: the plant (δ, v_tip) with input v_holder, the
        // friction column, and the slip integrator ṡ = v_tip.
        let a = [0.0, -1.0, k / m, -c / m];
        let b = [1.0, c / m];
        let bf = [0.0, -1.0 / m];
        let (na, ma) = (3, 2);
        let mut aa = vec![0.0; na * na];
        let mut ba = vec![0.0; na * ma];
        for i in 0..2 {
            aa[i * na..i * na + 2].copy_from_slice(&a[i * 2..(i + 1) * 2]);
            ba[i * ma] = b[i];
            ba[i * ma + 1] = bf[i];
        }
        aa[2 * na + 1] = 1.0;
        let (phi_m, gam_m) = zoh(&aa, &ba, na, ma, hs).ok_or("the contact's matrix exponential is not finite")?;
        let amp = &profile.display.amplifier;
        let f = &profile.display.friction;
        let x0 = circuit.dc_state(amp.offset_v).ok_or("the display circuit has no DC steady state")?;
        Ok(Self {
            sub,
            hs,
            phi_e: rows(&phi_e),
            gam_e: rows::<1, NE>(&gam_e)[0],
            ke: profile.electrostatic_coefficient(),
            gain: amp.gain_v,
            vmax: amp.max_v,
            offset: amp.offset_v,
            mu_s: f.mu_static,
            mu_k: f.mu_kinetic,
            v_s: f.stribeck_velocity,
            viscous: f.viscous,
            lag0: 2.0 * std::f64::consts::PI * f.lag_cutoff_hz,
            lag_slope: 2.0 * std::f64::consts::PI * f.lag_slope_hz_per_mm_s * 1e3,
            k,
            c,
            phi_m: rows(&phi_m),
            gam_m: rows(&gam_m),
            x0,
            delay: evflow_nodes::lab::display_model::delay_samples(amp.delay_ms, rate),
        })
    }

    /// The sliding friction at `speed` and load `n`, and the
    /// exp(−(speed/v_s)²) it is made of (for [`Self::slide_grad`]).
    #[inline(always)]
    fn slide(&self, speed: f64, n: f64) -> (f64, f64) {
        let r = speed / self.v_s;
        let e = exact_exp::exp_body(-r * r);
        ((self.mu_k + (self.mu_s - self.mu_k) * e) * n + self.viscous * speed, e)
    }

    /// ∂slide/∂speed and ∂slide/∂n, given `e` = exp(−(speed/v_s)²) as
    /// [`Self::slide`] returned it.
    fn slide_grad(&self, speed: f64, n: f64, e: f64) -> (f64, f64) {
        let r = speed / self.v_s;
        (
            (self.mu_s - self.mu_k) * e * (-2.0 * r / self.v_s) * n + self.viscous,
            self.mu_k + (self.mu_s - self.mu_k) * e,
        )
    }

    /// The display force for actuation `u`, normal load `load` (N) and
    /// holder velocity `velocity` (m/s), sample by sample from the model's
    /// initial state, keeping the tape.
    pub fn forward(&self, u: &[f64], load: &[f64], velocity: &[f64], tape: &mut Tape) -> Vec<f64> {
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            let [f] = unsafe { self.forward_avx2([u], load, velocity, [tape]) };
            return f;
        }
        let [f] = self.forward_body([u], load, velocity, [tape]);
        f
    }

    /// [`Self::forward`] of two actuations along the same path at once,
    /// each with its own tape: their steps alternate, so that one pass's
    /// chain of dependent operations runs while the other's waits. Each
    /// force (and tape) is the one [`Self::forward`] gives, bit for bit.
    /// The actuations must have one length.
    pub fn forward2(&self, u: [&[f64]; 2], load: &[f64], velocity: &[f64], tapes: [&mut Tape; 2]) -> [Vec<f64>; 2] {
        debug_assert_eq!(u[0].len(), u[1].len());
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { self.forward_avx2(u, load, velocity, tapes) };
        }
        self.forward_body(u, load, velocity, tapes)
    }

    /// J(F(u)) for an objective J of the display force F along the path
    /// (`load`, `velocity`), with ∂J/∂u written into `g`: the forward pass,
    /// then `adjoint(F)` = (J, ∂J/∂F), then the backward pass.
    pub fn objective_grad(
        &self,
        u: &[f64],
        (load, velocity): (&[f64], &[f64]),
        tape: &mut Tape,
        g: &mut [f64],
        adjoint: impl FnOnce(Vec<f64>) -> (f64, Vec<f64>),
    ) -> f64 {
        let (j, fbar) = adjoint(self.forward(u, load, velocity, tape));
        g.iter_mut().for_each(|v| *v = 0.0);
        self.backward(tape, &fbar, g);
        j
    }

    /// [`Self::forward_body`] compiled for AVX2 and FMA, so that the
    /// exponentials inline with their multiply-adds as instructions (Rust
    /// fuses nothing else on its own: the same bits as the portable build).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn forward_avx2<const K: usize>(
        &self,
        u: [&[f64]; K],
        load: &[f64],
        velocity: &[f64],
        tapes: [&mut Tape; K],
    ) -> [Vec<f64>; K] {
        self.forward_body(u, load, velocity, tapes)
    }

    /// The forward pass of K actuations of one length along one path,
    /// step by step side by side (each its own state and tape).
    #[inline(always)]
    fn forward_body<const K: usize>(
        &self,
        u: [&[f64]; K],
        load: &[f64],
        velocity: &[f64],
        mut tapes: [&mut Tape; K],
    ) -> [Vec<f64>; K] {
        let len = u[0].len();
        for tape in tapes.iter_mut() {
            tape.steps.clear();
            tape.samples.truncate(len);
            tape.velocity.truncate(len);
        }
        let vr0 = electrical::force_voltage(&self.x0);
        let mut runs = [(); K].map(|_| Run { xe: self.x0, fl: self.ke * vr0 * vr0, xm: [0.0; 2], stuck: true });
        let mut out = [(); K].map(|_| Vec::with_capacity(len));
        for n in 0..len {
            let ld = if load[n].is_finite() { load[n].max(0.0) } else { 0.0 };
            let v = if velocity[n].is_finite() { velocity[n] } else { 0.0 };
            let (mut vcmd, mut a) = ([0.0; K], [0.0; K]);
            for k in 0..K {
                (vcmd[k], a[k]) = self.drive(u[k], n, v, tapes[k]);
            }
            for _ in 0..self.sub {
                for k in 0..K {
                    self.substep(&mut runs[k], vcmd[k], a[k], ld, v, tapes[k]);
                }
            }
            for k in 0..K {
                out[k].push(self.k * runs[k].xm[0] + self.c * (v - runs[k].xm[1]));
            }
        }
        out
    }

    /// Sample n's amplifier voltage V_cmd for actuation `u` (delayed,
    /// non-finite samples 0, clamped to the amplifier's range) and its lag
    /// factor for holder velocity `v` ([`Self::lag_factor`]).
    #[inline(always)]
    fn drive(&self, u: &[f64], n: usize, v: f64, tape: &mut Tape) -> (f64, f64) {
        let un = if n >= self.delay { u[n - self.delay] } else { 0.0 };
        let uu = if un.is_finite() { un } else { 0.0 };
        let raw = self.gain * uu + self.offset;
        let vcmd = raw.clamp(-self.vmax, self.vmax);
        (vcmd, self.lag_factor(tape, n, v, vcmd != raw))
    }

    /// Sample n's lag factor a = exp(−ω_c(v)·h) for holder velocity `v`,
    /// from the tape when it holds one for the same velocity; records it
    /// and whether V_cmd was `clamped`.
    #[inline(always)]
    fn lag_factor(&self, tape: &mut Tape, n: usize, v: f64, clamped: bool) -> f64 {
        match tape.velocity.get(n) {
            Some(&vk) if vk.to_bits() == v.to_bits() => {
                let a = tape.samples[n].0;
                tape.samples[n] = (a, clamped);
                a
            }
            _ => {
                let wc = self.lag0 + self.lag_slope * v.abs();
                let a = exact_exp::exp_body(-wc * self.hs);
                if n < tape.velocity.len() {
                    tape.samples[n] = (a, clamped);
                    tape.velocity[n] = v;
                } else {
                    tape.samples.push((a, clamped));
                    tape.velocity.push(v);
                }
                a
            }
        }
    }

    /// One substep of one pass: circuit, lag, load, contact; recorded.
    #[inline(always)]
    fn substep(&self, r: &mut Run, vcmd: f64, a: f64, ld: f64, v: f64, tape: &mut Tape) {
        let ds_df = self.gam_m[2][1];
        let y = matvec(&self.phi_e, &r.xe);
        for ((x, yi), ge) in r.xe.iter_mut().zip(y).zip(self.gam_e) {
            *x = yi + ge * vcmd;
        }
        let vr = electrical::force_voltage(&r.xe);
        let fe = self.ke * vr * vr;
        r.fl = a * r.fl + (1.0 - a) * fe;
        let npre = ld + r.fl;
        let nf = npre.max(0.0);
        // The sliding friction at this speed and load, when the
        // contact was sliding (the limit) or starts to (the force).
        let mut sliding = if r.stuck { None } else { Some(self.slide(r.xm[1].abs(), nf)) };
        let limit = match sliding {
            Some((fs, _)) => fs,
            None => self.mu_s * nf,
        };
        let xa = [r.xm[0], r.xm[1], 0.0];
        let mut free = matvec(&self.phi_m, &xa);
        let g = matvec(&self.gam_m, &[v, 0.0]);
        for i in 0..3 {
            free[i] += g[i];
        }
        let required = if ds_df != 0.0 { -free[2] / ds_df } else { 0.0 };
        let xm0 = r.xm;
        let branch;
        let mut kept = (0.0, 0.0);
        if required.abs() <= limit.max(0.0) {
            branch = Branch::Stuck;
            r.xm[0] += v * self.hs;
            r.xm[1] = 0.0;
            r.stuck = true;
        } else {
            kept = *sliding.get_or_insert_with(|| self.slide(r.xm[1].abs(), nf));
            let fs = kept.0.max(0.0);
            let force = fs.min(required.abs()) * required.signum();
            branch = if fs < required.abs() { Branch::Slide } else { Branch::Clipped };
            for (i, x) in r.xm.iter_mut().enumerate() {
                *x = free[i] + self.gam_m[i][1] * force;
            }
            r.stuck = false;
        }
        let (slide, slide_exp) = kept;
        tape.steps.push(Step { xm0, vr, npre, branch, req_sign: required.signum(), slide, slide_exp });
    }

    /// Adds to `ubar` the gradient of Σ_n f̄\[n\]·F\[n\] with respect to the
    /// actuation, for the forward pass recorded in `tape`.
    pub fn backward(&self, tape: &Tape, fbar: &[f64], ubar: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { self.backward_avx2([tape], [fbar], [ubar]) };
        }
        self.backward_body([tape], [fbar], [ubar])
    }

    /// [`Self::backward`] of two passes of one length at once (as
    /// [`Self::forward2`] ran them), their steps alternating; each gradient
    /// the one [`Self::backward`] gives, bit for bit.
    pub fn backward2(&self, tapes: [&Tape; 2], fbar: [&[f64]; 2], ubar: [&mut [f64]; 2]) {
        debug_assert_eq!(tapes[0].samples.len(), tapes[1].samples.len());
        #[cfg(target_arch = "x86_64")]
        if evflow_nodes::cpu::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { self.backward_avx2(tapes, fbar, ubar) };
        }
        self.backward_body(tapes, fbar, ubar)
    }

    /// [`Self::backward_body`] compiled for AVX2 (the same operations in
    /// the same order: Rust fuses no multiply-add on its own).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn backward_avx2<const K: usize>(&self, tapes: [&Tape; K], fbar: [&[f64]; K], ubar: [&mut [f64]; K]) {
        self.backward_body(tapes, fbar, ubar)
    }

    /// The backward pass of K recorded passes of one length, step by step
    /// side by side.
    #[inline(always)]
    fn backward_body<const K: usize>(&self, tapes: [&Tape; K], fbar: [&[f64]; K], mut ubar: [&mut [f64]; K]) {
        let mut adj = [Adjoint { bxe: [0.0; NE], bfl: 0.0, bxm: [0.0; 2] }; K];
        for n in (0..tapes[0].samples.len()).rev() {
            let mut bvcmd = [0.0; K];
            for k in 0..K {
                adj[k].bxm[0] += self.k * fbar[k][n];
                adj[k].bxm[1] -= self.c * fbar[k][n];
            }
            for j in (0..self.sub).rev() {
                for k in 0..K {
                    let a = tapes[k].samples[n].0;
                    self.substep_adjoint(&mut adj[k], &tapes[k].steps[n * self.sub + j], a, &mut bvcmd[k]);
                }
            }
            for (k, ub) in ubar.iter_mut().enumerate() {
                if !tapes[k].samples[n].1 && n >= self.delay {
                    ub[n - self.delay] += bvcmd[k] * self.gain;
                }
            }
        }
    }

    /// One substep of [`Self::substep`] transposed: the adjoints `b` of
    /// the state after step `s` become those before it; the adjoint of
    /// V_cmd accumulates in `bvcmd`.
    #[inline(always)]
    fn substep_adjoint(&self, b: &mut Adjoint, s: &Step, a: f64, bvcmd: &mut f64) {
        let ds_df = self.gam_m[2][1];
        // (5) contact step.
        let mut bn = 0.0;
        let mut bxm0 = [0.0; 2];
        match s.branch {
            Branch::Stuck => {
                bxm0[0] = b.bxm[0];
            }
            Branch::Slide | Branch::Clipped => {
                let bforce = b.bxm[0] * self.gam_m[0][1] + b.bxm[1] * self.gam_m[1][1];
                let mut bfree = [b.bxm[0], b.bxm[1], 0.0];
                if s.branch == Branch::Clipped {
                    bfree[2] += -bforce / ds_df;
                } else {
                    let w = s.xm0[1].abs();
                    let nf = s.npre.max(0.0);
                    if s.slide > 0.0 {
                        let (dw, dn) = self.slide_grad(w, nf, s.slide_exp);
                        bn += bforce * s.req_sign * dn;
                        bxm0[1] += bforce * s.req_sign * dw * s.xm0[1].signum();
                    }
                }
                for (jj, bm) in bxm0.iter_mut().enumerate() {
                    for (i, bf) in bfree.iter().enumerate() {
                        *bm += bf * self.phi_m[i][jj];
                    }
                }
            }
        }
        b.bxm = bxm0;
        // (3) N = max(0, F_n + F_l).
        if s.npre > 0.0 {
            b.bfl += bn;
        }
        // (2) lag and square law.
        let bfe = (1.0 - a) * b.bfl;
        b.bfl *= a;
        let mut bxe1 = b.bxe;
        bxe1[electrical::GAP] += bfe * 2.0 * self.ke * s.vr;
        bxe1[electrical::RELAX] -= bfe * 2.0 * self.ke * s.vr;
        // (1) circuit.
        let mut b0 = [0.0; NE];
        for (i, bi) in bxe1.iter().enumerate() {
            for (jj, bj) in b0.iter_mut().enumerate() {
                *bj += bi * self.phi_e[i][jj];
            }
            *bvcmd += bi * self.gam_e[i];
        }
        b.bxe = b0;
    }
}

/// One forward pass's state: circuit, lag, tip, contact.
struct Run {
    xe: [f64; NE],
    fl: f64,
    xm: [f64; 2],
    stuck: bool,
}

/// One backward pass's adjoints of circuit, lag and tip.
#[derive(Clone, Copy)]
struct Adjoint {
    bxe: [f64; NE],
    bfl: f64,
    bxm: [f64; 2],
}

/// The force sensor's twin: resonance (exact map, substeps), direction
/// bias, full-scale clip and quantization, noise off.
#[derive(Debug, Clone)]
pub struct SensorTwin {
    sub: usize,
    phi: [[f64; 2]; 2],
    gam: [f64; 2],
    bias_right: f64,
    bias_left: f64,
    a_bias: f64,
    lsb: f64,
    full_scale: f64,
}

impl SensorTwin {
    /// The twin of `sim.forcesensor` on `profile` at `rate` Hz with `substeps`.
    pub fn new(profile: &LabProfile, rate: f64, substeps: usize) -> Result<Self, String> {
        profile.validate()?;
        let s = &profile.sensor;
        let h = 1.0 / rate;
        let sub = substeps.max(1);
        let w = 2.0 * std::f64::consts::PI * s.resonance_hz;
        let (phi, gam) = zoh(&[0.0, 1.0, -w * w, -2.0 * s.damping_ratio * w], &[0.0, w * w], 2, 1, h / sub as f64)
            .ok_or("the sensor's matrix exponential is not finite")?;
        Ok(Self {
            sub,
            phi: rows(&phi),
            gam: rows::<1, 2>(&gam)[0],
            bias_right: s.bias_right_n,
            bias_left: s.bias_left_n,
            a_bias: (-h / s.bias_time_s).exp(),
            lsb: 2.0 * s.full_scale_n / 2f64.powi(s.bits as i32),
            full_scale: s.full_scale_n,
        })
    }

    /// The acquired force for surface force `f` and velocity `v`; `pass`
    /// marks the samples whose derivative passes (not clipped).
    pub fn forward(&self, f: &[f64], velocity: &[f64], pass: &mut Vec<bool>) -> Vec<f64> {
        pass.clear();
        let (mut x, mut bias, mut dir) = ([0.0; 2], 0.0, 0i8);
        let mut out = Vec::with_capacity(f.len());
        for n in 0..f.len() {
            let fi = if f[n].is_finite() { f[n] } else { 0.0 };
            let v = if velocity[n].is_finite() { velocity[n] } else { 0.0 };
            if v > evflow_nodes::lab::sensor_model::V_DIR {
                dir = 1;
            } else if v < -evflow_nodes::lab::sensor_model::V_DIR {
                dir = -1;
            }
            let target = match dir {
                1 => self.bias_right,
                -1 => self.bias_left,
                _ => 0.0,
            };
            bias = target + (bias - target) * self.a_bias;
            for _ in 0..self.sub {
                let y = matvec(&self.phi, &x);
                x = [y[0] + self.gam[0] * fi, y[1] + self.gam[1] * fi];
            }
            let raw = x[0] + bias;
            let y = raw.clamp(-self.full_scale, self.full_scale - self.lsb);
            pass.push(y == raw);
            out.push((y / self.lsb).round() * self.lsb);
        }
        out
    }

    /// The gradient with respect to the surface force of Σ ȳ\[n\]·y\[n\]
    /// (quantization passed straight through, clipped samples 0).
    pub fn backward(&self, pass: &[bool], ybar: &[f64]) -> Vec<f64> {
        let mut fbar = vec![0.0; ybar.len()];
        let mut bx = [0.0; 2];
        for n in (0..ybar.len()).rev() {
            if pass[n] {
                bx[0] += ybar[n];
            }
            for _ in 0..self.sub {
                // x' = Φx + Γf: x̄ ← Φᵀx̄', f̄ += Γ·x̄'.
                fbar[n] += self.gam[0] * bx[0] + self.gam[1] * bx[1];
                bx = [self.phi[0][0] * bx[0] + self.phi[1][0] * bx[1], self.phi[0][1] * bx[0] + self.phi[1][1] * bx[1]];
            }
        }
        fbar
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use evflow_nodes::lab::display_model::DisplayModel;
    use evflow_nodes::lab::integrator::Method;
    use evflow_nodes::lab::sensor_model::SensorModel;
    use evflow_nodes::lab::tribometer_model::TribometerModel;

    /// Every profile shipped in graphs/lab (new ones included as they
    /// come), and the nominal one with a 2 ms latency.
    pub(super) fn shipped() -> Vec<(String, LabProfile)> {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab");
        let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok().map(|e| e.path())).collect();
        files.sort();
        let mut v: Vec<(String, LabProfile)> = files
            .into_iter()
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .map(|p| (p.file_stem().unwrap().to_string_lossy().into_owned(), LabProfile::load(&p).unwrap()))
            .collect();
        let mut late = LabProfile::default();
        late.display.amplifier.delay_ms = 2.0;
        v.push(("nominal, 2 ms late".into(), late));
        v
    }

    pub(super) fn pass(profile: &LabProfile, mass_g: f64, speed: f64) -> (Vec<f64>, Vec<f64>) {
        let mut t = TribometerModel::new(profile, 1000.0, speed * 1e-2, mass_g * 1e-3, 1, Method::Exact, 4).unwrap();
        let n = t.total_samples().unwrap() as usize;
        let (mut load, mut vel) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for _ in 0..n {
            let (_, v, l) = t.step();
            vel.push(v);
            load.push(l);
        }
        (load, vel)
    }

    /// A profile's heavy, fast stroke and two actuations along it (the
    /// second with runs held at 0.9).
    pub(super) fn two_actuations(profile: &LabProfile) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (load, vel) = pass(profile, 120.0, 8.0);
        let ua = actuation(load.len());
        let ub: Vec<f64> = ua.iter().enumerate().map(|(k, v)| if k % 7 < 3 { -0.6 * v } else { 0.9 }).collect();
        (load, vel, ua, ub)
    }

    /// Each value's bits.
    pub(super) fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    pub(super) fn actuation(n: usize) -> Vec<f64> {
        let mut r = evflow_nodes::rng::Rng::new(4);
        (0..n).map(|k| if k % 2 == 0 { 0.6 } else { -0.6 } * (1.0 + 0.4 * (2.0 * r.uniform() - 1.0))).collect()
    }

    #[test]
    fn the_twins_are_the_lab_models_with_their_noise_off() {
        for (name, profile) in shipped() {
            let (load, vel) = pass(&profile, 85.0, 5.0);
            let u = actuation(load.len());
            let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
            let mut tape = Tape::default();
            let f = twin.forward(&u, &load, &vel, &mut tape);
            let mut model = DisplayModel::new(&profile, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
            let sensor = SensorTwin::new(&profile, 1000.0, 4).unwrap();
            let mut sm = SensorModel::new(&profile, 1000.0, Method::Exact, 4, 0.0, 1).unwrap();
            let mut passed = Vec::new();
            let y = sensor.forward(&f, &vel, &mut passed);
            for n in 0..u.len() {
                let want = model.step(u[n], load[n], vel[n]);
                assert!(
                    (f[n] - want).abs() <= 1e-12 * want.abs().max(1e-3),
                    "{name} display n {n}: {} vs {want}",
                    f[n]
                );
                let ys = sm.step(want, vel[n]);
                assert!((y[n] - ys).abs() <= sensor.lsb * 1.001, "{name} sensor n {n}: {} vs {ys}", y[n]);
            }
        }
    }

    #[test]
    fn the_gradient_matches_central_differences() {
        for (name, profile) in shipped() {
            let (load, vel) = pass(&profile, 60.0, 3.0);
            let n = 900; // dwell, start and the first part of the constant speed
            let (load, vel) = (&load[..n], &vel[..n]);
            let u = actuation(n);
            let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
            let mut r = evflow_nodes::rng::Rng::new(8);
            let fbar: Vec<f64> = (0..n).map(|_| r.gaussian()).collect();
            let mut tape = Tape::default();
            twin.forward(&u, load, vel, &mut tape);
            let mut g = vec![0.0; n];
            twin.backward(&tape, &fbar, &mut g);
            let obj = |u: &[f64]| {
                let mut t = Tape::default();
                twin.forward(u, load, vel, &mut t).iter().zip(&fbar).map(|(a, b)| a * b).sum::<f64>()
            };
            let h = 1e-6;
            for k in [700, 750, 800, 850, 890] {
                let (mut a, mut b) = (u.clone(), u.clone());
                a[k] += h;
                b[k] -= h;
                let fd = (obj(&a) - obj(&b)) / (2.0 * h);
                assert!((fd - g[k]).abs() < 1e-4 * (fd.abs() + 1e-3), "{name} u[{k}]: {} vs {fd}", g[k]);
            }
        }
    }

    #[test]
    fn a_reused_tape_gives_the_fresh_tapes_values_bit_for_bit() {
        // The lag factors kept from the last pass (same velocity) and the
        // sliding friction kept for the backward pass are the values a
        // fresh tape computes: force and gradient identical to the bit,
        // also after the velocity changes under a kept tape.
        let profile = LabProfile::default();
        let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
        let (load, vel) = pass(&profile, 85.0, 5.0);
        let n = 1500;
        let (load, mut vel) = (&load[..n], vel[..n].to_vec());
        let u = actuation(n);
        let fbar: Vec<f64> = (0..n).map(|k| ((k * 7 % 13) as f64 - 6.0) * 0.1).collect();
        let run = |tape: &mut Tape, vel: &[f64]| {
            let f = twin.forward(&u, load, vel, tape);
            let mut g = vec![0.0; n];
            twin.backward(tape, &fbar, &mut g);
            (f, g)
        };
        let mut kept = Tape::default();
        for round in 0..3 {
            if round == 2 {
                vel.iter_mut().skip(400).step_by(3).for_each(|v| *v *= 1.5);
            }
            let (f, g) = run(&mut kept, &vel);
            let (f0, g0) = run(&mut Tape::default(), &vel);
            assert_eq!((bits(&f), bits(&g)), (bits(&f0), bits(&g0)), "round {round}");
        }
        assert!(kept.steps.iter().any(|s| s.branch == Branch::Slide), "no sliding step exercised");
    }

    #[test]
    fn the_avx2_build_gives_the_portable_builds_bits() {
        // forward and backward pick their AVX2 + FMA build on CPUs with
        // both; the bodies alone are the portable build.
        for (name, profile) in shipped() {
            let (load, vel) = pass(&profile, 120.0, 8.0);
            let n = load.len();
            let u = actuation(n);
            let fbar: Vec<f64> = (0..n).map(|k| ((k * 5 % 11) as f64 - 5.0) * 0.2).collect();
            let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
            let (mut t1, mut t2) = (Tape::default(), Tape::default());
            let f1 = twin.forward(&u, &load, &vel, &mut t1);
            let [f2] = twin.forward_body([&u], &load, &vel, [&mut t2]);
            let (mut g1, mut g2) = (vec![0.0; n], vec![0.0; n]);
            twin.backward(&t1, &fbar, &mut g1);
            twin.backward_body([&t2], [&fbar], [&mut g2]);
            assert_eq!(bits(&f1), bits(&f2), "{name}: forward");
            assert_eq!(bits(&g1), bits(&g2), "{name}: backward");
            assert!(t1.steps.iter().any(|s| s.branch == Branch::Slide), "{name}: no sliding step");
        }
    }

    #[test]
    fn two_passes_side_by_side_are_each_the_single_pass_bit_for_bit() {
        // Both builds (the bodies alone are the portable one), on every
        // shipped profile: forces, tapes and gradients as one pass alone.
        for (name, profile) in shipped() {
            let (load, vel, ua, ub) = two_actuations(&profile);
            let n = load.len();
            let fa: Vec<f64> = (0..n).map(|k| ((k * 5 % 11) as f64 - 5.0) * 0.2).collect();
            let fb: Vec<f64> = (0..n).map(|k| ((k * 3 % 7) as f64 - 3.0) * 0.1).collect();
            let twin = DisplayTwin::new(&profile, 1000.0, 4).unwrap();
            let (mut ta, mut tb) = (Tape::default(), Tape::default());
            let want = [twin.forward(&ua, &load, &vel, &mut ta), twin.forward(&ub, &load, &vel, &mut tb)];
            let (mut ga, mut gb) = (vec![0.0; n], vec![0.0; n]);
            twin.backward(&ta, &fa, &mut ga);
            twin.backward(&tb, &fb, &mut gb);
            for portable in [false, true] {
                // A reused tape (the velocity's factors kept) and a fresh one.
                let (mut t1, mut t2) = (ta.clone(), Tape::default());
                let got = if portable {
                    twin.forward_body([&ua, &ub], &load, &vel, [&mut t1, &mut t2])
                } else {
                    twin.forward2([&ua, &ub], &load, &vel, [&mut t1, &mut t2])
                };
                let (mut g1, mut g2) = (vec![0.0; n], vec![0.0; n]);
                if portable {
                    twin.backward_body([&t1, &t2], [&fa, &fb], [&mut g1, &mut g2]);
                } else {
                    twin.backward2([&t1, &t2], [&fa, &fb], [&mut g1, &mut g2]);
                }
                for k in 0..2 {
                    assert_eq!(bits(&got[k]), bits(&want[k]), "{name}: force {k}");
                }
                assert_eq!((bits(&g1), bits(&g2)), (bits(&ga), bits(&gb)), "{name}: gradients");
                assert_eq!(t2.steps.len(), tb.steps.len());
            }
            assert!(ta.steps.iter().any(|s| s.branch == Branch::Slide), "{name}: no sliding step");
        }
    }

    #[test]
    fn the_sensor_adjoint_satisfies_the_inner_product_identity() {
        let profile = LabProfile::default();
        let s = SensorTwin::new(&profile, 1000.0, 4).unwrap();
        let mut r = evflow_nodes::rng::Rng::new(2);
        let n = 500;
        let f: Vec<f64> = (0..n).map(|_| 0.01 * r.gaussian()).collect();
        let ybar: Vec<f64> = (0..n).map(|_| r.gaussian()).collect();
        let vel = vec![0.05; n];
        let mut pass = Vec::new();
        // Linear part only: the response to f minus the response to 0 (bias).
        let y1 = s.forward(&f, &vel, &mut pass);
        let y0 = s.forward(&vec![0.0; n], &vel, &mut pass);
        let lhs: f64 = y1.iter().zip(&y0).zip(&ybar).map(|((a, b), c)| (a - b) * c).sum();
        let fbar = s.backward(&pass, &ybar);
        let rhs: f64 = f.iter().zip(&fbar).map(|(a, b)| a * b).sum();
        // Quantization (0.37 mN steps) bounds the agreement.
        assert!((lhs - rhs).abs() < 0.02 * lhs.abs().max(rhs.abs()), "{lhs} vs {rhs}");
    }
}
