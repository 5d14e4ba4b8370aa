//! The virtual finger's motion: side-to-side strokes over a travel with a
//! speed and a pressure that wander like a person's.
//!
//! Each stroke picks a cruising speed and a target mass uniformly within
//! their ranges; during the stroke both drift by Ornstein–Uhlenbeck noise
//! (correlation time `wander_s`, rms 15 % of the range) and stay inside the
//! ranges. A stroke starts from rest with a raised-cosine acceleration over
//! half the reversal time, cruises, and brakes with a raised-cosine
//! deceleration that starts exactly when the distance left equals the
//! braking distance at the current speed (v·T/4 for a raised cosine of
//! length T/2), so the finger stops at the end of the travel and turns.
//! A speed range of 0 leaves the finger at rest at the left end.

use crate::lab::noise::Ou;
use crate::rng::Rng;

/// Standard gravity, m/s² (mass in g → load in N).
pub const G: f64 = 9.806_65;

/// Settings of the finger (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerSettings {
    /// Length of a stroke, m.
    pub travel: f64,
    /// Cruising speed range, m/s.
    pub speed: (f64, f64),
    /// Mass range (load / g), kg.
    pub mass: (f64, f64),
    /// Time of a full reversal (stop and restart), s.
    pub reversal: f64,
    /// Correlation time of the speed and pressure drift, s.
    pub wander: f64,
    /// Sample period, s.
    pub h: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Speeding up from rest: time into the phase.
    Accel(f64),
    Cruise,
    /// Braking: steps taken, steps in all, initial speed.
    Decel(u32, u32, f64),
}

/// The finger's state.
#[derive(Debug, Clone)]
pub struct Finger {
    s: FingerSettings,
    rng: Rng,
    speed_drift: Ou,
    mass_drift: Ou,
    phase: Phase,
    /// Position along the stroke from the left end, m.
    pub position: f64,
    /// Direction of the current stroke: +1 rightward, −1 leftward.
    dir: f64,
    /// Signed velocity of the last step (mean over the step), m/s.
    pub velocity: f64,
    /// Cruising speed and target mass of this stroke.
    cruise: f64,
    target_mass: f64,
    /// Current mass, kg.
    pub mass: f64,
}

impl Finger {
    /// A finger at rest at the left end; `seed` fixes its strokes.
    pub fn new(s: FingerSettings, seed: u64) -> Self {
        let mut f = Finger {
            s,
            rng: Rng::substream(seed, 1),
            speed_drift: Ou::new(0.15 * (s.speed.1 - s.speed.0), s.wander, s.h, Rng::substream(seed, 2)),
            mass_drift: Ou::new(0.15 * (s.mass.1 - s.mass.0), s.wander, s.h, Rng::substream(seed, 3)),
            phase: Phase::Accel(0.0),
            position: 0.0,
            dir: 1.0,
            velocity: 0.0,
            cruise: 0.0,
            target_mass: 0.0,
            mass: 0.0,
        };
        f.new_stroke();
        f.mass = f.target_mass;
        f
    }

    fn uniform_in(&mut self, (lo, hi): (f64, f64)) -> f64 {
        lo + (hi - lo) * self.rng.uniform()
    }

    fn new_stroke(&mut self) {
        self.cruise = self.uniform_in(self.s.speed);
        self.target_mass = self.uniform_in(self.s.mass);
        self.phase = Phase::Accel(0.0);
    }

    /// Load on the surface, N.
    pub fn load(&self) -> f64 {
        self.mass * G
    }

    /// Speed the finger aims at now (cruise plus drift, inside the range).
    fn aim(&self) -> f64 {
        (self.cruise + self.speed_drift.value()).clamp(self.s.speed.0, self.s.speed.1)
    }

    /// Advances one sample.
    pub fn step(&mut self) {
        let h = self.s.h;
        let half = 0.5 * self.s.reversal.max(2.0 * h);
        self.speed_drift.step();
        self.mass_drift.step();
        let m_aim = (self.target_mass + self.mass_drift.value()).clamp(self.s.mass.0, self.s.mass.1);
        // Pressure follows its aim with the same correlation time (no jumps between strokes).
        let a = (h / self.s.wander.max(h)).min(1.0);
        self.mass += a * (m_aim - self.mass);

        let left = if self.dir > 0.0 { self.s.travel - self.position } else { self.position };
        let speed_now = self.velocity.abs();
        // Brake when the raised cosine from the current speed v over the
        // nominal T/2 (N steps) would just cover the distance left — it
        // covers v·h·(N − 1)/2, since Σ_{i=1..N} cos(πi/N) = −1 — with the
        // step count rounded up and the initial speed scaled down (by at
        // most a step's worth) so that it ends exactly at the end.
        let n_nom = (half / h).round().max(2.0);
        if !matches!(self.phase, Phase::Decel(..)) && speed_now > 0.0 && left <= speed_now * h * 0.5 * (n_nom - 1.0) {
            let n = ((2.0 * left / (speed_now * h)).ceil() + 1.0).clamp(2.0, n_nom);
            let v0 = (2.0 * left / (h * (n - 1.0))).min(speed_now);
            self.phase = Phase::Decel(0, n as u32, v0);
        }
        let speed = match self.phase {
            Phase::Accel(t) => {
                let t = t + h;
                let v = self.aim() * 0.5 * (1.0 - (std::f64::consts::PI * (t / half).min(1.0)).cos());
                self.phase = if t >= half { Phase::Cruise } else { Phase::Accel(t) };
                v
            }
            Phase::Cruise => self.aim(),
            Phase::Decel(i, n, v0) => {
                let i = i + 1;
                self.phase = Phase::Decel(i, n, v0);
                v0 * 0.5 * (1.0 + (std::f64::consts::PI * (i.min(n) as f64 / n as f64)).cos())
            }
        };
        let before = self.position;
        self.position = (self.position + self.dir * speed * h).clamp(0.0, self.s.travel);
        self.velocity = (self.position - before) / h;
        let stopped = matches!(self.phase, Phase::Decel(i, n, _) if i >= n);
        let at_end = if self.dir > 0.0 { self.position >= self.s.travel } else { self.position <= 0.0 };
        if stopped || (at_end && self.aim() > 0.0 && !matches!(self.phase, Phase::Accel(_))) {
            self.dir = -self.dir;
            self.new_stroke();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(speed: (f64, f64), mass: (f64, f64)) -> FingerSettings {
        FingerSettings { travel: 0.08, speed, mass, reversal: 0.1, wander: 1.0, h: 1e-3 }
    }

    fn run(s: FingerSettings, seconds: f64, seed: u64) -> Vec<(f64, f64, f64)> {
        let mut f = Finger::new(s, seed);
        (0..(seconds / s.h) as usize)
            .map(|_| {
                f.step();
                (f.position, f.velocity, f.load())
            })
            .collect()
    }

    #[test]
    fn strokes_stay_on_the_travel_within_the_ranges_and_reverse() {
        let s = settings((0.03, 0.07), (0.06, 0.11));
        let v = run(s, 30.0, 1);
        let mut reversals = 0;
        for w in v.windows(2) {
            assert!((0.0..=0.08).contains(&w[1].0));
            assert!(w[1].1.abs() <= 0.07 + 1e-9, "{}", w[1].1);
            assert!(w[1].2 >= 0.06 * G - 1e-9 && w[1].2 <= 0.11 * G + 1e-9);
            if w[0].1 * w[1].1 < 0.0 || (w[0].1 != 0.0 && w[1].1 == 0.0) {
                reversals += 1;
            }
        }
        // 8 cm at 3–7 cm/s: a stroke takes 1.2–2.8 s.
        assert!((10..=30).contains(&reversals), "{reversals}");
        // Cruising speeds cover the range: some strokes near 3, some near 7 cm/s.
        let fast = v.iter().filter(|p| p.1.abs() > 0.06).count();
        let slow = v.iter().filter(|p| p.1.abs() > 0.025 && p.1.abs() < 0.04).count();
        assert!(fast > 100 && slow > 100, "{fast} {slow}");
        // It reaches both ends.
        assert!(v.iter().any(|p| p.0 > 0.0799) && v.iter().filter(|p| p.0 < 1e-4).count() > 1);
    }

    #[test]
    fn the_velocity_is_the_derivative_of_the_position_and_smooth() {
        let s = settings((0.03, 0.07), (0.06, 0.11));
        let v = run(s, 10.0, 2);
        for w in v.windows(2) {
            assert!(((w[1].0 - w[0].0) / 1e-3 - w[1].1).abs() < 1e-9);
            // Raised-cosine reversals: |a| ≤ π/2 · v_max / (T/2) = 2.2 m/s².
            assert!(((w[1].1 - w[0].1) / 1e-3).abs() < 2.3, "{:?}", w);
        }
    }

    #[test]
    fn same_seed_same_finger_other_seed_other_finger() {
        let s = settings((0.03, 0.07), (0.06, 0.11));
        assert_eq!(run(s, 3.0, 5), run(s, 3.0, 5));
        assert_ne!(run(s, 3.0, 5), run(s, 3.0, 6));
    }

    #[test]
    fn extremes_stay_finite_and_bounded() {
        for (speed, mass) in [((0.0, 0.0), (0.001, 0.001)), ((0.5, 0.5), (1.0, 1.0)), ((0.0, 0.5), (0.001, 1.0))] {
            let v = run(settings(speed, mass), 5.0, 3);
            for p in &v {
                assert!(p.0.is_finite() && p.1.is_finite() && p.2.is_finite());
                assert!((0.0..=0.08).contains(&p.0) && p.1.abs() <= speed.1 + 1e-9);
            }
            if speed.1 == 0.0 {
                assert!(v.iter().all(|p| p.0 == 0.0 && p.1 == 0.0));
            } else {
                assert!(v.iter().any(|p| p.0 > 0.079), "{speed:?} reaches the right end");
            }
        }
    }
}
