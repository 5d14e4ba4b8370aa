//! Gain matching (dissertation §5.3.2, Table 5.1): every method's actuation
//! is played at each gain of the sweep, and a gain is chosen per method by
//! the same rule.
//!
//! * **Table 5.1's rule**: the gain whose largest power density is nearest
//!   the real force's ("almost the same maximum magnitude of power
//!   density"): the `metric` node's `peak_psd_ratio` nearest 1 on a log
//!   scale.
//! * **Best E_s**: the gain with the lowest E_s — the second reading, an
//!   upper bound on what any gain rule could give a method.

/// One method's scores at one gain.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AtGain {
    /// The gain.
    #[serde(with = "super::exact")]
    pub gain: f64,
    /// E_s, rectangular one-second segments (the dissertation's reading).
    #[serde(with = "super::exact")]
    pub rect: f64,
    /// E_s, Hann-windowed half-overlapping segments (Welch's reading).
    #[serde(with = "super::exact")]
    pub welch: f64,
    /// Virtual over real peak power density (rect spectra).
    #[serde(with = "super::exact")]
    pub peak_ratio: f64,
}

/// The chosen gains of one method.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Chosen {
    /// By Table 5.1's rule.
    pub table51: AtGain,
    /// The lowest rect E_s over the sweep.
    pub best_rect: AtGain,
    /// The lowest Welch E_s over the sweep.
    pub best_welch: AtGain,
}

/// Chooses among `sweep` (at least one entry).
pub fn choose(sweep: &[AtGain]) -> Option<Chosen> {
    let first = *sweep.first()?;
    let mut c = Chosen { table51: first, best_rect: first, best_welch: first };
    for s in &sweep[1..] {
        if s.peak_ratio.ln().abs() < c.table51.peak_ratio.ln().abs() {
            c.table51 = *s;
        }
        if s.rect < c.best_rect.rect {
            c.best_rect = *s;
        }
        if s.welch < c.best_welch.welch {
            c.best_welch = *s;
        }
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(gain: f64, rect: f64, welch: f64, peak_ratio: f64) -> AtGain {
        AtGain { gain, rect, welch, peak_ratio }
    }

    #[test]
    fn table_51_matches_peak_power_on_a_log_scale_and_best_takes_the_lowest() {
        // Ratios 0.3, 0.8, 1.5, 3: |ln| = 1.20, 0.22, 0.41, 1.10 → 0.8 wins,
        // although 1.5 is nearer 1 on a linear scale than 0.3 is.
        let sweep = [at(0.6, 0.9, 0.5, 0.3), at(0.8, 0.5, 0.6, 0.8), at(1.0, 0.4, 0.7, 1.5), at(1.2, 0.7, 0.4, 3.0)];
        let c = choose(&sweep).unwrap();
        assert_eq!(c.table51.gain, 0.8);
        assert_eq!(c.best_rect.gain, 1.0);
        assert_eq!(c.best_welch.gain, 1.2);
        assert!(choose(&[]).is_none());
    }
}
