//! An independent reference solution of the display's equations, for tests
//! only: event-driven, with no code shared with the lab's integrators (no
//! matrix exponential, no `explicit_step`, no `CoulombLti`).
//!
//! The state (circuit, lag, relaxation, δ, v_tip) is advanced by classical
//! RK4 written out here, with a step far below every time constant
//! (default 10 ns). Coulomb friction is not regularized: the contact is
//! either *stuck* (v_tip = 0, δ̇ = v_holder, held while the force the tip
//! needs, k δ + c v_holder, is within μ_s N) or *slipping* in a fixed
//! direction (friction = Stribeck force against it). A zero crossing of
//! v_tip and a breakaway are located by bisection on the step length to
//! below 1 ps, and the mode switches exactly there. Inputs are held over
//! each sample, as the model defines them.

use super::electrical::{self, Circuit};
use super::profile::LabProfile;

const NE: usize = electrical::N;
/// States: circuit (NE), lag F_l, relaxation q, δ, v_tip.
const NS: usize = NE + 4;
const FL: usize = NE;
const RQ: usize = NE + 1;
const DL: usize = NE + 2;
const VT: usize = NE + 3;

/// The reference display (noise off).
pub struct RefDisplay {
    ae: Vec<f64>,
    be: Vec<f64>,
    ke: f64,
    gain: f64,
    vmax: f64,
    offset: f64,
    wr: f64,
    mu_s: f64,
    mu_k: f64,
    v_s: f64,
    viscous: f64,
    lag0: f64,
    lag_slope: f64,
    k: f64,
    c: f64,
    m: f64,
    h: f64,
    s: [f64; NS],
    /// 0: stuck; ±1: slipping in that direction.
    dir: f64,
}

/// Per-sample inputs held over one sample.
#[derive(Clone, Copy)]
struct Held {
    vcmd: f64,
    load: f64,
    v: f64,
    wc: f64,
}

impl RefDisplay {
    /// The display of `profile`, stepped internally by `h` seconds.
    pub fn new(profile: &LabProfile, h: f64) -> Self {
        let circuit = Circuit::of(profile);
        let (ae, be) = circuit.matrices();
        let a = &profile.display.amplifier;
        let f = &profile.display.friction;
        let ct = &profile.display.contact;
        let tau = 2.0 * std::f64::consts::PI;
        let mut r = Self {
            ae,
            be,
            ke: profile.electrostatic_coefficient(),
            gain: a.gain_v,
            vmax: a.max_v,
            offset: a.offset_v,
            wr: tau * profile.display.electrical.relaxation_hz,
            mu_s: f.mu_static,
            mu_k: f.mu_kinetic,
            v_s: f.stribeck_velocity,
            viscous: f.viscous,
            lag0: tau * f.lag_cutoff_hz,
            lag_slope: tau * f.lag_slope_hz_per_mm_s * 1e3,
            k: ct.stiffness_n_per_m,
            c: ct.damping_ns_per_m,
            m: ct.tip_mass_g * 1e-3,
            h,
            s: [0.0; NS],
            dir: 0.0,
        };
        // Circuit at its DC state under the offset: integrate it alone with
        // the input held until it no longer moves (no linear solve shared
        // with the model): relax over many of its slowest time constants.
        let held = Held { vcmd: r.offset, load: 0.0, v: 0.0, wc: r.lag0 };
        let mut x = [0.0; NS];
        let dt = 2e-7;
        for _ in 0..200_000 {
            r.rk4(&mut x, dt, held);
        }
        // Only the circuit, and the relaxation state at its own rest.
        r.s[..NE].copy_from_slice(&x[..NE]);
        r.s[RQ] = if r.wr > 0.0 { x[electrical::GAP] } else { 0.0 };
        let vr = r.s[electrical::GAP] - r.s[RQ];
        r.s[FL] = r.ke * vr * vr;
        r
    }

    fn slide(&self, speed: f64, n: f64) -> f64 {
        let q = speed / self.v_s;
        (self.mu_k + (self.mu_s - self.mu_k) * crate::exact_exp::exp(-q * q)) * n + self.viscous * speed
    }

    fn normal(&self, s: &[f64; NS], load: f64) -> f64 {
        (load + s[FL]).max(0.0)
    }

    fn deriv(&self, s: &[f64; NS], i: Held) -> [f64; NS] {
        let mut d = [0.0; NS];
        for (r, dr) in d.iter_mut().take(NE).enumerate() {
            *dr = (0..NE).map(|j| self.ae[r * NE + j] * s[j]).sum::<f64>() + self.be[r] * i.vcmd;
        }
        let vg = s[electrical::GAP];
        d[RQ] = self.wr * (vg - s[RQ]);
        let vr = vg - s[RQ];
        d[FL] = i.wc * (self.ke * vr * vr - s[FL]);
        if self.dir == 0.0 {
            d[DL] = i.v;
            d[VT] = 0.0;
        } else {
            let n = self.normal(s, i.load);
            let f = self.dir * self.slide(s[VT].abs(), n);
            d[DL] = i.v - s[VT];
            d[VT] = (self.k * s[DL] + self.c * (i.v - s[VT]) - f) / self.m;
        }
        d
    }

    fn rk4(&self, s: &mut [f64; NS], h: f64, i: Held) {
        let add = |s: &[f64; NS], k: &[f64; NS], a: f64| {
            let mut t = *s;
            for j in 0..NS {
                t[j] += a * k[j];
            }
            t
        };
        let k1 = self.deriv(s, i);
        let k2 = self.deriv(&add(s, &k1, 0.5 * h), i);
        let k3 = self.deriv(&add(s, &k2, 0.5 * h), i);
        let k4 = self.deriv(&add(s, &k3, h), i);
        for j in 0..NS {
            s[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        if self.dir == 0.0 {
            s[VT] = 0.0;
        }
    }

    /// > 0 when the mode must switch at the end of a step from `s`.
    fn event(&self, s: &[f64; NS], i: Held) -> f64 {
        if self.dir == 0.0 {
            (self.k * s[DL] + self.c * i.v).abs() - self.mu_s * self.normal(s, i.load)
        } else {
            -self.dir * s[VT]
        }
    }

    /// Decides the mode at a switching point (v_tip = 0 now).
    fn switch(&mut self, i: Held) {
        self.s[VT] = 0.0;
        let need = self.k * self.s[DL] + self.c * i.v;
        self.dir = if need.abs() <= self.mu_s * self.normal(&self.s, i.load) { 0.0 } else { need.signum() };
    }

    fn advance(&mut self, mut t: f64, i: Held) {
        let mut guard = 0;
        while t > 0.0 {
            let h = self.h.min(t);
            let mut next = self.s;
            self.rk4(&mut next, h, i);
            if self.event(&next, i) <= 0.0 {
                self.s = next;
                t -= h;
                continue;
            }
            // Bisect the step length for the switching time.
            let (mut lo, mut hi) = (0.0, h);
            while hi - lo > 1e-12 {
                let mid = 0.5 * (lo + hi);
                let mut trial = self.s;
                self.rk4(&mut trial, mid, i);
                if self.event(&trial, i) > 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let mut at = self.s;
            self.rk4(&mut at, hi, i);
            self.s = at;
            t -= hi;
            self.switch(i);
            guard += 1;
            assert!(guard < 1_000_000, "the reference chatters");
        }
    }

    /// One sample of `dt` s with `u`, `load` N and holder velocity `v` held; the force at its end.
    pub fn step(&mut self, u: f64, load: f64, v: f64, dt: f64) -> f64 {
        let vcmd = (self.gain * u + self.offset).clamp(-self.vmax, self.vmax);
        let i = Held { vcmd, load, v, wc: self.lag0 + self.lag_slope * v.abs() };
        if self.dir == 0.0 && self.event(&self.s, i) > 0.0 {
            self.switch(i);
        }
        self.advance(dt, i);
        self.k * self.s[DL] + self.c * (v - self.s[VT])
    }
}
