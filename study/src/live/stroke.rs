//! One virtual user's strokes over one sample, as the live study's graphs
//! see them: the finger's true position, velocity and load (`sim.user`
//! with the user's seed and ranges) and the force the real sample gives it
//! (`sim.texture`) — the same numbers, sample for sample, computed here for
//! the stroke's floor, which optimizes through the display knowing them.

use super::scope::User;
use crate::StudyError;
use evflow_nodes::lab::texture::{samples, TextureScan};
use evflow_nodes::lab::user::finger::{Finger, FingerSettings};
use evflow_nodes::synth::output_filter::OutputFilter;

/// A user's strokes over a sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Sample rate, Hz.
    pub rate: f64,
    /// Finger position along the stroke, m.
    pub position: Vec<f64>,
    /// Signed finger velocity, m/s.
    pub velocity: Vec<f64>,
    /// Normal load, N.
    pub load: Vec<f64>,
    /// The real sample's friction force, N.
    pub real: Vec<f64>,
    /// The same without the base friction μ₀·N·tanh(v/v_s): the texture's
    /// own modulation of the force, N.
    pub modulation: Vec<f64>,
}

impl Stroke {
    /// `user`'s strokes over `sample` for `seconds` at `rate` Hz (the
    /// finger's reversal time and drift correlation time at `sim.user`'s
    /// defaults).
    pub fn of(user: &User, sample: &str, seconds: f64, rate: f64) -> Result<Self, StudyError> {
        let surface = samples::lookup(sample).map_err(StudyError::Config)?;
        let settings = FingerSettings {
            travel: user.travel_cm * 1e-2,
            speed: (user.speed[0] * 0.01, user.speed[1] * 0.01),
            mass: (user.mass[0] * 1e-3, user.mass[1] * 1e-3),
            reversal: 0.1,
            wander: 1.0,
            h: 1.0 / rate,
        };
        let n = (seconds * rate).round() as usize;
        let mut finger = Finger::new(settings, user.seed);
        let mut scan = TextureScan::new(surface);
        let mut s = Stroke {
            rate,
            position: Vec::with_capacity(n),
            velocity: Vec::with_capacity(n),
            load: Vec::with_capacity(n),
            real: Vec::with_capacity(n),
            modulation: Vec::with_capacity(n),
        };
        for _ in 0..n {
            finger.step();
            let (x, v, l) = (finger.position, finger.velocity, finger.load());
            let f = scan.force(x, v, l);
            s.position.push(x);
            s.velocity.push(v);
            s.load.push(l);
            s.real.push(f);
            s.modulation.push(f - scan.surface().base_force(v, l));
        }
        Ok(s)
    }

    /// Samples.
    pub fn len(&self) -> usize {
        self.real.len()
    }

    /// True for a stroke without samples.
    pub fn is_empty(&self) -> bool {
        self.real.is_empty()
    }

    /// The real force high-passed as every graph of the study high-passes
    /// it (4th-order Butterworth at 10 Hz).
    pub fn real_highpassed(&self) -> Result<Vec<f64>, StudyError> {
        let mut y = self.real.clone();
        OutputFilter::highpass(4, 10.0, self.rate)?.apply_in_place(&mut y);
        Ok(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graphs::run_graph;
    use evflow_nodes::recording::format::Recording;

    #[test]
    fn the_stroke_is_what_the_graphs_user_and_sample_give_sample_for_sample() {
        let dir = tempfile::tempdir().unwrap();
        let user = User { name: "t".into(), seed: 9, speed: [2.0, 9.0], mass: [40.0, 130.0], travel_cm: 3.0 };
        let graph = r#"
[graph]
format = 1
name = "stroke"
rate = 1000.0
duration = 3.0
connections = [
    "user.position -> sample.position", "user.velocity -> sample.velocity", "user.load -> sample.load",
    "user.position -> rec.x", "user.velocity -> rec.v", "user.load -> rec.l", "sample.force -> rec.f",
]
[vars]
user_seed = 1
speed_min = 3.0
speed_max = 7.0
mass_min = 60.0
mass_max = 110.0
travel = 0.08
[nodes.user]
type = "sim.user"
seed = "$user_seed"
speed_min = "$speed_min"
speed_max = "$speed_max"
mass_min = "$mass_min"
mass_max = "$mass_max"
travel = "$travel"
[nodes.sample]
type = "sim.texture"
sample = "felt-fabric"
[nodes.rec]
type = "recording.out"
path = "truth"
channels = ["x", "v", "l", "f"]
"#;
        let file = dir.path().join("stroke.toml");
        std::fs::write(&file, graph).unwrap();
        run_graph(&file, &user.sets(), dir.path()).unwrap();
        let rec = Recording::open(&dir.path().join("truth")).unwrap();
        let s = Stroke::of(&user, "felt-fabric", 3.0, 1000.0).unwrap();
        assert_eq!(s.len(), 3000);
        // The recording holds 32-bit floats: the stroke agrees to their precision.
        for (name, ours) in [("x", &s.position), ("v", &s.velocity), ("l", &s.load), ("f", &s.real)] {
            let theirs = rec.channel(name).unwrap();
            for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
                assert!((a - b).abs() <= 1e-6 * (1.0 + a.abs()), "{name}[{k}]: {a} vs {b}");
            }
        }
        // The modulation is the force without its base friction: it averages
        // out over the travel, while the force does not.
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let moving: Vec<usize> = (0..s.len()).filter(|&k| s.velocity[k].abs() > 0.01).collect();
        let m: Vec<f64> = moving.iter().map(|&k| s.modulation[k] * s.velocity[k].signum()).collect();
        let f: Vec<f64> = moving.iter().map(|&k| s.real[k] * s.velocity[k].signum()).collect();
        assert!(mean(&m).abs() < 0.2 * mean(&f), "{} vs {}", mean(&m), mean(&f));
        assert!(Stroke::of(&user, "no-such-sample", 1.0, 1000.0).is_err());
    }
}
