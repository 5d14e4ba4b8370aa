//! The linear tribometer of dissertation §5.1.1 as a plain model: the
//! carriage's trapezoidal motion over the travel with left and right passes,
//! and the stylus — a mass in a vertical linear bearing with Coulomb
//! friction and viscous damping, resting on the sample through the pen
//! tip's normal stiffness and damping — which sets the normal load.
//!
//! ```text
//! m z̈ = −m g − c_b ż − f_b + N,   N = k_n (h_s(x) − z) + c_n (ḣ_s − ż)  while in contact (h_s > z)
//! ```
//! with |f_b| ≤ F_b the bearing's set-valued Coulomb friction (integrator.rs)
//! and h_s(x) = tilt·x/travel + w·sin(2πx/λ) the sample's height under the pen.
//!
//! The state is (q, ż) with q = z − h_s the stylus's height above the sample
//! (q < 0: pressed in). Within a substep the sample height is interpolated
//! linearly between its exact values at the substep's ends (first-order
//! hold, ḣ = secant slope), so a stiff contact sees a continuous surface, not
//! a staircase: q̇ = ż − ḣ, m ż' = −m g − c_b ż − f_b − k_n q − c_n (ż − ḣ).

use super::integrator::{CoulombLti, Method, Plant};
use super::profile::{LabProfile, G};

/// The carriage's motion: dwell, trapezoidal move right, dwell, move left, …
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    travel: f64,
    accel: f64,
    dwell: f64,
    v_peak: f64,
    t_acc: f64,
    t_cruise: f64,
}

impl Motion {
    /// Travel `travel` m at up to `speed` m/s with acceleration `accel` m/s²,
    /// resting `dwell` s before each pass. `speed` 0 stands still.
    pub fn new(travel: f64, speed: f64, accel: f64, dwell: f64) -> Self {
        let (v_peak, t_acc, t_cruise) = if speed <= 0.0 {
            (0.0, 0.0, 0.0)
        } else if travel >= speed * speed / accel {
            (speed, speed / accel, (travel - speed * speed / accel) / speed)
        } else {
            // Triangular profile: the travel is too short to reach the speed.
            let vp = (accel * travel).sqrt();
            (vp, vp / accel, 0.0)
        };
        Self { travel, accel, dwell, v_peak, t_acc, t_cruise }
    }

    /// Duration of one move, s (infinite when standing still).
    pub fn move_time(&self) -> f64 {
        if self.v_peak == 0.0 {
            f64::INFINITY
        } else {
            2.0 * self.t_acc + self.t_cruise
        }
    }

    /// Duration of one pass (dwell then move), s.
    pub fn pass_time(&self) -> f64 {
        self.dwell + self.move_time()
    }

    /// Duration of `passes` passes and a final dwell, s.
    pub fn total_time(&self, passes: u64) -> f64 {
        passes as f64 * self.pass_time() + self.dwell
    }

    /// The speed of the constant-speed part, m/s.
    pub fn peak_speed(&self) -> f64 {
        self.v_peak
    }

    /// Distance covered `tau` s into a move, and the speed then.
    fn along(&self, tau: f64) -> (f64, f64) {
        let (a, vp, ta) = (self.accel, self.v_peak, self.t_acc);
        let t_move = self.move_time();
        if tau <= 0.0 {
            (0.0, 0.0)
        } else if tau < ta {
            (0.5 * a * tau * tau, a * tau)
        } else if tau < ta + self.t_cruise {
            (0.5 * a * ta * ta + vp * (tau - ta), vp)
        } else if tau < t_move {
            let r = t_move - tau;
            (self.travel - 0.5 * a * r * r, a * r)
        } else {
            (self.travel, 0.0)
        }
    }

    /// Carriage position (m, from the left end) and velocity (m/s) at time
    /// `t` s, for a run of `passes` passes (0 = endless).
    pub fn at(&self, t: f64, passes: u64) -> (f64, f64) {
        if self.v_peak == 0.0 || t <= 0.0 {
            return (0.0, 0.0);
        }
        let pass_time = self.pass_time();
        let mut k = (t / pass_time).floor() as u64;
        let mut tau = t - k as f64 * pass_time - self.dwell;
        if passes > 0 && k >= passes {
            // After the last pass: rest where it ended.
            k = passes - 1;
            tau = self.move_time();
        }
        let (d, v) = self.along(tau);
        if k & 1 == 0 {
            (d, v)
        } else {
            (self.travel - d, -v)
        }
    }
}

/// Load beyond which the stylus counts as diverged, N.
const GUARD: f64 = 1e4;
/// Stroke of the stylus in its bearing: farther from the sample counts as diverged, m.
const STROKE: f64 = 0.05;
/// Vertical speed beyond which the stylus counts as diverged, m/s.
const VMAX: f64 = 10.0;

/// The tribometer: carriage motion and stylus dynamics.
#[derive(Debug, Clone)]
pub struct TribometerModel {
    motion: Motion,
    passes: u64,
    h: f64,
    hs: f64,
    substeps: usize,
    m: f64,
    fb: f64,
    cb: f64,
    kn: f64,
    tilt: f64,
    wav: f64,
    wav_len: f64,
    travel: f64,
    contact: CoulombLti,
    free: CoulombLti,
    n: u64,
    z: [f64; 2],
    stuck: bool,
    /// Times the state was reset after diverging.
    pub diverged: u64,
}

impl TribometerModel {
    /// The tribometer of `profile` sampled at `rate` Hz, carriage speed
    /// `speed` m/s, stylus mass `mass` kg, `passes` passes (0 = endless).
    pub fn new(
        profile: &LabProfile,
        rate: f64,
        speed: f64,
        mass: f64,
        passes: u64,
        method: Method,
        substeps: usize,
    ) -> Result<Self, String> {
        profile.validate()?;
        let t = &profile.tribometer;
        let travel = t.travel_cm * 1e-2;
        let motion = Motion::new(travel, speed.max(0.0), t.accel_m_s2, t.dwell_s);
        let h = 1.0 / rate;
        let hs = h / substeps.max(1) as f64;
        let (kn, cn, cb, m) = (t.normal_stiffness_n_per_m, t.normal_damping_ns_per_m, t.bearing_damping_ns_per_m, mass);
        // States (q, ż); inputs (ḣ, 1); bearing friction f opposes ż.
        let in_contact =
            Plant { a: vec![0.0, 1.0, -kn / m, -(cn + cb) / m], b: vec![-1.0, 0.0, cn / m, -G], n: 2, m: 2 };
        let flying = Plant { a: vec![0.0, 1.0, 0.0, -cb / m], b: vec![-1.0, 0.0, 0.0, -G], n: 2, m: 2 };
        let bf = vec![0.0, -1.0 / m];
        let mut model = Self {
            motion,
            passes,
            h,
            hs,
            substeps: substeps.max(1),
            m,
            fb: t.bearing_friction_n,
            cb,
            kn,
            tilt: t.tilt_mm * 1e-3,
            wav: t.waviness_um * 1e-6,
            wav_len: t.waviness_mm * 1e-3,
            travel,
            contact: CoulombLti::new(in_contact, bf.clone(), 1, hs, method)?,
            free: CoulombLti::new(flying, bf, 1, hs, method)?,
            n: 0,
            z: [0.0; 2],
            stuck: true,
            diverged: 0,
        };
        model.reset();
        Ok(model)
    }

    /// The carriage motion.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// Samples in the whole run, or `None` when endless.
    pub fn total_samples(&self) -> Option<u64> {
        let t = self.motion.total_time(self.passes);
        (self.passes > 0 && t.is_finite()).then(|| (t / self.h).ceil() as u64)
    }

    /// Samples produced so far.
    pub fn produced(&self) -> u64 {
        self.n
    }

    /// Sample height under the pen at carriage position `x` (m) and its slope.
    pub fn surface(&self, x: f64) -> (f64, f64) {
        let k = 2.0 * std::f64::consts::PI / self.wav_len;
        (self.tilt * x / self.travel + self.wav * (k * x).sin(), self.tilt / self.travel + self.wav * k * (k * x).cos())
    }

    /// Back to t = 0: carriage at the left end, stylus resting in equilibrium
    /// (the bearing carrying nothing, so the load is exactly m·g).
    pub fn reset(&mut self) {
        self.n = 0;
        self.diverged = 0;
        self.settle();
    }

    fn settle(&mut self) {
        self.z = [-self.m * G / self.kn, 0.0];
        self.stuck = true;
    }

    /// Sets the stylus state (height above the sample m, vertical velocity m/s); for tests.
    pub fn set_stylus(&mut self, q: f64, zd: f64) {
        self.z = [q, zd];
        self.stuck = zd == 0.0;
    }

    /// The stylus state (height above the sample, vertical velocity).
    pub fn stylus(&self) -> (f64, f64) {
        (self.z[0], self.z[1])
    }

    /// Stylus energy ½mż² + m g z + ½k_n (h_s − z)₊² at carriage position `x`, J.
    pub fn energy(&self, x: f64) -> f64 {
        let pen = (-self.z[0]).max(0.0);
        let z = self.z[0] + self.surface(x).0;
        0.5 * self.m * self.z[1] * self.z[1] + self.m * G * z + 0.5 * self.kn * pen * pen
    }

    /// One sample: (position m at its end, mean velocity over the sample
    /// m/s, mean normal load over the sample N).
    ///
    /// The load is the contact force averaged over the sample, from the
    /// stylus's momentum balance per substep, N̄ = m·Δż/h + m·g + c_b·Δz/h + f_b
    /// (exact for the exact map). Unlike the spring force at one instant it
    /// does not alias the stick–slip of a very stiff contact at coarse steps.
    pub fn step(&mut self) -> (f64, f64, f64) {
        let t0 = self.n as f64 * self.h;
        let (x0, _) = self.motion.at(t0, self.passes);
        let mut impulse = 0.0;
        let mut h_a = self.surface(x0).0;
        for j in 0..self.substeps {
            let tb = t0 + (j + 1) as f64 * self.hs;
            let h_b = self.surface(self.motion.at(tb, self.passes).0).0;
            let hdot = (h_b - h_a) / self.hs;
            h_a = h_b;
            let in_contact = self.z[0] < 0.0;
            let sys = if in_contact { &self.contact } else { &self.free };
            let fb = self.fb;
            let zd0 = self.z[1];
            let r = sys.step(&mut self.z, &[hdot, 1.0], fb, |_| fb);
            self.stuck = r.stuck;
            if in_contact {
                // Momentum balance: the mean contact force over the substep.
                impulse += self.m * (r.v_end - zd0) + self.hs * (self.m * G + r.force) + self.cb * r.slip;
            }
        }
        self.n += 1;
        let (x1, _) = self.motion.at(self.n as f64 * self.h, self.passes);
        let mut load = (impulse / self.h).max(0.0);
        let sane =
            self.z[0].is_finite() && self.z[0].abs() <= STROKE && self.z[1].is_finite() && self.z[1].abs() <= VMAX;
        if !(load.is_finite() && load <= GUARD && sane) {
            self.diverged += 1;
            self.settle();
            load = if load.is_finite() { load.min(GUARD) } else { 0.0 };
        }
        (x1, (x1 - x0) / self.h, load)
    }
}
