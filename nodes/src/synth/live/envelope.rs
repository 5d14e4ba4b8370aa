//! The forward model seen through a Nyquist-rate carrier, and a grid of
//! such models blended at the finger's condition.
//!
//! With u\[k\] = s_k·a\[k\], s_k = (−1)^k, the second-order Volterra model of
//! [`crate::synth::volterra`] becomes, since s_{k−i}·s_{k−j} = (−1)^{i+j}
//! for every k,
//!
//! ```text
//! y[k] = c + s_k · Σ_i l̃_i a[k−i] + Σ_i Σ_j Q_ij a[k−i] a[k−j],
//! Q_ij = (−1)^{i+j} H_ij,   l̃_i = (−1)^i l_i
//! ```
//!
//! a *time-invariant* quadratic model of the envelope a (only the small
//! linear term, which an amplifier offset brings, keeps the carrier's
//! sign). A held envelope a raises the force by κ·a², κ = Σ Q_ij, the
//! model's carrier gain. The live synthesis ([`super::horizon`]) optimizes
//! the envelope, which varies as slowly as the texture, instead of u,
//! which alternates every sample.
//!
//! **Blending.** The models of a grid of trained conditions (loads ×
//! speeds, every combination present) are blended bilinearly at the
//! finger's (load, speed), clamped to the grid — the weighted average 𝒲𝒜
//! of Eq. 6.1 applied to the kernels, in place and without allocating.

use crate::synth::error::SynthError;
use crate::synth::volterra::Volterra;

/// A forward model in the envelope domain.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvelopeModel {
    /// Memory M, samples.
    pub memory: usize,
    /// Q, M × M, symmetric, row-major.
    pub q: Vec<f64>,
    /// l̃, M.
    pub lt: Vec<f64>,
    /// κ = Σ Q_ij, N per unit envelope².
    pub kappa: f64,
    /// β: the residual noise power added per unit of u², N² (the model's noise model).
    pub beta: f64,
}

impl EnvelopeModel {
    /// The envelope-domain form of `v`, with noise slope `beta`.
    pub fn of(v: &Volterra, beta: f64) -> Self {
        let m = v.memory();
        let sign = |i: usize| if i.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut q = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                q[i * m + j] = sign(i + j) * v.quadratic(i, j);
            }
        }
        let lt: Vec<f64> = (0..m).map(|i| sign(i) * v.linear()[i]).collect();
        let kappa = q.iter().sum();
        Self { memory: m, q, lt, kappa, beta: beta.max(0.0) }
    }

    /// A model of memory `m` with every coefficient 0 (a buffer to blend into).
    pub fn zeros(m: usize) -> Self {
        Self { memory: m, q: vec![0.0; m * m], lt: vec![0.0; m], kappa: 0.0, beta: 0.0 }
    }

    /// Σ w·model over `parts` into `self` (all of one memory; nothing allocated).
    fn blend(&mut self, parts: &[(&EnvelopeModel, f64)]) {
        self.q.iter_mut().for_each(|x| *x = 0.0);
        self.lt.iter_mut().for_each(|x| *x = 0.0);
        self.kappa = 0.0;
        self.beta = 0.0;
        for (m, w) in parts {
            for (a, b) in self.q.iter_mut().zip(&m.q) {
                *a += w * b;
            }
            for (a, b) in self.lt.iter_mut().zip(&m.lt) {
                *a += w * b;
            }
            self.kappa += w * m.kappa;
            self.beta += w * m.beta;
        }
    }
}

/// Forward models over a rectangular grid of trained conditions.
#[derive(Debug, Clone)]
pub struct ModelGrid {
    /// Trained loads, g, ascending.
    loads: Vec<f64>,
    /// Trained speeds, cm/s, ascending.
    speeds: Vec<f64>,
    /// The models, load-major: index = i_load · speeds + i_speed.
    models: Vec<EnvelopeModel>,
}

/// The bracketing indices and the weight of the upper one for `x` on the
/// ascending axis `axis`, clamped to its ends (a non-finite `x` takes the
/// first point).
pub fn bracket(axis: &[f64], x: f64) -> (usize, usize, f64) {
    let n = axis.len();
    if n == 1 || !x.is_finite() || x <= axis[0] {
        return (0, 0, 0.0);
    }
    if x >= axis[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let hi = axis.iter().position(|&a| a > x).unwrap_or(n - 1);
    let lo = hi - 1;
    (lo, hi, (x - axis[lo]) / (axis[hi] - axis[lo]))
}

impl ModelGrid {
    /// A grid from models at (load g, speed cm/s); every combination of the
    /// loads and speeds that occur must be present exactly once. `names`
    /// label the models in errors.
    pub fn new(entries: Vec<((f64, f64), EnvelopeModel)>, names: &[String]) -> Result<Self, SynthError> {
        let first = entries.first().ok_or_else(|| SynthError::Config("name at least one forward model".into()))?;
        let m = first.1.memory;
        let mut loads: Vec<f64> = Vec::new();
        let mut speeds: Vec<f64> = Vec::new();
        for (k, ((l, s), model)) in entries.iter().enumerate() {
            if model.memory != m {
                return Err(SynthError::Config(format!(
                    "{}: memory {} differs from {}'s {m}; the models of one grid must share their memory",
                    names[k], model.memory, names[0]
                )));
            }
            if !loads.contains(l) {
                loads.push(*l);
            }
            if !speeds.contains(s) {
                speeds.push(*s);
            }
        }
        loads.sort_by(f64::total_cmp);
        speeds.sort_by(f64::total_cmp);
        let mut models = Vec::with_capacity(loads.len() * speeds.len());
        for &l in &loads {
            for &s in &speeds {
                let at: Vec<usize> =
                    entries.iter().enumerate().filter(|(_, e)| e.0 == (l, s)).map(|(k, _)| k).collect();
                match at.as_slice() {
                    [k] => models.push(entries[*k].1.clone()),
                    [] => {
                        return Err(SynthError::Config(format!(
                            "no model at {l} g, {s} cm/s: the models must cover every combination of their loads \
                             ({loads:?} g) and speeds ({speeds:?} cm/s)"
                        )))
                    }
                    [a, b, ..] => {
                        return Err(SynthError::Config(format!(
                            "{} and {} are both at {l} g, {s} cm/s; one model per condition",
                            names[*a], names[*b]
                        )))
                    }
                }
            }
        }
        Ok(Self { loads, speeds, models })
    }

    /// The memory of the grid's models.
    pub fn memory(&self) -> usize {
        self.models[0].memory
    }

    /// The trained loads (g) and speeds (cm/s).
    pub fn axes(&self) -> (&[f64], &[f64]) {
        (&self.loads, &self.speeds)
    }

    /// The model at `load` g and `speed` cm/s (bilinear, clamped) into `out`.
    pub fn at(&self, load: f64, speed: f64, out: &mut EnvelopeModel) {
        let (l0, l1, wl) = bracket(&self.loads, load);
        let (s0, s1, ws) = bracket(&self.speeds, speed.abs());
        let ns = self.speeds.len();
        let at = |l: usize, s: usize| &self.models[l * ns + s];
        out.blend(&[
            (at(l0, s0), (1.0 - wl) * (1.0 - ws)),
            (at(l0, s1), (1.0 - wl) * ws),
            (at(l1, s0), wl * (1.0 - ws)),
            (at(l1, s1), wl * ws),
        ]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn random(m: usize, seed: u64) -> Volterra {
        let mut r = Rng::new(seed);
        let upper: Vec<f64> = (0..m * (m + 1) / 2).map(|_| r.gaussian()).collect();
        Volterra::from_upper(&upper, (0..m).map(|_| r.gaussian()).collect(), r.gaussian()).unwrap()
    }

    /// y[k] from the envelope-domain form, for an envelope `a` (zero before 0).
    fn envelope_eval(e: &EnvelopeModel, c: f64, a: &[f64], k: usize) -> f64 {
        let m = e.memory;
        let at = |i: usize| if i <= k { a[k - i] } else { 0.0 };
        let s = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut y = c;
        for i in 0..m {
            y += s * e.lt[i] * at(i);
            for j in 0..m {
                y += e.q[i * m + j] * at(i) * at(j);
            }
        }
        y
    }

    #[test]
    fn the_envelope_form_gives_the_models_force_on_a_carrier() {
        let v = random(6, 1);
        let e = EnvelopeModel::of(&v, 0.0);
        let mut r = Rng::new(2);
        let a: Vec<f64> = (0..50).map(|_| r.uniform()).collect();
        let u: Vec<f64> = a.iter().enumerate().map(|(k, x)| if k % 2 == 0 { *x } else { -x }).collect();
        let mut y = vec![0.0; 50];
        v.eval(&u, &mut y);
        for (k, yk) in y.iter().enumerate() {
            let want = envelope_eval(&e, v.constant(), &a, k);
            assert!((yk - want).abs() < 1e-10 * (1.0 + want.abs()), "k {k}: {yk} vs {want}");
        }
        assert!((e.kappa - v.carrier_gain()).abs() < 1e-12 * (1.0 + e.kappa.abs()));
    }

    #[test]
    fn the_grid_blends_bilinearly_and_clamps_to_its_corners() {
        let models: Vec<EnvelopeModel> = (0..4).map(|s| EnvelopeModel::of(&random(3, 10 + s), s as f64)).collect();
        let conds = [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)];
        let names: Vec<String> = (0..4).map(|k| format!("m{k}")).collect();
        // Given out of order: the grid sorts its axes.
        let order = [3, 0, 2, 1];
        let grid = ModelGrid::new(order.iter().map(|&k| (conds[k], models[k].clone())).collect(), &names).unwrap();
        let mut out = EnvelopeModel::zeros(3);
        grid.at(60.0, 3.0, &mut out);
        assert_eq!(out, models[0]);
        grid.at(1e9, -1e9, &mut out);
        assert_eq!(out.q, models[3].q, "speed by magnitude, clamped to 7; load clamped to 110");
        grid.at(85.0, 4.0, &mut out);
        let w = [0.5 * 0.75, 0.5 * 0.25, 0.5 * 0.75, 0.5 * 0.25];
        for i in 0..9 {
            let want: f64 = (0..4).map(|k| w[k] * models[k].q[i]).sum();
            assert!((out.q[i] - want).abs() < 1e-12);
        }
        assert!((out.beta - (0.0 * w[0] + 1.0 * w[1] + 2.0 * w[2] + 3.0 * w[3])).abs() < 1e-12);
        grid.at(f64::NAN, 5.0, &mut out);
        assert!(out.q.iter().all(|x| x.is_finite()));
    }

    #[test]
    fn an_incomplete_or_doubled_grid_is_refused_by_name() {
        let m = EnvelopeModel::of(&random(3, 1), 0.0);
        let names: Vec<String> = (0..3).map(|k| format!("model{k}.json")).collect();
        let e = ModelGrid::new(vec![((60.0, 3.0), m.clone()), ((110.0, 7.0), m.clone())], &names).unwrap_err();
        assert!(e.to_string().contains("no model at 60 g, 7 cm/s"), "{e}");
        let e = ModelGrid::new(vec![((60.0, 3.0), m.clone()), ((60.0, 3.0), m.clone())], &names).unwrap_err();
        assert!(e.to_string().contains("model0.json and model1.json"), "{e}");
        let other = EnvelopeModel::of(&random(4, 1), 0.0);
        let e = ModelGrid::new(vec![((60.0, 3.0), m), ((60.0, 7.0), other)], &names).unwrap_err();
        assert!(e.to_string().contains("memory"), "{e}");
        assert!(ModelGrid::new(vec![], &names).is_err());
    }
}
