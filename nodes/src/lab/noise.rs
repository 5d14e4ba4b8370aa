//! Coloured noise for the lab: the Ornstein–Uhlenbeck process, sampled
//! exactly (`x[n+1] = a·x[n] + σ·√(1−a²)·z`, `a = e^{−h/τ}`), so its variance is
//! σ² at every step size (Gillespie, "Exact numerical simulation of the
//! Ornstein–Uhlenbeck process and its integral", Phys. Rev. E 54, 1996).

use crate::rng::Rng;

/// A stationary Ornstein–Uhlenbeck process with its own random stream.
#[derive(Debug, Clone)]
pub struct Ou {
    a: f64,
    b: f64,
    sigma: f64,
    x: f64,
    rng: Rng,
}

impl Ou {
    /// Rms `sigma`, correlation time `tau` s, sampled every `h` s, drawing
    /// from `rng`. Starts from a stationary draw.
    pub fn new(sigma: f64, tau: f64, h: f64, rng: Rng) -> Self {
        let a = (-h / tau).exp();
        let mut ou = Self { a, b: sigma * (1.0 - a * a).max(0.0).sqrt(), sigma, x: 0.0, rng };
        ou.reset();
        ou
    }

    /// Back to t = 0: the same stream, the same first value.
    pub fn reset(&mut self) {
        self.rng.reset();
        self.x = if self.sigma > 0.0 { self.sigma * self.rng.gaussian() } else { 0.0 };
    }

    /// The current value.
    pub fn value(&self) -> f64 {
        self.x
    }

    /// Advances one step and returns the new value.
    pub fn step(&mut self) -> f64 {
        if self.sigma > 0.0 {
            self.x = self.a * self.x + self.b * self.rng.gaussian();
        }
        self.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variance_and_correlation_match_the_process() {
        let (sigma, tau, h) = (0.5, 0.01, 0.001);
        let mut ou = Ou::new(sigma, tau, h, Rng::new(3));
        let n = 400_000;
        let (mut s2, mut lag1, mut prev) = (0.0, 0.0, ou.value());
        for _ in 0..n {
            let x = ou.step();
            s2 += x * x;
            lag1 += x * prev;
            prev = x;
        }
        let var = s2 / n as f64;
        let rho = lag1 / s2;
        assert!((var / (sigma * sigma) - 1.0).abs() < 0.05, "variance {var}");
        assert!((rho - (-h / tau).exp()).abs() < 0.01, "lag-1 correlation {rho}");
    }

    #[test]
    fn zero_sigma_is_silent_and_reset_replays() {
        let mut z = Ou::new(0.0, 1.0, 1e-3, Rng::new(1));
        assert!((0..100).all(|_| z.step() == 0.0));
        let mut o = Ou::new(1.0, 0.1, 1e-3, Rng::new(9));
        let a: Vec<f64> = (0..50).map(|_| o.step()).collect();
        o.reset();
        let b: Vec<f64> = (0..50).map(|_| o.step()).collect();
        assert_eq!(a, b);
    }
}
