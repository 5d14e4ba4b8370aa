//! A texture sample's friction as a function of position along the scan:
//! a coefficient μ(x) = μ₀·(1 + m(x)) whose modulation m is a sum of
//! sinusoids in space — the sample's periodic components (weave, dots,
//! ridges, ripples) and a random component (many sinusoids with log-uniform
//! wavelengths, fixed phases) — each seen through the finger's or pen's
//! contact patch.
//!
//! **Contact patch.** A contact of half-width σ averages the surface with a
//! Gaussian weight, which multiplies a component of wavelength λ by
//! exp(−2π²σ²/λ²) exactly. The patch grows with the load as a Hertzian
//! contact, σ = σ₁·(N / 1 N)^{1/3}, and with the material's compliance
//! (σ₁ is larger for soft samples): soft samples lose their fine detail,
//! rough stiff ones keep it, and a heavier press smooths a little more.
//!
//! **Load-dependent components.** A component may grow with the load as
//! (N / N₈₅)^β (β its `load_exponent`, N₈₅ the 85 g middle load of the
//! grid, at most ×[`LOAD_GAIN_MAX`]): on a rigid ridged sheet a pen pressed
//! harder meets the ridges' flanks, and "the minor components in m₁ are
//! emphasized in m₃" (dissertation §5.3.1, plastic sheet).
//!
//! **Force.** F = μ(x)·N·tanh(v / v_s): Coulomb friction opposing the motion
//! (positive when moving toward +x, the lab's sign), regularized over
//! v_s = 0.5 mm/s so that a finger at rest feels no force and a reversal
//! has no jump. At a constant speed v a component of wavelength λ appears
//! at the temporal frequency v/λ — the linear frequency–velocity relation
//! of dissertation §6.3 — and the force's power grows with N² (§5.3.1).

use std::f64::consts::TAU;

/// Regularization speed of the friction's sign, m/s.
pub const V_SIGN: f64 = 0.0005;

/// The load at which the amplitudes are given: 85 g, the middle of the
/// dissertation's 60–110 g grid, N.
pub const N_REF: f64 = 0.085 * 9.806_65;

/// The largest growth of a load-dependent component, (N / N₈₅)^β ≤ 2.
pub const LOAD_GAIN_MAX: f64 = 2.0;

/// One spatial sinusoid of the modulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// Wavelength, m.
    pub wavelength: f64,
    /// Relative amplitude (of μ₀) at the 85 g load [`N_REF`].
    pub amplitude: f64,
    /// Phase, rad.
    pub phase: f64,
    /// Growth with the load: the amplitude is multiplied by
    /// min((N / N₈₅)^β, [`LOAD_GAIN_MAX`]); 0 for most components.
    pub load_exponent: f64,
}

impl Component {
    /// A component whose amplitude does not depend on the load.
    pub const fn fixed(wavelength: f64, amplitude: f64, phase: f64) -> Self {
        Component { wavelength, amplitude, phase, load_exponent: 0.0 }
    }

    /// The factor the load applies to the amplitude.
    pub fn load_gain(&self, load: f64) -> f64 {
        if self.load_exponent == 0.0 {
            1.0
        } else {
            (load.max(0.0) / N_REF).powf(self.load_exponent).min(LOAD_GAIN_MAX)
        }
    }
}

/// How the random component's amplitudes depend on the wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Amplitudes ∝ (λ / λ_max)^slope: a broadband roughness whose long
    /// wavelengths dominate for a positive slope.
    PowerLaw(f64),
    /// Amplitudes ∝ exp(−ln²(λ/λ_c) / (2w²)): random texture with a
    /// preferred scale λ_c (fibre tufts, folds) and no visible pattern; its
    /// spectrum has a broad hump at v/λ_c.
    Peak {
        /// Preferred wavelength λ_c, m.
        center: f64,
        /// Width w in natural-log units of wavelength.
        width: f64,
    },
}

/// A sample's surface: base friction, components, contact compliance.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Base friction coefficient μ₀.
    pub mu: f64,
    /// Modulation components (periodic first, then random).
    pub components: Vec<Component>,
    /// Contact half-width at 1 N, m.
    pub sigma_1n: f64,
}

/// The random component's recipe: `count` sinusoids with wavelengths
/// log-uniform in [`shortest`, `longest`], amplitudes shaped by `shape`
/// and scaled to a total rms of `rms`, phases from `seed`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roughness {
    /// Rms of the random modulation (relative).
    pub rms: f64,
    /// Shortest wavelength, m.
    pub shortest: f64,
    /// Longest wavelength, m.
    pub longest: f64,
    /// Amplitude against wavelength.
    pub shape: Shape,
    /// Number of sinusoids.
    pub count: usize,
    /// Seed fixing wavelengths and phases (the same sample, the same surface).
    pub seed: u64,
}

impl Roughness {
    /// The sinusoids of this roughness.
    pub fn components(&self) -> Vec<Component> {
        let mut s = self.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let (lo, hi) = (self.shortest.ln(), self.longest.ln());
        let mut c: Vec<Component> = (0..self.count)
            .map(|_| {
                let wavelength = (lo + (hi - lo) * next()).exp();
                let amplitude = match self.shape {
                    Shape::PowerLaw(slope) => (wavelength / self.longest).powf(slope),
                    Shape::Peak { center, width } => {
                        (-(wavelength / center).ln().powi(2) / (2.0 * width * width).max(1e-12)).exp()
                    }
                };
                Component { wavelength, amplitude, phase: TAU * next(), load_exponent: 0.0 }
            })
            .collect();
        // A sum of sinusoids of amplitudes a_k has rms √(Σa²/2).
        let rms = (c.iter().map(|k| k.amplitude * k.amplitude).sum::<f64>() / 2.0).sqrt();
        if rms > 0.0 {
            for k in &mut c {
                k.amplitude *= self.rms / rms;
            }
        }
        c
    }
}

impl Surface {
    /// A surface from its periodic components and random parts. If the
    /// amplitudes could sum to more than 0.9 (load-dependent ones at their
    /// largest growth) the modulation is scaled down so that μ(x) ≥ 0.1·μ₀
    /// everywhere and at every load.
    pub fn new(mu: f64, periodic: &[Component], roughness: &[Roughness], sigma_1n: f64) -> Self {
        let mut components: Vec<Component> = periodic.to_vec();
        for r in roughness {
            components.extend(r.components());
        }
        let worst = |c: &Component| if c.load_exponent == 0.0 { 1.0 } else { LOAD_GAIN_MAX };
        let total: f64 = components.iter().map(|c| c.amplitude.abs() * worst(c)).sum();
        if total > 0.9 {
            for c in &mut components {
                c.amplitude *= 0.9 / total;
            }
        }
        Surface { mu, components, sigma_1n }
    }

    /// The contact half-width under `load` N, m.
    pub fn sigma(&self, load: f64) -> f64 {
        self.sigma_1n * load.max(0.0).cbrt()
    }

    /// The gain of each component under `load` — the contact patch's
    /// attenuation times the load's growth — written into `gains` (one per
    /// component).
    pub fn gains(&self, load: f64, gains: &mut [f64]) {
        let s = self.sigma(load);
        for (g, c) in gains.iter_mut().zip(&self.components) {
            let patch = (-2.0 * std::f64::consts::PI.powi(2) * s * s / (c.wavelength * c.wavelength)).exp();
            *g = patch * c.load_gain(load);
        }
    }

    /// The component with the largest amplitude under `load` (after the
    /// contact patch and the load's growth): the main component of the
    /// sample's force, at v/λ (§6.3). `None` for a flat surface.
    pub fn dominant(&self, load: f64) -> Option<Component> {
        let mut g = vec![0.0; self.components.len()];
        self.gains(load, &mut g);
        self.components
            .iter()
            .zip(&g)
            .max_by(|a, b| (a.0.amplitude.abs() * a.1).total_cmp(&(b.0.amplitude.abs() * b.1)))
            .map(|(c, _)| *c)
    }

    /// μ(x) with the given per-component gains.
    pub fn mu_at(&self, x: f64, gains: &[f64]) -> f64 {
        let m: f64 = self
            .components
            .iter()
            .zip(gains)
            .map(|(c, g)| g * c.amplitude * (TAU * x / c.wavelength + c.phase).sin())
            .sum();
        self.mu * (1.0 + m)
    }

    /// The force of the base friction alone, μ₀·N·tanh(v/v_s): what
    /// [`Surface::force`] is without the texture's modulation.
    pub fn base_force(&self, v: f64, n: f64) -> f64 {
        if !(v.is_finite() && n.is_finite()) {
            return 0.0;
        }
        self.mu * n.max(0.0) * (v / V_SIGN).tanh()
    }

    /// The friction force at position `x` (m), velocity `v` (m/s) and load
    /// `n` (N), given the gains for that load. Finite for finite inputs;
    /// non-finite inputs give 0.
    pub fn force(&self, x: f64, v: f64, n: f64, gains: &[f64]) -> f64 {
        if !(x.is_finite() && v.is_finite() && n.is_finite()) {
            return 0.0;
        }
        let n = n.max(0.0);
        self.mu_at(x, gains).max(0.0) * n * (v / V_SIGN).tanh()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gaussian_patch_attenuates_a_sinusoid_by_the_closed_form() {
        // Numerically average one component over a Gaussian patch and
        // compare with exp(−2π²σ²/λ²).
        let c = Component::fixed(0.002, 0.5, 0.3);
        let s = Surface::new(1.0, &[c], &[], 0.0004);
        let sigma = s.sigma(2.0);
        let mut g = [0.0];
        s.gains(2.0, &mut g);
        let x0 = 0.0123;
        let (mut acc, mut wsum) = (0.0, 0.0);
        for i in -8000..=8000 {
            let d = i as f64 * sigma * 1e-3;
            let w = (-0.5 * (d / sigma).powi(2)).exp();
            acc += w * (TAU * (x0 + d) / c.wavelength + c.phase).sin();
            wsum += w;
        }
        let want = acc / wsum;
        let got = g[0] * (TAU * x0 / c.wavelength + c.phase).sin();
        assert!((want - got).abs() < 1e-6, "{want} vs {got}");
    }

    #[test]
    fn roughness_has_the_requested_rms_and_is_fixed_by_its_seed() {
        let r = Roughness { rms: 0.2, shortest: 5e-4, longest: 0.01, shape: Shape::PowerLaw(0.5), count: 48, seed: 7 };
        let c = r.components();
        let rms = (c.iter().map(|k| k.amplitude.powi(2)).sum::<f64>() / 2.0).sqrt();
        assert!((rms - 0.2).abs() < 1e-12);
        assert_eq!(c, r.components());
        assert_ne!(c, Roughness { seed: 8, ..r }.components());
        assert!(c.iter().all(|k| (5e-4..=0.01).contains(&k.wavelength)));
    }

    #[test]
    fn friction_opposes_motion_vanishes_at_rest_and_stays_non_negative_in_magnitude() {
        let r = Roughness { rms: 0.6, shortest: 5e-4, longest: 0.01, shape: Shape::PowerLaw(0.0), count: 32, seed: 1 };
        let s = Surface::new(0.2, &[Component::fixed(0.003, 0.8, 0.0)], &[r], 1e-4);
        let mut g = vec![0.0; s.components.len()];
        s.gains(1.0, &mut g);
        for i in 0..2000 {
            let x = i as f64 * 7e-5;
            let f = s.force(x, 0.05, 1.0, &g);
            assert!((0.0..=0.2 * 1.9 + 1e-12).contains(&f), "{f}");
            assert!(s.mu_at(x, &g) >= 0.1 * 0.2 - 1e-12);
            assert!(s.force(x, -0.05, 1.0, &g) <= 0.0);
            assert_eq!(s.force(x, 0.0, 1.0, &g), 0.0);
        }
        assert_eq!(s.force(f64::NAN, 0.05, 1.0, &g), 0.0);
        assert_eq!(s.force(0.01, 0.05, -3.0, &g), 0.0);
    }

    #[test]
    fn a_peaked_roughness_is_largest_at_its_scale_and_load_growth_is_capped() {
        let shape = Shape::Peak { center: 0.002, width: 0.2 };
        let r = Roughness { rms: 0.2, shortest: 0.001, longest: 0.004, shape, count: 200, seed: 3 };
        let c = r.components();
        let best = c.iter().max_by(|a, b| a.amplitude.total_cmp(&b.amplitude)).unwrap();
        assert!((best.wavelength / 0.002).ln().abs() < 0.05, "{}", best.wavelength);
        // An octave away the amplitude is exp(−ln²2 / 0.08) = 0.25 % of the peak's.
        for k in &c {
            let want = (-(k.wavelength / 0.002).ln().powi(2) / 0.08).exp();
            assert!(
                (k.amplitude / best.amplitude - want / (-(best.wavelength / 0.002f64).ln().powi(2) / 0.08).exp()).abs()
                    < 1e-12
            );
        }
        let h = Component { load_exponent: 1.5, ..Component::fixed(0.001, 0.1, 0.0) };
        assert_eq!(h.load_gain(N_REF), 1.0);
        assert!((h.load_gain(0.060 * 9.806_65) - (60.0f64 / 85.0).powf(1.5)).abs() < 1e-12);
        assert_eq!(h.load_gain(1000.0), LOAD_GAIN_MAX);
        assert_eq!(h.load_gain(0.0), 0.0);
        // Scaled for the worst case: 0.6 + 2 × 0.3 > 0.9, so μ ≥ 0.1·μ₀ at any load.
        let s = Surface::new(0.2, &[Component::fixed(0.002, 0.6, 0.0), Component { amplitude: 0.3, ..h }], &[], 0.0);
        let mut g = vec![0.0; 2];
        s.gains(100.0, &mut g);
        for i in 0..4000 {
            assert!(s.mu_at(i as f64 * 1e-6, &g) >= 0.1 * 0.2 - 1e-12);
        }
    }
}
