//! Sample times across ports at different rates, exactly.
//!
//! Every port rate is an integer multiple or divisor of the base rate
//! ([`Ratio`]): sample k of a port at ratio (mul, div) falls at base tick
//! k·div/mul. Nodes whose ports run at different rates use these to decide,
//! the same way whatever the block size, which samples of one port come at
//! or before a sample of another.

use evflow_engine::rate::Ratio;
use evflow_engine::NodeError;

/// The rate of a port, as a ratio to the base rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    mul: u64,
    div: u64,
}

impl Clock {
    /// The clock of a port at `rate` Hz in a graph whose base rate is `base` Hz.
    pub fn new(rate: f64, base: f64, port: &str) -> Result<Self, NodeError> {
        let r = Ratio::of(rate, base).ok_or_else(|| {
            NodeError::Other(format!(
                "port `{port}` runs at {rate} Hz, not an integer multiple or divisor of the base rate {base} Hz"
            ))
        })?;
        Ok(Self { mul: r.mul, div: r.div })
    }

    /// True when sample `k` of this clock falls at or before sample `l` of `other`.
    #[inline]
    pub fn at_or_before(&self, k: u64, other: &Clock, l: u64) -> bool {
        (k as u128) * (self.div as u128) * (other.mul as u128) <= (l as u128) * (other.div as u128) * (self.mul as u128)
    }

    /// True when sample `k` of this clock falls strictly before sample `l` of `other`.
    #[inline]
    pub fn before(&self, k: u64, other: &Clock, l: u64) -> bool {
        (k as u128) * (self.div as u128) * (other.mul as u128) < (l as u128) * (other.div as u128) * (self.mul as u128)
    }

    /// Samples per second relative to the base rate, mul/div.
    pub fn ratio(&self) -> f64 {
        self.mul as f64 / self.div as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_samples_of_different_rates() {
        let fast = Clock::new(20_000.0, 1000.0, "t").unwrap();
        let slow = Clock::new(40.0, 1000.0, "v").unwrap();
        // 40 Hz sample 4 is at tick 100 = 20 kHz sample 2000.
        assert!(slow.at_or_before(4, &fast, 2000));
        assert!(!slow.before(4, &fast, 2000));
        assert!(slow.before(4, &fast, 2001));
        assert!(!slow.at_or_before(5, &fast, 2400));
        assert!(Clock::new(333.0, 1000.0, "x").is_err());
    }
}
