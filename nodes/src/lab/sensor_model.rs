//! The force sensor and its acquisition as a plain model: a second-order
//! resonance (the pen's mass on the sensor's stiffness, unit DC gain), a DC
//! bias that depends on the direction of motion (dissertation §5.1.1: "the
//! different DC biases the force sensor encountered during moving left or
//! right") and settles after each reversal, slow thermal drift, white noise,
//! clipping at full scale and uniform quantization to the converter's bits.
//!
//! ```text
//! ẍ + 2ζω ẋ + ω² x = ω² F_surface,   y = Q(clip(x + b(dir) + drift + noise))
//! ```

use super::integrator::{Lti, Method};
use super::noise::Ou;
use super::profile::LabProfile;
use crate::rng::Rng;

/// Speed above which the sensor counts as moving in a direction, m/s.
pub const V_DIR: f64 = 1e-4;

/// The sensor model and its state.
#[derive(Debug, Clone)]
pub struct SensorModel {
    lti: Lti,
    substeps: usize,
    omega: f64,
    bias_right: f64,
    bias_left: f64,
    a_bias: f64,
    noise: f64,
    lsb: f64,
    full_scale: f64,
    rng: Rng,
    drift: Ou,
    x: [f64; 2],
    bias: f64,
    dir: i8,
    /// Input samples that were NaN or infinite (read as 0).
    pub bad_inputs: u64,
    /// Times the resonator was reset after diverging (explicit methods only).
    pub diverged: u64,
}

impl SensorModel {
    /// The sensor of `profile` sampled at `rate` Hz; `noise` scales the
    /// random terms; `seed` seeds them.
    pub fn new(
        profile: &LabProfile,
        rate: f64,
        method: Method,
        substeps: usize,
        noise: f64,
        seed: u64,
    ) -> Result<Self, String> {
        profile.validate()?;
        let s = &profile.sensor;
        let h = 1.0 / rate;
        let w = 2.0 * std::f64::consts::PI * s.resonance_hz;
        let hs = h / substeps.max(1) as f64;
        let lti = Lti::new(vec![0.0, 1.0, -w * w, -2.0 * s.damping_ratio * w], vec![0.0, w * w], 2, 1, hs, method)?;
        let noise = noise.max(0.0);
        let mut m = Self {
            lti,
            substeps: substeps.max(1),
            omega: w,
            bias_right: s.bias_right_n,
            bias_left: s.bias_left_n,
            a_bias: (-h / s.bias_time_s).exp(),
            noise: s.noise_n * noise,
            lsb: 2.0 * s.full_scale_n / 2f64.powi(s.bits as i32),
            full_scale: s.full_scale_n,
            rng: Rng::substream(seed, 11),
            drift: Ou::new(s.drift_n * noise, s.drift_time_s, h, Rng::substream(seed, 12)),
            x: [0.0; 2],
            bias: 0.0,
            dir: 0,
            bad_inputs: 0,
            diverged: 0,
        };
        m.reset();
        Ok(m)
    }

    /// Back to t = 0: at rest, zeroed (no bias), noise replayed.
    pub fn reset(&mut self) {
        self.rng.reset();
        self.drift.reset();
        self.x = [0.0; 2];
        self.bias = 0.0;
        self.dir = 0;
        self.bad_inputs = 0;
        self.diverged = 0;
    }

    /// The converter's step, N.
    pub fn lsb(&self) -> f64 {
        self.lsb
    }

    /// Energy of the resonator ½(ω²x² + ẋ²) per unit mass-equivalent.
    pub fn energy(&self) -> f64 {
        0.5 * (self.omega * self.omega * self.x[0] * self.x[0] + self.x[1] * self.x[1])
    }

    /// Sets the resonator state; for tests.
    pub fn set_state(&mut self, x: f64, xd: f64) {
        self.x = [x, xd];
    }

    /// The resonator's output before bias, noise and quantization, N.
    pub fn mechanical(&self) -> f64 {
        self.x[0]
    }

    /// One sample: surface force `f` N and velocity `v` m/s held over the
    /// sample; returns the acquired force at its end, N.
    pub fn step(&mut self, f: f64, v: f64) -> f64 {
        let f = if f.is_finite() {
            f
        } else {
            self.bad_inputs += 1;
            0.0
        };
        let v = if v.is_finite() { v } else { 0.0 };
        if v > V_DIR {
            self.dir = 1;
        } else if v < -V_DIR {
            self.dir = -1;
        }
        let target = match self.dir {
            1 => self.bias_right,
            -1 => self.bias_left,
            _ => 0.0,
        };
        self.bias = target + (self.bias - target) * self.a_bias;
        for _ in 0..self.substeps {
            self.lti.step(&mut self.x, &[f]);
        }
        if !self.x.iter().all(|s| s.is_finite() && s.abs() < 1e6) {
            self.diverged += 1;
            self.x = [0.0; 2];
        }
        let drift = self.drift.step();
        let noise = if self.noise > 0.0 { self.noise * self.rng.gaussian() } else { 0.0 };
        let y = (self.x[0] + self.bias + drift + noise).clamp(-self.full_scale, self.full_scale - self.lsb);
        (y / self.lsb).round() * self.lsb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::testutil::{mean, shipped};

    fn noiseless(p: &LabProfile, rate: f64, method: Method, substeps: usize) -> SensorModel {
        SensorModel::new(p, rate, method, substeps, 0.0, 1).unwrap()
    }

    #[test]
    fn step_response_is_the_damped_oscillators() {
        // x(t) = 1 − e^{−ζωt}(cos ω_d t + ζ/√(1−ζ²) sin ω_d t) for a unit step,
        // exactly at the samples (the held input is the step itself).
        let mut p = LabProfile::default();
        p.sensor.bias_right_n = 0.0;
        p.sensor.bits = 32.0;
        for (f0, rate) in [(1500.0, 10_000.0), (1500.0, 1000.0), (150_000.0, 1000.0)] {
            p.sensor.resonance_hz = f0;
            let mut s = noiseless(&p, rate, Method::Exact, 1);
            let (w, z) = (2.0 * std::f64::consts::PI * f0, p.sensor.damping_ratio);
            let wd = w * (1.0 - z * z).sqrt();
            for n in 1..200 {
                s.step(1.0, 0.0);
                let t = n as f64 / rate;
                let want = 1.0 - (-z * w * t).exp() * ((wd * t).cos() + z / (1.0 - z * z).sqrt() * (wd * t).sin());
                assert!((s.mechanical() - want).abs() < 1e-9, "f0 {f0} rate {rate} n {n}");
            }
        }
    }

    #[test]
    fn bias_depends_on_direction_and_quantization_on_bits() {
        let p = LabProfile::default();
        let mut s = noiseless(&p, 1000.0, Method::Exact, 4);
        assert_eq!(s.step(0.0, 0.0), 0.0, "tared at rest");
        let right: Vec<f64> = (0..500).map(|_| s.step(0.0, 0.05)).collect();
        let left: Vec<f64> = (0..500).map(|_| s.step(0.0, -0.05)).collect();
        let (r, l) = (mean(&right[300..]), mean(&left[300..]));
        assert!((r - p.sensor.bias_right_n).abs() <= s.lsb(), "right bias {r}");
        assert!((l - p.sensor.bias_left_n).abs() <= s.lsb(), "left bias {l}");
        // Every output is a whole number of converter steps: 24 N / 2¹⁶.
        assert!((s.lsb() - 24.0 / 65536.0).abs() < 1e-15);
        for y in right.iter().chain(&left) {
            assert!(((y / s.lsb()) - (y / s.lsb()).round()).abs() < 1e-9);
        }
        // Clipped at full scale.
        let mut s = noiseless(&p, 1000.0, Method::Exact, 4);
        let big: Vec<f64> = (0..200).map(|_| s.step(1e3, 0.0)).collect();
        assert!(big.iter().all(|y| y.abs() <= p.sensor.full_scale_n));
    }

    #[test]
    fn noise_has_the_profile_rms_and_is_seeded() {
        let mut p = LabProfile::default();
        p.sensor.drift_n = 0.0;
        let run = |seed| {
            let mut s = SensorModel::new(&p, 1000.0, Method::Exact, 1, 1.0, seed).unwrap();
            (0..20_000).map(|_| s.step(0.5, 0.0)).collect::<Vec<f64>>()
        };
        let y = run(5);
        let m = mean(&y[100..]);
        let sd = (y[100..].iter().map(|v| (v - m).powi(2)).sum::<f64>() / (y.len() - 100) as f64).sqrt();
        // Quantization adds lsb²/12 to the variance.
        let want = (p.sensor.noise_n.powi(2) + (24.0f64 / 65536.0).powi(2) / 12.0).sqrt();
        assert!((sd / want - 1.0).abs() < 0.03, "rms {sd} vs {want}");
        assert!((m - 0.5).abs() < 1e-3);
        assert_eq!(y, run(5));
        assert_ne!(y, run(6));
    }

    #[test]
    fn resonator_is_passive_and_explicit_euler_fails_when_stiff() {
        let p = shipped("stiff");
        let mut s = noiseless(&p, 1000.0, Method::Exact, 1);
        s.set_state(1.0, 0.0);
        let mut e = s.energy();
        for _ in 0..100 {
            s.step(0.0, 0.0);
            assert!(s.energy() <= e * (1.0 + 1e-12));
            e = s.energy();
        }
        let mut s = noiseless(&p, 1000.0, Method::Euler, 1);
        for _ in 0..100 {
            assert!(s.step(0.1, 0.05).is_finite());
        }
        assert!(s.diverged > 0);
    }
}
