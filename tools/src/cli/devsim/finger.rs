//! The emulator's virtual finger: a deterministic side-to-side scan.
//!
//! The finger slides along x between `x0` and `x0 + travel` at a constant
//! speed, turning round at each end (a triangle wave in position, a square
//! wave in velocity), at a fixed y, pressing with a load that breathes
//! slowly (±10 % at 0.5 Hz) around its mean — close enough to a person
//! scanning a texture for the chain to see changing velocity and load.

/// The scan.
#[derive(Debug, Clone, Copy)]
pub struct Finger {
    /// Start of the scanned stretch, m.
    pub x0: f64,
    /// Length of the stretch, m (> 0).
    pub travel: f64,
    /// Sliding speed, m/s (> 0).
    pub speed: f64,
    /// Fixed y, m.
    pub y: f64,
    /// Mean load, N.
    pub load: f64,
}

/// Where the finger is at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerState {
    /// Position along x, m.
    pub x: f64,
    /// Position along y, m.
    pub y: f64,
    /// Velocity along x, m/s.
    pub velocity: f64,
    /// Normal load, N.
    pub load: f64,
}

impl Finger {
    /// The finger at time `t` (s).
    pub fn at(&self, t: f64) -> FingerState {
        let period = 2.0 * self.travel / self.speed;
        let phase = (t / period).rem_euclid(1.0) * 2.0; // 0..2: out and back
        let (x, velocity) = if phase < 1.0 {
            (self.x0 + self.travel * phase, self.speed)
        } else {
            (self.x0 + self.travel * (2.0 - phase), -self.speed)
        };
        let load = self.load * (1.0 + 0.1 * (2.0 * std::f64::consts::PI * 0.5 * t).sin());
        FingerState { x, y: self.y, velocity, load }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scan_is_a_triangle_at_constant_speed() {
        let f = Finger { x0: 0.01, travel: 0.08, speed: 0.05, y: 0.03, load: 0.8 };
        assert_eq!(f.at(0.0).x, 0.01);
        assert!((f.at(0.8).x - 0.05).abs() < 1e-12);
        assert!((f.at(1.6).x - 0.09).abs() < 1e-9);
        assert!((f.at(2.4).x - 0.05).abs() < 1e-9);
        assert!((f.at(3.2).x - 0.01).abs() < 1e-9, "back after 2·travel/speed");
        assert_eq!(f.at(0.5).velocity, 0.05);
        assert_eq!(f.at(2.0).velocity, -0.05);
        for k in 0..1000 {
            let s = f.at(k as f64 * 0.01);
            assert!((0.01 - 1e-12..=0.09 + 1e-12).contains(&s.x) && (0.72 - 1e-12..=0.88 + 1e-12).contains(&s.load));
        }
    }
}
