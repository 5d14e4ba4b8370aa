//! The virtual electrovibration display as a plain model: actuation, load
//! and sliding velocity in, lateral force out, one sample at a time. The
//! `sim.display` node (display.rs) wraps it; docs/simulated-lab.md derives it.
//!
//! The actuation first passes the latency line (`delay_ms`, whole samples).
//! Chain per substep (every method; `exact` uses the exact maps, `rk4` and
//! `euler` their one-step maps of the same linear parts, integrator.rs):
//! 1. amplifier + circuit + charge relaxation (electrical.rs) advance by
//!    their map with the commanded voltage V_cmd = clamp(g·u + V_off + noise,
//!    ±V_max) held;
//! 2. electrostatic force F_e = k_e·v_r², v_r = v_g − q the gap voltage after
//!    the relaxation high-pass (square law, Meyer et al. 2013);
//! 3. first-order electroadhesion lag with speed-dependent cutoff
//!    ω_c = 2π(f_0 + s·|v|) (Balasubramanian, Pool & Vardar 2025), F_e held
//!    (F_l ← a F_l + (1−a) F_e, a = e^{−ω_c h} exact, its RK4/Euler
//!    polynomial otherwise);
//! 4. normal force N = max(0, F_n + F_l); friction limit μ_s·N, sliding
//!    friction (μ_k + (μ_s−μ_k)e^{−(v/v_s)²})·N + c_v|v| (Stribeck), μ scaled
//!    by coloured noise and drift;
//! 5. the tip (mass m on lateral stiffness k and damping c to the holder,
//!    which moves at the input velocity) rubs on the glass: the linear map
//!    plus the implicit set-valued Coulomb law (integrator.rs), the same law
//!    for every method.
//!
//! The splitting (each step's N from the end of its electrical step) makes
//! every method first order overall; all converge to the event-driven
//! reference of `reference.rs` (convergence_tests.rs).
//!
//! The output is the force the contact transmits to the holder,
//! F = k·δ + c·(v_holder − v_tip), δ = x_holder − x_tip.

use super::electrical::{self, Circuit};
use super::integrator::{decay, CoulombLti, Lti, Method, Plant};
use super::noise::Ou;
use super::profile::LabProfile;
use crate::rng::Rng;

/// Force beyond which the model counts as diverged (only explicit methods reach it), N.
pub const GUARD_N: f64 = 1e3;
/// Gap voltage beyond which the model counts as diverged, V.
const GUARD_V: f64 = 1e5;

/// The actuation path's latency `delay_ms` in whole samples at `rate` Hz.
pub fn delay_samples(delay_ms: f64, rate: f64) -> usize {
    let d = (delay_ms * 1e-3 * rate).round();
    if d.is_finite() && d > 0.0 {
        d as usize
    } else {
        0
    }
}

/// The friction law's constants.
#[derive(Debug, Clone, Copy)]
struct Fric {
    mu_s: f64,
    mu_k: f64,
    v_s: f64,
    viscous: f64,
}

impl Fric {
    /// Sliding friction at speed `speed` under normal force `n`, μ scaled by `scale`:
    /// (μ_k + (μ_s − μ_k)·e^{−(v/v_s)²})·scale·N + c_v·|v| (Stribeck).
    fn slide(&self, speed: f64, n: f64, scale: f64) -> f64 {
        let r = speed / self.v_s;
        (self.mu_k + (self.mu_s - self.mu_k) * crate::exact_exp::exp(-r * r)) * scale * n + self.viscous * speed
    }
}

/// The display model and its state.
#[derive(Debug, Clone)]
pub struct DisplayModel {
    method: Method,
    substeps: usize,
    hs: f64,
    circuit: Circuit,
    elec: Lti,
    mech: CoulombLti,
    ke: f64,
    gain: f64,
    vmax: f64,
    offset: f64,
    noise_v: f64,
    fric: Fric,
    lag0: f64,
    lag_slope: f64,
    k: f64,
    c: f64,
    m: f64,
    rng: Rng,
    mu_noise: Ou,
    mu_drift: Ou,
    x0: [f64; electrical::NR],
    // State: circuit and relaxation, lag, contact (δ, v_tip).
    xe: [f64; electrical::NR],
    fl: f64,
    xm: [f64; 2],
    stuck: bool,
    /// Times the state was reset after diverging.
    pub diverged: u64,
    /// Input samples that were NaN or infinite (read as 0).
    pub bad_inputs: u64,
    last_n: f64,
    /// The actuation's latency line: the last `delay` samples of u, oldest at `head`.
    line: Vec<f64>,
    head: usize,
}

impl DisplayModel {
    /// A display of `profile` sampled at `rate` Hz, integrated by `method`
    /// with `substeps` per sample; `noise` scales every random term (0 =
    /// none); `seed` seeds them.
    pub fn new(
        profile: &LabProfile,
        rate: f64,
        method: Method,
        substeps: usize,
        noise: f64,
        seed: u64,
    ) -> Result<Self, String> {
        profile.validate()?;
        let fr = profile.display.electrical.relaxation_hz;
        if !(rate.is_finite() && rate > 0.0) {
            return Err(format!("the sample rate {rate} Hz is not a positive number"));
        }
        if fr >= 0.5 * rate {
            return Err(format!(
                "`display.electrical.relaxation_hz` = {fr} Hz must be below half the sample rate ({} Hz)",
                0.5 * rate
            ));
        }
        let h = 1.0 / rate;
        let hs = h / substeps.max(1) as f64;
        let circuit = Circuit::of(profile);
        let (ae, be) = circuit.relaxed_matrices();
        let elec = Lti::new(ae, be, electrical::NR, 1, hs, method)?;
        let ct = &profile.display.contact;
        let (k, c, m) = (ct.stiffness_n_per_m, ct.damping_ns_per_m, ct.tip_mass_g * 1e-3);
        // States (δ, v_tip); input v_holder; friction f on the tip.
        let plant = Plant { a: vec![0.0, -1.0, k / m, -c / m], b: vec![1.0, c / m], n: 2, m: 1 };
        let mech = CoulombLti::new(plant, vec![0.0, -1.0 / m], 1, hs, method)?;
        let a = &profile.display.amplifier;
        let f = &profile.display.friction;
        // DC steady state of the circuit under the amplifier offset.
        let x0 = circuit.dc_state(a.offset_v).ok_or("the display circuit has no DC steady state")?;
        let noise_scale = noise.max(0.0);
        let fb = f.noise_bandwidth_hz;
        let mut model = Self {
            method,
            substeps: substeps.max(1),
            hs,
            circuit,
            elec,
            mech,
            ke: profile.electrostatic_coefficient(),
            gain: a.gain_v,
            vmax: a.max_v,
            offset: a.offset_v,
            noise_v: a.noise_v * noise_scale,
            fric: Fric { mu_s: f.mu_static, mu_k: f.mu_kinetic, v_s: f.stribeck_velocity, viscous: f.viscous },
            lag0: 2.0 * std::f64::consts::PI * f.lag_cutoff_hz,
            lag_slope: 2.0 * std::f64::consts::PI * f.lag_slope_hz_per_mm_s * 1e3,
            k,
            c,
            m,
            rng: Rng::substream(seed, 1),
            mu_noise: Ou::new(
                f.noise * noise_scale,
                1.0 / (2.0 * std::f64::consts::PI * fb),
                h,
                Rng::substream(seed, 2),
            ),
            mu_drift: Ou::new(f.drift * noise_scale, f.drift_time_s, h, Rng::substream(seed, 3)),
            x0,
            xe: x0,
            fl: 0.0,
            xm: [0.0; 2],
            stuck: true,
            diverged: 0,
            bad_inputs: 0,
            last_n: 0.0,
            line: vec![0.0; delay_samples(a.delay_ms, rate)],
            head: 0,
        };
        model.reset();
        Ok(model)
    }

    /// Back to t = 0: circuit at its DC state, contact at rest, noise replayed.
    pub fn reset(&mut self) {
        self.rng.reset();
        self.mu_noise.reset();
        self.mu_drift.reset();
        self.reset_dynamics();
        self.diverged = 0;
        self.bad_inputs = 0;
    }

    fn reset_dynamics(&mut self) {
        self.xe = self.x0;
        let vr = electrical::force_voltage(&self.x0);
        self.fl = self.ke * vr * vr;
        self.xm = [0.0; 2];
        self.stuck = true;
        self.last_n = 0.0;
        self.line.iter_mut().for_each(|x| *x = 0.0);
        self.head = 0;
    }

    /// u as it reaches the amplifier: `u` delayed by the latency line.
    fn delayed(&mut self, u: f64) -> f64 {
        match self.line.len() {
            0 => u,
            d => {
                let out = std::mem::replace(&mut self.line[self.head], u);
                self.head = (self.head + 1) % d;
                out
            }
        }
    }

    fn clean(&mut self, x: f64) -> f64 {
        if x.is_finite() {
            x
        } else {
            self.bad_inputs += 1;
            0.0
        }
    }

    /// One sample: actuation `u` (1.0 = 50 V, i.e. ±1 gives 100 Vpp), normal
    /// load `load` N and holder velocity `v` m/s, held over the sample;
    /// returns the lateral force at the end of the sample, N.
    pub fn step(&mut self, u: f64, load: f64, v: f64) -> f64 {
        let u = self.clean(u);
        let u = self.delayed(u);
        let load = self.clean(load).max(0.0);
        let v = self.clean(v);
        let noise = if self.noise_v > 0.0 { self.noise_v * self.rng.gaussian() } else { 0.0 };
        let vcmd = (self.gain * u + self.offset + noise).clamp(-self.vmax, self.vmax);
        let mu_scale = (1.0 + self.mu_noise.step() + self.mu_drift.step()).max(0.0);
        let wc = self.lag0 + self.lag_slope * v.abs();
        let a = decay(self.method, -wc * self.hs);
        let fric = self.fric;
        for _ in 0..self.substeps {
            self.elec.step(&mut self.xe, &[vcmd]);
            let vr = electrical::force_voltage(&self.xe);
            let fe = self.ke * vr * vr;
            self.fl = a * self.fl + (1.0 - a) * fe;
            let n = (load + self.fl).max(0.0);
            self.last_n = n;
            let limit = if self.stuck { fric.mu_s * mu_scale * n } else { fric.slide(self.xm[1].abs(), n, mu_scale) };
            let r = self.mech.step(&mut self.xm, &[v], limit, |s| fric.slide(s, n, mu_scale));
            self.stuck = r.stuck;
        }
        let f = self.k * self.xm[0] + self.c * (v - self.xm[1]);
        let ok = f.is_finite()
            && f.abs() <= GUARD_N
            && self.xe.iter().all(|x| x.is_finite() && x.abs() <= GUARD_V)
            && self.fl.is_finite();
        if ok {
            f
        } else {
            self.diverged += 1;
            self.reset_dynamics();
            if f.is_finite() {
                f.clamp(-GUARD_N, GUARD_N)
            } else {
                0.0
            }
        }
    }

    /// The gap voltage now, V.
    pub fn gap_voltage(&self) -> f64 {
        self.xe[electrical::GAP]
    }

    /// The normal force (load plus lagged electrostatic force) of the last substep, N.
    pub fn normal_force(&self) -> f64 {
        self.last_n
    }

    /// Energy stored in the circuit's capacitors, J.
    pub fn electrical_energy(&self) -> f64 {
        self.circuit.energy(&self.xe)
    }

    /// Mechanical energy of the contact, ½kδ² + ½mv², J.
    pub fn mechanical_energy(&self) -> f64 {
        0.5 * self.k * self.xm[0] * self.xm[0] + 0.5 * self.m * self.xm[1] * self.xm[1]
    }

    /// Sets the contact state (δ m, tip velocity m/s); for tests.
    pub fn set_contact(&mut self, delta: f64, v_tip: f64) {
        self.xm = [delta, v_tip];
        self.stuck = v_tip == 0.0;
    }

    /// Sets the circuit state (the relaxation state keeps its value); for tests.
    pub fn set_circuit(&mut self, x: [f64; electrical::N]) {
        self.xe[..electrical::N].copy_from_slice(&x);
    }

    /// The circuit of this display.
    pub fn circuit(&self) -> &Circuit {
        &self.circuit
    }
}
