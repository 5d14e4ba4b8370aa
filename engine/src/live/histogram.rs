//! A fixed-resolution histogram of durations (1 µs buckets up to 20 ms, an
//! exact maximum above), filled off the real-time thread.

/// Bucket width in nanoseconds.
const BUCKET_NS: u64 = 1_000;
/// Buckets below the overflow bucket (20 ms).
const BUCKETS: usize = 20_000;

/// Counts of durations in 1 µs buckets, with the exact largest value.
#[derive(Debug, Clone)]
pub struct Histogram {
    counts: Vec<u64>,
    overflow: u64,
    n: u64,
    max_ns: u64,
    sum_ns: u128,
}

impl Default for Histogram {
    fn default() -> Self {
        Self::new()
    }
}

/// Percentiles of a histogram, in microseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Percentiles {
    /// Samples counted.
    pub n: u64,
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// 99.9th percentile.
    pub p999: f64,
    /// Largest value (exact).
    pub max: f64,
    /// Mean (exact).
    pub mean: f64,
}

impl Histogram {
    /// An empty histogram.
    pub fn new() -> Self {
        Self { counts: vec![0; BUCKETS], overflow: 0, n: 0, max_ns: 0, sum_ns: 0 }
    }

    /// Counts one duration.
    pub fn add(&mut self, ns: u64) {
        let b = (ns / BUCKET_NS) as usize;
        match self.counts.get_mut(b) {
            Some(c) => *c += 1,
            None => self.overflow += 1,
        }
        self.n += 1;
        self.max_ns = self.max_ns.max(ns);
        self.sum_ns += ns as u128;
    }

    /// Durations counted.
    pub fn len(&self) -> u64 {
        self.n
    }

    /// True when nothing was counted.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The smallest value (µs, bucket upper edge) at or below which a
    /// fraction `q` of the durations lie; in the overflow region, the exact
    /// maximum.
    pub fn quantile_us(&self, q: f64) -> f64 {
        if self.n == 0 {
            return 0.0;
        }
        let rank = ((q * self.n as f64).ceil() as u64).clamp(1, self.n);
        let mut seen = 0;
        for (b, &c) in self.counts.iter().enumerate() {
            seen += c;
            if seen >= rank {
                // The bucket's upper edge, but never above the true maximum.
                let edge = ((b as u64 + 1) * BUCKET_NS).min(self.max_ns);
                return edge as f64 / 1e3;
            }
        }
        self.max_ns as f64 / 1e3
    }

    /// p50, p99, p99.9, max and mean.
    pub fn percentiles(&self) -> Percentiles {
        Percentiles {
            n: self.n,
            p50: self.quantile_us(0.5),
            p99: self.quantile_us(0.99),
            p999: self.quantile_us(0.999),
            max: self.max_ns as f64 / 1e3,
            mean: if self.n == 0 { 0.0 } else { self.sum_ns as f64 / self.n as f64 / 1e3 },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_a_known_distribution() {
        let mut h = Histogram::new();
        // 1..=1000 µs, one each (values at bucket centres).
        for us in 1..=1000u64 {
            h.add(us * 1000 - 500);
        }
        let p = h.percentiles();
        assert_eq!(p.n, 1000);
        assert_eq!(p.p50, 500.0);
        assert_eq!(p.p99, 990.0);
        assert_eq!(p.p999, 999.0);
        assert_eq!(p.max, 999.5);
        assert!((p.mean - 500.0).abs() < 1e-9);
    }

    #[test]
    fn overflow_reports_the_exact_maximum() {
        let mut h = Histogram::new();
        for _ in 0..10 {
            h.add(4_500);
        }
        h.add(75_000_000);
        assert_eq!(h.quantile_us(1.0), 75_000.0);
        assert_eq!(h.quantile_us(0.5), 5.0);
        assert_eq!(Histogram::new().percentiles(), Percentiles::default());
    }
}
