//! Starting actuations for the optimized synthesis.
//!
//! **The square-law envelope on a Nyquist-rate carrier.** A square-law
//! display turns an actuation a·(−1)ⁿ — a full swing every sample, held —
//! into a nearly steady extra friction κ·a² (the gap voltage follows the
//! swing through the circuit's capacitive division; its square hardly
//! moves). A slowly varying envelope a\[n\] then renders κ·a\[n\]², at the
//! envelope's own frequencies, not doubled as a force-shaped actuation
//! would be. To render the (zero-mean, high-passed) force f:
//!
//! ```text
//! u[n] = (−1)ⁿ · √( max(0, (f[n] + c) / κ) ),   c = −min f over the kept samples
//! ```
//!
//! the offset c keeps the radicand ≥ 0 with the least extra friction. κ is
//! the forward model's carrier gain ([`super::volterra::Volterra::carrier_gain`]),
//! learned from the display's recordings, not set by hand.

use super::error::SynthError;

/// The square-law envelope start for the force `f`, offset from the
/// samples where `keep` is set, carrier gain `kappa` (N), clipped to ±`bound`.
pub fn carrier(f: &[f64], keep: &[bool], kappa: f64, bound: f64) -> Result<Vec<f64>, SynthError> {
    carrier_scaled(f, keep, kappa, bound, 1.0)
}

/// [`carrier`] with the offset c scaled by `offset_scale` (below 1 the
/// troughs of the force are clipped; above 1 the carrier never falls to 0).
pub fn carrier_scaled(
    f: &[f64],
    keep: &[bool],
    kappa: f64,
    bound: f64,
    offset_scale: f64,
) -> Result<Vec<f64>, SynthError> {
    if !(kappa.is_finite() && kappa > 0.0) {
        return Err(SynthError::Data(format!(
            "the forward model's carrier gain is {kappa} N: a Nyquist-rate carrier raises no friction on this model, \
             so the square-law start is undefined (start from the inverse model or from zero)"
        )));
    }
    let c = -f.iter().zip(keep).filter(|(_, k)| **k).map(|(v, _)| *v).fold(f64::INFINITY, f64::min);
    let c = if c.is_finite() { c.max(0.0) * offset_scale.max(0.0) } else { 0.0 };
    Ok(f.iter()
        .enumerate()
        .map(|(n, &v)| {
            let a = ((v + c) / kappa).max(0.0).sqrt().min(bound);
            if n % 2 == 0 {
                a
            } else {
                -a
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_squared_times_kappa_is_the_force_plus_its_offset() {
        let f: Vec<f64> = (0..200).map(|n| 0.05 * (n as f64 * 0.1).sin()).collect();
        let keep = vec![true; 200];
        let u = carrier(&f, &keep, 0.2, 1.0).unwrap();
        let c = -f.iter().cloned().fold(f64::INFINITY, f64::min);
        for n in 0..200 {
            assert!((0.2 * u[n] * u[n] - (f[n] + c)).abs() < 1e-12);
            assert!(u[n] == 0.0 || (u[n] > 0.0) == (n % 2 == 0), "alternates");
        }
        assert!(carrier(&f, &keep, 0.0, 1.0).is_err());
        assert!(carrier(&f, &keep, -0.1, 1.0).is_err());
        // A bound clips the envelope.
        let big: Vec<f64> = f.iter().map(|v| v * 100.0).collect();
        assert!(carrier(&big, &keep, 0.2, 1.0).unwrap().iter().all(|u| u.abs() <= 1.0));
    }
}
