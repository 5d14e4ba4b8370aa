//! Training and validation data made on the simulated lab (for tests,
//! benchmarks and the figures of docs/narx.md):
//! excitations (random binary, PRBS from the `prbs` node) driven through the
//! virtual display (`sim.display`'s model) and force sensor at a constant
//! sliding speed and load, high-passed at 10 Hz as dissertation §5.1.1.

use crate::filters::butterworth::design::{butterworth, Kind};
use crate::filters::butterworth::sos::Cascade;
use crate::lab::display_model::DisplayModel;
use crate::lab::integrator::Method;
use crate::lab::profile::G;
use crate::lab::sensor_model::SensorModel;
use crate::lab::LabProfile;
use crate::rng::Rng;
use evflow_engine::harness::Single;

/// A random binary sequence ±1 (independent fair coin flips, seeded): no
/// past of it predicts its next value.
pub fn rbs(n: usize, seed: u64) -> Vec<f64> {
    let mut r = Rng::new(seed);
    (0..n).map(|_| if r.next_u64() >> 63 == 1 { 1.0 } else { -1.0 }).collect()
}

/// `n` samples of the `prbs` node of the given order (c = 1, B = 1).
pub fn prbs(order: u32, n: usize) -> Vec<f64> {
    let params = format!("order = {order}\nperiods = 100000");
    let s = Single::new(&crate::sources::prbs::SPEC, &params).output("out").ticks(n as u64).block(4096);
    s.run().expect("prbs runs").remove(0)
}

/// The experimental condition of a lab recording.
#[derive(Debug, Clone, Copy)]
pub struct Lab {
    /// Stylus mass, g.
    pub mass_g: f64,
    /// Sliding speed, cm/s.
    pub speed_cm_s: f64,
    /// Noise scale (1 = the nominal profile).
    pub noise: f64,
    /// Seed of the lab's noise.
    pub seed: u64,
}

impl Default for Lab {
    fn default() -> Self {
        Self { mass_g: 85.0, speed_cm_s: 5.0, noise: 1.0, seed: 11 }
    }
}

impl Lab {
    /// The high-passed sensor force for actuation `u` at 1 kHz: display and
    /// sensor of the nominal lab, the pen sliding at constant speed (the
    /// constant-speed segment of a tribometer pass), a 4th-order 10 Hz
    /// Butterworth high-pass (§5.1.1). The first 200 ms settle the contact
    /// and the filter with the display off and are dropped.
    pub fn force(&self, u: &[f64]) -> Vec<f64> {
        let p = LabProfile::default();
        let mut d = DisplayModel::new(&p, 1000.0, Method::Exact, 4, self.noise, self.seed).unwrap();
        let mut s = SensorModel::new(&p, 1000.0, Method::Exact, 1, self.noise, self.seed ^ 0x5a5a).unwrap();
        let mut hp = Cascade::new(&butterworth(Kind::Highpass, 4, 10.0, 1000.0).unwrap());
        let (load, v) = (self.mass_g * 1e-3 * G, self.speed_cm_s * 1e-2);
        let settle = 200;
        let mut out = Vec::with_capacity(u.len());
        for (i, a) in std::iter::repeat_n(0.0, settle).chain(u.iter().copied()).enumerate() {
            let f = hp.tick(s.step(d.step(a, load, v), v));
            if i >= settle {
                out.push(f);
            }
        }
        out
    }
}
