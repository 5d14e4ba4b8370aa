//! Scores of an estimated actuation against the reference (dissertation
//! Fig. 5.4 compares the closed-loop estimate with the reference PRBS9).
//!
//! A binary reference has two levels; "sign" below means the side of the
//! level midway between them — the sign itself for a ±c excitation, on or
//! off for a 0/c one.

use super::model::ClosedLoopScore;
use crate::wide_sum::SumSq;

/// The level midway between the reference's extremes (0 for ±c).
fn midpoint(reference: &[f64]) -> f64 {
    let (lo, hi) = reference
        .iter()
        .filter(|r| r.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| (lo.min(r), hi.max(r)));
    if lo.is_finite() && hi.is_finite() {
        let mid = 0.5 * (lo + hi);
        // lo + hi overflows for a reference near f64::MAX.
        if mid.is_finite() {
            mid
        } else {
            0.5 * lo + 0.5 * hi
        }
    } else {
        0.0
    }
}

/// Level ("sign") agreement and RMS error of `est` against `reference`,
/// over the samples where the reference is not at its midpoint (the level
/// of a binary excitation is what is compared; RMS over the same samples,
/// its squares scaled where they would overflow, so a finite estimate and
/// reference give a finite RMS — cut at f64::MAX if it lies beyond).
/// `None` when no sample qualifies or the lengths differ.
pub fn score(est: &[f64], reference: &[f64]) -> Option<ClosedLoopScore> {
    if est.len() != reference.len() {
        return None;
    }
    let mid = midpoint(reference);
    let (mut n, mut agree, mut sq) = (0usize, 0usize, SumSq::<f64>::default());
    for (&e, &r) in est.iter().zip(reference) {
        if r == mid || !r.is_finite() {
            continue;
        }
        n += 1;
        if (e - mid) * (r - mid) > 0.0 {
            agree += 1;
        }
        sq.add_diff(e, r);
    }
    (n > 0).then(|| ClosedLoopScore {
        sign_agreement: agree as f64 / n as f64,
        transition_agreement: transition_agreement(est, reference).unwrap_or(f64::NAN),
        rms: sq.root_mean(n as f64).saturated().0,
        samples: n,
    })
}

/// Fraction of transitions of `reference` (samples where it crosses its
/// midpoint) that `est` reproduces, and fraction of non-transitions it
/// keeps — for a ±c excitation the part an even (square-law) display makes
/// visible independently of the global sign.
pub fn transition_agreement(est: &[f64], reference: &[f64]) -> Option<f64> {
    if est.len() != reference.len() || est.len() < 2 {
        return None;
    }
    let mid = midpoint(reference);
    let n = est.len() - 1;
    let cross = |x: &[f64], i: usize| (x[i] - mid) * (x[i - 1] - mid) < 0.0;
    let agree = (1..est.len()).filter(|&i| cross(reference, i) == cross(est, i)).count();
    Some(agree as f64 / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_count_signs_and_errors() {
        let r = [1.0, -1.0, 1.0, -1.0];
        let s = score(&[0.9, -0.8, -0.2, -1.0], &r).unwrap();
        assert_eq!(s.sign_agreement, 0.75);
        let want = ((0.01 + 0.04 + 1.44 + 0.0) / 4.0f64).sqrt();
        assert!((s.rms - want).abs() < 1e-15);
        // A zero estimate agrees with nothing.
        assert_eq!(score(&[0.0; 4], &r).unwrap().sign_agreement, 0.0);
        assert!(score(&[1.0], &r).is_none());
        assert!(score(&[1.0], &[0.0]).is_none());
        // The global sign is invisible to transitions.
        let flipped: Vec<f64> = r.iter().map(|v| -v).collect();
        assert_eq!(transition_agreement(&flipped, &r), Some(1.0));
        assert_eq!(score(&flipped, &r).unwrap().sign_agreement, 0.0);
    }

    #[test]
    fn a_reference_near_max_gives_a_finite_rms() {
        // Steps to ±1e300 and ±f64::MAX: the plain squares overflowed (rms inf).
        for big in [1e300, f64::MAX] {
            let r = [big, big, -big, -big];
            let s = score(&[0.5; 4], &r).unwrap();
            assert!((s.rms - big).abs() <= 1e-15 * big, "{:e} vs {big:e}", s.rms);
            assert_eq!((s.samples, s.sign_agreement), (4, 0.5));
        }
        // A constant reference of MAX: its midpoint is MAX, not inf.
        assert_eq!(midpoint(&[f64::MAX, f64::MAX]), f64::MAX);
    }

    #[test]
    fn a_unipolar_reference_is_scored_by_its_level() {
        // 0/1 levels: the midpoint 0.5 splits on from off.
        let r = [0.0, 1.0, 1.0, 0.0, 1.0];
        let s = score(&[0.1, 0.8, 0.4, 0.45, 0.9], &r).unwrap();
        assert_eq!(s.samples, 5);
        assert_eq!(s.sign_agreement, 0.8);
        // The reference crosses 0.5 at 1, 3 and 4, the estimate at 1, 2 and 4.
        assert_eq!(transition_agreement(&[0.1, 0.8, 0.4, 0.45, 0.9], &r), Some(0.5));
        // Shifted and scaled copies of a ±1 reference score alike.
        let pm = [-1.0, 1.0, 1.0, -1.0, 1.0];
        let e = [-0.8, 0.6, -0.2, -0.1, 0.8];
        let shifted: Vec<f64> = e.iter().map(|x| 0.5 + 0.5 * x).collect();
        assert_eq!(score(&e, &pm).unwrap().sign_agreement, score(&shifted, &r).unwrap().sign_agreement);
    }
}
