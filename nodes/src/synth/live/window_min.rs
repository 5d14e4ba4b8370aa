//! The minimum of the last W samples of a stream in O(1) amortized per
//! sample, without allocating: a monotone queue (each new sample removes
//! the larger ones before it; the front is the minimum) in a fixed ring.

/// A sliding-window minimum.
#[derive(Debug, Clone)]
pub struct WindowMin {
    w: usize,
    vals: Vec<f64>,
    idx: Vec<u64>,
    head: usize,
    len: usize,
    n: u64,
}

impl WindowMin {
    /// The minimum over the last `w` samples (at least 1).
    pub fn new(w: usize) -> Self {
        let w = w.max(1);
        Self { w, vals: vec![0.0; w], idx: vec![0; w], head: 0, len: 0, n: 0 }
    }

    /// Forgets every sample.
    pub fn reset(&mut self) {
        self.head = 0;
        self.len = 0;
        self.n = 0;
    }

    /// Adds a sample (a non-finite one counts as 0) and returns the minimum
    /// of the last `w`.
    pub fn push(&mut self, x: f64) -> f64 {
        let x = if x.is_finite() { x } else { 0.0 };
        let cap = self.w;
        // Drop the front once it falls out of the window.
        if self.len > 0 && self.idx[self.head] + (self.w as u64) <= self.n {
            self.head = (self.head + 1) % cap;
            self.len -= 1;
        }
        // Drop the back while it is not smaller than x.
        while self.len > 0 {
            let back = (self.head + self.len - 1) % cap;
            if self.vals[back] >= x {
                self.len -= 1;
            } else {
                break;
            }
        }
        let at = (self.head + self.len) % cap;
        self.vals[at] = x;
        self.idx[at] = self.n;
        self.len += 1;
        self.n += 1;
        self.vals[self.head]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn equals_the_brute_force_minimum() {
        for w in [1, 2, 5, 17] {
            let mut r = Rng::new(w as u64);
            let xs: Vec<f64> = (0..500).map(|k| if k % 50 < 10 { 1.0 } else { r.gaussian() }).collect();
            let mut m = WindowMin::new(w);
            for (n, x) in xs.iter().enumerate() {
                let got = m.push(*x);
                let want = xs[n.saturating_sub(w - 1)..=n].iter().cloned().fold(f64::INFINITY, f64::min);
                assert_eq!(got, want, "w {w} n {n}");
            }
            m.reset();
            assert_eq!(m.push(3.0), 3.0);
        }
        let mut m = WindowMin::new(3);
        assert_eq!(m.push(f64::NAN), 0.0);
    }
}
