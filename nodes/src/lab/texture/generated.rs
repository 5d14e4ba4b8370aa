//! Generated texture samples, `generated-<seed>`: a [`Surface`] drawn from
//! a `u64` seed with [`crate::rng`], so that a model library can be measured
//! on many more textures than the lab's seven (issue 17). The same seed
//! always gives the same surface; the name is the whole recipe.
//!
//! Every value is drawn within the ranges the seven shipped samples
//! ([`super::samples`]) cover, so a generated sample is one more sample of
//! the same kind, never a new regime:
//!
//! * **Base friction** μ₀ uniform in 0.13–0.23.
//! * **Patterned or not.** 5 in 7 are patterned (as the dotted sheet, chair
//!   fabric, painting canvas, plastic sheet and rippled paper): a main
//!   component of wavelength log-uniform in 0.9–2.5 mm and amplitude
//!   uniform in 0.25–0.50, phase 0, with 0–2 harmonics at λ/2 and λ/3 of
//!   amplitude 0.06–0.18 and random phase. One patterned sample in 5 is
//!   *ridged* (as the plastic sheet): main wavelength 1.5–2.5 mm, two
//!   harmonics at λ/3 and λ/5 that grow with the load (β = 1.5), phase 0 —
//!   a square wave's odd harmonics. Periodic wavelengths thus lie in
//!   0.30–2.5 mm (the shipped samples: 0.34–2.5 mm, and the chair's 6.6 mm
//!   pattern repeat).
//! * The other 2 in 7 are **patternless** (as the felt fabric and scrunched
//!   paper): random texture of rms 0.25 around a preferred scale
//!   log-uniform in 1.3–2.0 mm (log-width 0.2, 24 sinusoids).
//! * **Broadband roughness** on every sample: rms uniform in 0.02–0.15,
//!   wavelengths from 0.3–0.5 mm to 5–10 mm, slope 0.3–1.0, 16–48
//!   sinusoids, its own seed.
//! * **Contact half-width at 1 N** σ₁: 2 in 7 samples are *soft* (as the
//!   two fabrics) with σ₁ uniform in 0.35–0.40 mm, the rest rough with σ₁ in
//!   0.04–0.10 mm.
//!
//! [`Surface::new`] caps the modulation as for the shipped samples, so
//! μ(x) ≥ 0.1·μ₀ at every load.

use super::surface::{Component, Roughness, Shape, Surface};
use crate::rng::Rng;

/// The prefix of a generated sample's name: `generated-<seed>`.
pub const PREFIX: &str = "generated-";

const MM: f64 = 1e-3;

/// A name that starts with `generated-` but whose seed is not a `u64`
/// written in decimal without a sign or leading zeros.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "sample `{0}`: a generated sample is named generated-<seed>, the seed a whole number \
     0–18446744073709551615 written without sign or leading zeros (e.g. generated-7)"
)]
pub struct BadName(pub String);

/// The name of the generated sample of `seed`.
pub fn name(seed: u64) -> String {
    format!("{PREFIX}{seed}")
}

/// The seed of a generated sample's name: `None` when `name` does not start
/// with `generated-` (not a generated sample), an error when it does but
/// the rest is not a canonical `u64`.
pub fn parse(name: &str) -> Option<Result<u64, BadName>> {
    let digits = name.strip_prefix(PREFIX)?;
    let canonical =
        !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) && (digits == "0" || !digits.starts_with('0'));
    Some(if canonical { digits.parse().map_err(|_| BadName(name.to_string())) } else { Err(BadName(name.to_string())) })
}

/// Uniform in [lo, hi).
fn between(r: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * r.uniform()
}

/// Log-uniform in [lo, hi).
fn log_between(r: &mut Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * r.uniform()).exp()
}

/// True with probability `p`.
fn chance(r: &mut Rng, p: f64) -> bool {
    r.uniform() < p
}

/// Whether the generated sample of `seed` is soft (wide contact patch).
pub fn is_soft(seed: u64) -> bool {
    surface(seed).sigma_1n > 0.2 * MM
}

/// The surface of the generated sample of `seed` (ranges: module doc).
pub fn surface(seed: u64) -> Surface {
    // A labelled substream: the surface's numbers never coincide with a
    // sensor's or a user's stream seeded with the same number.
    let mut r = Rng::substream(seed, 0x7465_7874_7572_6573); // "textures"
    let mu = between(&mut r, 0.13, 0.23);
    let patterned = chance(&mut r, 5.0 / 7.0);
    let mut periodic = Vec::new();
    let mut random = Vec::new();
    if patterned {
        let ridged = chance(&mut r, 0.2);
        let (lo, hi) = if ridged { (1.5, 2.5) } else { (0.9, 2.5) };
        let l = log_between(&mut r, lo, hi) * MM;
        periodic.push(Component::fixed(l, between(&mut r, 0.25, 0.50), 0.0));
        if ridged {
            for order in [3.0, 5.0] {
                let a = between(&mut r, 0.06, 0.18);
                periodic.push(Component { load_exponent: 1.5, ..Component::fixed(l / order, a, 0.0) });
            }
        } else {
            let harmonics = (r.next_u64() % 3) as usize;
            for order in [2.0, 3.0].into_iter().take(harmonics) {
                let a = between(&mut r, 0.06, 0.18);
                let phase = between(&mut r, 0.0, std::f64::consts::TAU);
                periodic.push(Component::fixed(l / order, a, phase));
            }
        }
    } else {
        let center = log_between(&mut r, 1.3, 2.0);
        let width: f64 = 0.2;
        let (lo, hi) = (center * (-2.0 * width).exp(), center * (2.0 * width).exp());
        let shape = Shape::Peak { center: center * MM, width };
        random.push(Roughness { rms: 0.25, shortest: lo * MM, longest: hi * MM, shape, count: 24, seed: r.next_u64() });
    }
    random.push(Roughness {
        rms: between(&mut r, 0.02, 0.15),
        shortest: between(&mut r, 0.3, 0.5) * MM,
        longest: between(&mut r, 5.0, 10.0) * MM,
        shape: Shape::PowerLaw(between(&mut r, 0.3, 1.0)),
        count: 16 + (r.next_u64() % 33) as usize,
        seed: r.next_u64(),
    });
    let soft = chance(&mut r, 2.0 / 7.0);
    let sigma = if soft { between(&mut r, 0.35, 0.40) } else { between(&mut r, 0.04, 0.10) } * MM;
    Surface::new(mu, &periodic, &random, sigma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::texture::samples;

    const G: f64 = 9.806_65;

    #[test]
    fn the_same_seed_gives_the_same_surface_and_seeds_differ() {
        assert_eq!(surface(7), surface(7));
        assert_eq!(samples::sample("generated-7"), Some(surface(7)));
        for s in 0..50u64 {
            assert_ne!(surface(s), surface(s + 1), "{s}");
        }
        assert_ne!(surface(0), surface(u64::MAX));
        assert_eq!(parse(&name(u64::MAX)), Some(Ok(u64::MAX)));
        assert_eq!(parse("felt-fabric"), None);
    }

    #[test]
    fn malformed_names_are_refused_with_a_clear_error() {
        for bad in ["generated-x", "generated-", "generated-07", "generated-+7", "generated-18446744073709551616"] {
            let e = parse(bad).unwrap().unwrap_err();
            assert_eq!(e, BadName(bad.to_string()));
            let msg = e.to_string();
            assert!(msg.contains(&format!("`{bad}`")) && msg.contains("generated-<seed>"), "{msg}");
            let msg = samples::lookup(bad).unwrap_err();
            assert!(msg.contains(&format!("`{bad}`")) && msg.contains("generated-<seed>"), "{msg}");
            assert_eq!(samples::sample(bad), None);
        }
        let unknown = samples::lookup("velvet").unwrap_err();
        assert!(
            unknown.contains("`velvet`") && unknown.contains("felt-fabric") && unknown.contains("generated-<seed>")
        );
    }

    #[test]
    fn every_generated_surface_gives_finite_bounded_force_over_loads_and_velocities() {
        // |F| ≤ μ₀·(1 + 0.9)·N: Surface::new caps the summed amplitudes at
        // 0.9 (load-grown ones at their largest growth), the patch only
        // attenuates.
        for seed in 0..200u64 {
            let s = surface(seed);
            assert!((0.13..0.23).contains(&s.mu), "{seed}");
            let mut g = vec![0.0; s.components.len()];
            for grams in [0.0, 1.0, 60.0, 85.0, 110.0, 1000.0] {
                let load = grams * 1e-3 * G;
                s.gains(load, &mut g);
                assert!(g.iter().all(|k| k.is_finite() && (0.0..=2.0).contains(k)), "{seed} {grams}");
                for v in [-0.5, -0.07, -0.03, 0.0, 1e-4, 0.03, 0.05, 0.07, 0.5] {
                    for i in 0..400 {
                        let x = i as f64 * 3.7e-5;
                        let f = s.force(x, v, load, &g);
                        assert!(f.is_finite() && f.abs() <= s.mu * 1.9 * load + 1e-12, "{seed} {grams} g {v} m/s: {f}");
                        assert!(f * v >= 0.0, "opposes the motion");
                        assert!(s.mu_at(x, &g) >= 0.1 * s.mu - 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn generated_samples_span_the_shipped_ranges() {
        let mut mains = Vec::new();
        let (mut soft, mut patternless, mut ridged) = (0, 0, 0);
        for seed in 1..=200u64 {
            let s = surface(seed);
            soft += usize::from(is_soft(seed));
            if s.components.iter().any(|c| c.load_exponent > 0.0) {
                ridged += 1;
            }
            // Periodic components come first and have phase 0 for the main.
            let main = s.components[0];
            if main.wavelength >= 0.9 * MM && main.phase == 0.0 {
                mains.push(main.wavelength);
            } else {
                patternless += 1;
            }
            let d = s.dominant(0.085 * G).unwrap();
            assert!((0.25 * MM..=10.0 * MM).contains(&d.wavelength), "{seed}");
            assert!(s.components.iter().all(|c| (0.29 * MM..=10.0 * MM).contains(&c.wavelength)), "{seed}");
        }
        let (lo, hi) = mains.iter().fold((1.0f64, 0.0f64), |(a, b), &l| (a.min(l), b.max(l)));
        assert!(lo < 1.0 * MM && hi > 2.3 * MM && hi < 2.5 * MM, "{lo} {hi}");
        // Expected 57 soft, 57 patternless, 29 ridged of 200.
        assert!((35..80).contains(&soft), "{soft}");
        assert!((35..80).contains(&patternless), "{patternless}");
        assert!((12..50).contains(&ridged), "{ridged}");
        // Soft samples keep less fine detail than rough ones, as §6.5.1
        // groups them: the patch's gain on a 0.6 mm component at 85 g.
        for seed in 1..=40u64 {
            let s = Surface { components: vec![Component::fixed(0.6 * MM, 0.1, 0.0)], ..surface(seed) };
            let mut g = [0.0];
            s.gains(0.085 * G, &mut g);
            if is_soft(seed) {
                assert!(g[0] < 0.01, "{seed}: {}", g[0]);
            } else {
                assert!(g[0] > 0.5, "{seed}: {}", g[0]);
            }
        }
    }

    #[test]
    fn the_node_takes_generated_names_and_its_spec_lists_every_sample() {
        let spec = super::super::SPEC.params.iter().find(|p| p.name == "sample").unwrap();
        for n in samples::NAMES {
            assert!(spec.doc.contains(n), "{n}");
        }
        assert!(spec.doc.contains("generated-<seed>"));
    }
}
