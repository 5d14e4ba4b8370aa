//! The limiter's gate: a linear fade between 0 and 1 in a whole number of
//! samples, counted in integers so it lands on exactly 0 and exactly 1.

/// A linear envelope that moves one step of 1/`steps` per sample towards
/// open (1) or closed (0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    at: u32,
    steps: u32,
}

impl Envelope {
    /// A closed envelope (0) that takes `steps` samples (at least 1) to open
    /// or close completely.
    pub fn closed(steps: u32) -> Self {
        Self { at: 0, steps: steps.max(1) }
    }

    /// Moves one sample towards open (`true`) or closed (`false`) and
    /// returns the new level in [0, 1].
    #[inline]
    pub fn advance(&mut self, open: bool) -> f64 {
        if open {
            self.at = (self.at + 1).min(self.steps);
        } else {
            self.at = self.at.saturating_sub(1);
        }
        self.level()
    }

    /// The level in [0, 1]: exactly 0 when closed, exactly 1 when open.
    #[inline]
    pub fn level(&self) -> f64 {
        if self.at == self.steps {
            1.0
        } else {
            self.at as f64 / self.steps as f64
        }
    }

    /// True when fully closed.
    pub fn is_closed(&self) -> bool {
        self.at == 0
    }

    /// Samples a full fade takes.
    pub fn steps(&self) -> u32 {
        self.steps
    }
}

#[cfg(test)]
mod tests {
    use super::Envelope;

    #[test]
    fn opens_and_closes_in_exactly_the_given_steps() {
        let mut e = Envelope::closed(10);
        let up: Vec<f64> = (0..12).map(|_| e.advance(true)).collect();
        assert_eq!(up[9], 1.0);
        assert!(up[8] < 1.0);
        assert_eq!(up[0], 0.1);
        let down: Vec<f64> = (0..10).map(|_| e.advance(false)).collect();
        assert_eq!(down[9], 0.0);
        assert!(down[8] > 0.0);
        assert!(e.is_closed());
        // Monotone steps of exactly 1/10.
        for w in down.windows(2) {
            assert!((w[0] - w[1] - 0.1).abs() < 1e-15);
        }
    }

    #[test]
    fn one_step_envelope_switches_at_once() {
        let mut e = Envelope::closed(0);
        assert_eq!(e.steps(), 1);
        assert_eq!(e.advance(true), 1.0);
        assert_eq!(e.advance(false), 0.0);
    }
}
