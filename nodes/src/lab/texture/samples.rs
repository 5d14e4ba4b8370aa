//! The seven texture samples: the six of dissertation §5.3 (Fig. 5.5) and
//! the rippled paper of §6.3 (Fig. 6.5), as [`Surface`]s.
//!
//! The dissertation describes them (Appendix, §6.6): the dotted sheet is a
//! thin plastic sheet with holes all over it; the chair fabric a soft
//! material with woven patterns; the felt fabric a thick soft material with
//! no distinguishable pattern; the painting canvas a rough, sturdy linen with
//! uniform nodes; the plastic sheet rigid with diagonal ridges (a square
//! wave under the finger); the scrunched paper a thick paper with random
//! patterns; the rippled paper an almost perfect sinusoid. "Chair and felt
//! fabrics feel soft while others generally feel rough." The values below
//! are chosen to reproduce those descriptions, not measured: wavelengths of
//! the visible patterns (mm scale, main components of 5–50 Hz at 3–7 cm/s as
//! in Fig. 5.7), a contact patch that is wide on the soft samples (their fine
//! detail is smoothed away) and narrow on the stiff ones, and base friction
//! coefficients of a pen tip on plastic, paper and fabric (0.13–0.24) so that
//! forces at 60–110 g stay near the 0.075–0.25 N range of §3.2.1.

use super::surface::{Component, Roughness, Surface};

/// The sample names, as the `sample` parameter takes them.
pub const NAMES: &[&str] = &[
    "dotted-sheet",
    "chair-fabric",
    "felt-fabric",
    "painting-canvas",
    "plastic-sheet",
    "scrunched-paper",
    "rippled-paper",
];

/// Whether a sample is soft (the dissertation's grouping).
pub fn is_soft(name: &str) -> bool {
    matches!(name, "chair-fabric" | "felt-fabric")
}

const MM: f64 = 1e-3;

fn periodic(parts: &[(f64, f64, f64)]) -> Vec<Component> {
    parts.iter().map(|&(l, a, p)| Component { wavelength: l * MM, amplitude: a, phase: p }).collect()
}

fn rough(rms: f64, shortest_mm: f64, longest_mm: f64, slope: f64, count: usize, seed: u64) -> Option<Roughness> {
    Some(Roughness { rms, shortest: shortest_mm * MM, longest: longest_mm * MM, slope, count, seed })
}

/// The surface of a named sample, or `None` for an unknown name.
pub fn sample(name: &str) -> Option<Surface> {
    Some(match name {
        // Holes on a 2 mm grid: a strong fundamental with the harmonics of
        // short dips; thin stiff plastic, a narrow contact.
        "dotted-sheet" => Surface::new(
            0.16,
            &periodic(&[(2.0, 0.45, 0.0), (1.0, 0.18, 0.4), (0.667, 0.08, 0.9)]),
            rough(0.03, 0.3, 5.0, 0.5, 24, 11),
            0.08 * MM,
        ),
        // Woven 1.6 mm threads, some fuzz; soft: a wide contact.
        "chair-fabric" => {
            Surface::new(0.22, &periodic(&[(1.6, 0.45, 0.0)]), rough(0.05, 0.5, 4.0, 0.5, 32, 12), 0.3 * MM)
        }
        // No pattern: random fibre clumps of 1.5–3.5 mm; thick and soft:
        // the widest contact, which leaves mostly the larger clumps.
        "felt-fabric" => Surface::new(0.24, &[], rough(0.20, 1.5, 3.5, 0.0, 48, 13), 0.6 * MM),
        // Linen nodes at 0.9 mm (and their harmonic), irregular threads; sturdy.
        "painting-canvas" => Surface::new(
            0.19,
            &periodic(&[(0.9, 0.25, 0.0), (0.45, 0.10, 0.7)]),
            rough(0.10, 0.3, 6.0, 0.5, 32, 14),
            0.06 * MM,
        ),
        // Ridges 1.5 mm apart at 45° to the scan: 2.12 mm along it,
        // square-wave harmonics 1, 3, 5; rigid and smooth between ridges.
        "plastic-sheet" => {
            let l = 1.5 * std::f64::consts::SQRT_2;
            Surface::new(
                0.13,
                &periodic(&[(l, 0.40, 0.0), (l / 3.0, 0.13, 0.0), (l / 5.0, 0.08, 0.0)]),
                rough(0.02, 0.3, 5.0, 0.5, 16, 15),
                0.04 * MM,
            )
        }
        // Random folds of 3–5 mm (a characteristic fold size), large; thick
        // paper, fairly stiff.
        "scrunched-paper" => Surface::new(0.18, &[], rough(0.30, 3.0, 5.0, 0.0, 48, 16), 0.1 * MM),
        // An almost perfect 5 mm sinusoid (§6.3, Fig. 6.5), a faint harmonic.
        "rippled-paper" => Surface::new(
            0.17,
            &periodic(&[(5.0, 0.50, 0.0), (2.5, 0.06, 0.5)]),
            rough(0.04, 0.5, 10.0, 0.5, 24, 17),
            0.1 * MM,
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_has_a_surface_and_friction_in_range() {
        for n in NAMES {
            let s = sample(n).unwrap();
            assert!((0.1..0.3).contains(&s.mu), "{n}");
            assert!(s.components.iter().map(|c| c.amplitude.abs()).sum::<f64>() <= 0.9 + 1e-12, "{n}");
        }
        assert!(sample("velvet").is_none());
    }
}
