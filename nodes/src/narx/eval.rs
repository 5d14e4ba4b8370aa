//! Scores of an estimated actuation against the reference (dissertation
//! Fig. 5.4 compares the closed-loop estimate with the reference PRBS9).

use super::model::ClosedLoopScore;

/// Sign agreement and RMS error of `est` against `reference`, over the
/// samples where the reference is not 0 (the sign of a binary excitation
/// is what is compared; RMS over the same samples). `None` when no sample
/// qualifies or the lengths differ.
pub fn score(est: &[f64], reference: &[f64]) -> Option<ClosedLoopScore> {
    if est.len() != reference.len() {
        return None;
    }
    let (mut n, mut agree, mut sq) = (0usize, 0usize, 0.0);
    for (&e, &r) in est.iter().zip(reference) {
        if r == 0.0 || !r.is_finite() {
            continue;
        }
        n += 1;
        if e * r > 0.0 {
            agree += 1;
        }
        sq += (e - r) * (e - r);
    }
    (n > 0).then(|| ClosedLoopScore {
        sign_agreement: agree as f64 / n as f64,
        transition_agreement: transition_agreement(est, reference).unwrap_or(f64::NAN),
        rms: (sq / n as f64).sqrt(),
        samples: n,
    })
}

/// Fraction of transitions of `reference` (samples where its sign changes)
/// that `est` reproduces, and fraction of non-transitions it keeps — the
/// part of a binary actuation an even (square-law) display makes visible
/// independently of the global sign.
pub fn transition_agreement(est: &[f64], reference: &[f64]) -> Option<f64> {
    if est.len() != reference.len() || est.len() < 2 {
        return None;
    }
    let n = est.len() - 1;
    let agree =
        (1..est.len()).filter(|&i| (reference[i] * reference[i - 1] < 0.0) == (est[i] * est[i - 1] < 0.0)).count();
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
}
