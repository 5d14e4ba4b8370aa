//! The display's electrical circuit: amplifier → insulating coating → air
//! gap → pen tip (or stratum corneum) → return path, the lumped series
//! impedance model of Shultz, Peshkin & Colgate (IEEE Haptics Symposium
//! 2018), with a leaky coating (the Johnsen–Rahbek path of Shultz et al.,
//! WHC 2015) and a leaky gap (charge leakage, AliAbbasi et al.).
//!
//! States: amplifier output V_a, coating voltage v_i, gap voltage v_g, tip
//! voltage v_t. With the loop current i = (V_a − v_i − v_g − v_t)/R_b:
//!
//! ```text
//! V̇_a = ω_a (V_cmd − V_a)
//! C_i v̇_i = i − v_i/R_i      C_g v̇_g = i − v_g/R_g      C_t v̇_t = i − v_t/R_t
//! ```
//!
//! The electrostatic force acts across the gap: F_e = k_e v_r², k_e = ε0A/(2d²),
//! where v_r is the gap voltage after an optional first-order charge
//! relaxation (a high-pass of corner f_r = `relaxation_hz`; 0 = none):
//!
//! ```text
//! q̇ = ω_r (v_g − q),   v_r = v_g − q,   ω_r = 2π f_r
//! ```
//!
//! q is the part of the gap voltage that charge moving in the contact (the
//! stratum corneum, a moist finger, a lossy coating) has already screened;
//! V_r(jω) = jω/(jω + ω_r) · V_g(jω). The display models carry q as a fifth
//! state of the circuit ([`Circuit::relaxed_matrices`]); with f_r = 0 it
//! stays 0.

use super::profile::LabProfile;

/// Index of the gap voltage in the state.
pub const GAP: usize = 2;
/// Number of states of the circuit.
pub const N: usize = 4;
/// Index of the relaxation state q in the relaxed circuit's state.
pub const RELAX: usize = 4;
/// Number of states of the circuit with its relaxation state.
pub const NR: usize = 5;

/// The voltage that reaches the square law, v_r = v_g − q, of a relaxed-circuit state.
#[inline]
pub fn force_voltage(x: &[f64; NR]) -> f64 {
    x[GAP] - x[RELAX]
}

/// The circuit's element values in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circuit {
    /// Amplifier bandwidth, rad/s.
    pub omega_a: f64,
    /// Coating capacitance and leakage (F, Ω).
    pub ci: f64,
    /// Coating leakage, Ω.
    pub ri: f64,
    /// Gap capacitance, F.
    pub cg: f64,
    /// Gap leakage, Ω.
    pub rg: f64,
    /// Tip capacitance, F.
    pub ct: f64,
    /// Tip resistance, Ω.
    pub rt: f64,
    /// Return resistance, Ω.
    pub rb: f64,
    /// Charge-relaxation corner, rad/s (0 = none).
    pub omega_r: f64,
}

impl Circuit {
    /// The circuit of a profile.
    pub fn of(p: &LabProfile) -> Self {
        let e = &p.display.electrical;
        Self {
            omega_a: 2.0 * std::f64::consts::PI * p.display.amplifier.bandwidth_hz,
            ci: p.insulator_capacitance(),
            ri: e.insulator_leak_mohm * 1e6,
            cg: p.gap_capacitance(),
            rg: e.gap_leak_mohm * 1e6,
            ct: e.tip_capacitance_nf * 1e-9,
            rt: e.tip_resistance_kohm * 1e3,
            rb: e.return_kohm * 1e3,
            omega_r: 2.0 * std::f64::consts::PI * e.relaxation_hz,
        }
    }

    /// (A, B) of ẋ = A x + B V_cmd, row-major, 4 × 4 and 4 × 1.
    pub fn matrices(&self) -> (Vec<f64>, Vec<f64>) {
        let g = 1.0 / self.rb;
        let mut a = vec![0.0; N * N];
        a[0] = -self.omega_a;
        // Rows 1..3: C_k v̇_k = (V_a − v_i − v_g − v_t)/R_b − v_k/R_k.
        for (row, (c, r)) in [(self.ci, self.ri), (self.cg, self.rg), (self.ct, self.rt)].into_iter().enumerate() {
            let k = row + 1;
            a[k * N] = g / c;
            for j in 1..N {
                a[k * N + j] = -g / c;
            }
            a[k * N + k] -= 1.0 / (r * c);
        }
        let b = vec![self.omega_a, 0.0, 0.0, 0.0];
        (a, b)
    }

    /// (A, B) of the circuit with its relaxation state q (index [`RELAX`]),
    /// 5 × 5 and 5 × 1: the rows of [`Circuit::matrices`] and q̇ = ω_r (v_g − q).
    pub fn relaxed_matrices(&self) -> (Vec<f64>, Vec<f64>) {
        let (a4, b4) = self.matrices();
        let mut a = vec![0.0; NR * NR];
        for i in 0..N {
            a[i * NR..i * NR + N].copy_from_slice(&a4[i * N..(i + 1) * N]);
        }
        a[RELAX * NR + GAP] = self.omega_r;
        a[RELAX * NR + RELAX] = -self.omega_r;
        let mut b = vec![0.0; NR];
        b[..N].copy_from_slice(&b4);
        (a, b)
    }

    /// The relaxed circuit's steady state under a constant command `v` V:
    /// x = −A⁻¹ B v for the circuit, q = v_g when relaxing (else 0).
    /// `None` when the circuit has no DC steady state.
    pub fn dc_state(&self, v: f64) -> Option<[f64; NR]> {
        let (a, b) = self.matrices();
        let amat = super::expm::Mat { n: N, a };
        let mut rhs = super::expm::Mat::zeros(N);
        for (i, bi) in b.iter().enumerate() {
            rhs.set(i, 0, -bi * v);
        }
        let ss = amat.solve(&rhs)?;
        let mut x = [0.0; NR];
        for (i, xi) in x.iter_mut().take(N).enumerate() {
            *xi = ss.get(i, 0);
        }
        x[RELAX] = if self.omega_r > 0.0 { x[GAP] } else { 0.0 };
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// The square-law voltage v_r per volt commanded at `f` Hz, as (re, im):
    /// [`Circuit::gap_response`] times the relaxation's jω/(jω + ω_r).
    pub fn relaxed_response(&self, f: f64) -> (f64, f64) {
        let g = self.gap_response(f);
        let w = 2.0 * std::f64::consts::PI * f;
        let hp = cdiv((0.0, w), (self.omega_r, w));
        (g.0 * hp.0 - g.1 * hp.1, g.0 * hp.1 + g.1 * hp.0)
    }

    /// Gap voltage per volt commanded at frequency `f` Hz, as (re, im):
    /// H = Z_g / (R_b + Z_i + Z_g + Z_t) · 1/(1 + jω/ω_a), Z_k = R_k ∥ C_k.
    pub fn gap_response(&self, f: f64) -> (f64, f64) {
        let w = 2.0 * std::f64::consts::PI * f;
        let par = |r: f64, c: f64| cdiv((r, 0.0), (1.0, w * r * c));
        let zi = par(self.ri, self.ci);
        let zg = par(self.rg, self.cg);
        let zt = par(self.rt, self.ct);
        let total = (self.rb + zi.0 + zg.0 + zt.0, zi.1 + zg.1 + zt.1);
        let h = cdiv(zg, total);
        let amp = cdiv((1.0, 0.0), (1.0, w / self.omega_a));
        (h.0 * amp.0 - h.1 * amp.1, h.0 * amp.1 + h.1 * amp.0)
    }

    /// |gap_response(f)|.
    pub fn gap_gain(&self, f: f64) -> f64 {
        let (re, im) = self.gap_response(f);
        re.hypot(im)
    }

    /// Gap voltage per commanded volt at DC: R_g / (R_b + R_i + R_g + R_t).
    pub fn dc_gain(&self) -> f64 {
        self.rg / (self.rb + self.ri + self.rg + self.rt)
    }

    /// Stored energy ½ Σ C v² of the capacitors for state `x`, J.
    pub fn energy(&self, x: &[f64]) -> f64 {
        0.5 * (self.ci * x[1] * x[1] + self.cg * x[2] * x[2] + self.ct * x[3] * x[3])
    }
}

fn cdiv(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::integrator::{Lti, Method};

    #[test]
    fn dc_and_high_frequency_limits_match_the_divider_formulas() {
        let c = Circuit::of(&LabProfile::default());
        assert!((c.gap_gain(1e-6) - c.dc_gain()).abs() < 1e-6);
        // Nominal: 2.5 / (0.01 + 10 + 2.5 + 0.1) MΩ = 0.198.
        assert!((c.dc_gain() - 0.19825).abs() < 1e-4, "{}", c.dc_gain());
        // Between the leakage corners and the amplifier/return poles the
        // circuit is a capacitive divider (1/C_g)/(1/C_i + 1/C_g + 1/C_t).
        let cap = (1.0 / c.cg) / (1.0 / c.ci + 1.0 / c.cg + 1.0 / c.ct);
        assert!((c.gap_gain(2000.0) / cap - 1.0).abs() < 0.03, "{} vs {cap}", c.gap_gain(2000.0));
    }

    #[test]
    fn exact_simulation_reproduces_the_complex_impedance_response() {
        // Drive a sine, let transients die, compare the gap-voltage amplitude
        // and phase with the analytic H(jω). Checks the circuit matrices and
        // their exact discretization against circuit theory.
        let c = Circuit::of(&LabProfile::default());
        let (a, b) = c.matrices();
        // The rate is high so the images of the held input's staircase (at
        // rate ± f, which the flat mid-band of the circuit passes and the
        // sampling folds back onto f) stay below 0.05 %.
        for (f, rate) in [(10.0, 200_000.0), (50.0, 200_000.0), (250.0, 200_000.0), (2000.0, 2_000_000.0)] {
            let h = 1.0 / rate;
            let sys = Lti::new(a.clone(), b.clone(), N, 1, h, Method::Exact).unwrap();
            let mut x = [0.0; N];
            // Whole periods only: settle for 10 periods (≥ 20 time constants), measure over 10.
            let per = (rate / f).round() as usize;
            let settle = 10 * per;
            let total = settle + 10 * per;
            let (mut si, mut co) = (0.0, 0.0);
            let mut count = 0.0;
            for n in 0..total {
                // Input held over [t_n, t_n + h): use the value at the step's middle
                // so the ZOH phase lag of h/2 is compensated.
                let t = (n as f64 + 0.5) * h;
                sys.step(&mut x, &[(2.0 * std::f64::consts::PI * f * t).sin()]);
                if n >= settle {
                    let te = (n + 1) as f64 * h;
                    si += x[GAP] * (2.0 * std::f64::consts::PI * f * te).sin();
                    co += x[GAP] * (2.0 * std::f64::consts::PI * f * te).cos();
                    count += 1.0;
                }
            }
            let (re, im) = (2.0 * si / count, 2.0 * co / count);
            let (hr, hi) = c.gap_response(f);
            let sinc = {
                let x = std::f64::consts::PI * f * h;
                x.sin() / x
            };
            assert!(
                ((re * re + im * im).sqrt() / (hr.hypot(hi) * sinc) - 1.0).abs() < 1e-3,
                "f {f}: gain {} vs {}",
                (re * re + im * im).sqrt(),
                hr.hypot(hi) * sinc
            );
            assert!((im.atan2(re) - hi.atan2(hr)).abs() < 2e-3, "f {f}: phase {} vs {}", im.atan2(re), hi.atan2(hr));
        }
    }

    #[test]
    fn circuit_is_passive() {
        // Charged capacitors, no drive: stored energy never increases.
        let c = Circuit::of(&LabProfile::default());
        let (a, b) = c.matrices();
        let sys = Lti::new(a, b, N, 1, 1e-4, Method::Exact).unwrap();
        let mut x = [0.0, 30.0, -20.0, 5.0];
        let mut e = c.energy(&x);
        for _ in 0..2000 {
            sys.step(&mut x, &[0.0]);
            let e1 = c.energy(&x);
            assert!(e1 <= e * (1.0 + 1e-12), "{e} → {e1}");
            e = e1;
        }
        assert!(e < 1e-3 * c.energy(&[0.0, 30.0, -20.0, 5.0]));
    }
}
