//! The gradient-based lateral force of dissertation §4.1 as a per-tick
//! state machine, shared by the `mesh.gradient` node and the calibration.
//!
//! * Eq. 4.1–4.3: tan α = Δz/Δr between the current hit point and the
//!   previous one (the *secant* slope), or — the alternative — the slope of
//!   the hit triangle along the direction of motion, −(n_x d_x + n_y d_y)/n_z
//!   (the *normal* slope), which stays defined when the finger stops.
//! * Eq. 4.4–4.5: F = −F_pz · tan α (F_pz = 1 N in the dissertation).
//! * Eq. 4.6: F^sq = sgn(F)·√|F|.
//! * Eq. 4.7: I = (0.7 F^sq + 0.3 F_min − F_max)/(F_min − F_max), written
//!   for a general interval [I_hi, I_lo] = [1.0, 0.3], clamped: F^sq ≤ F_min
//!   gives I_hi, F^sq ≥ F_max gives I_lo (checked first, so a flat mesh with
//!   F_min = F_max never divides by zero).
//!
//! "The previous hit point" is the last one at least `min_step` away (the
//! anchor): while the finger moves less than that — or stands still — the
//! output holds, so Δr never approaches zero, and at 1 kHz the secant spans
//! about the 60 Hz frame spacing of the original (§4.2.1). A move longer
//! than `max_step` in one tick (a lift, a jump between scan lines) restarts
//! from the new point without a slope.

use super::raycast::{Hit, RayCaster};
use super::trimesh::Mesh;

/// How the slope is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SlopeMode {
    /// Δz/Δr between consecutive hit points (Eq. 4.1).
    Secant,
    /// The hit triangle's slope along the direction of motion.
    Normal,
}

/// Eq. 4.6: the signed square root.
#[inline]
pub fn signed_sqrt(f: f64) -> f64 {
    if f == 0.0 {
        0.0
    } else {
        f.signum() * f.abs().sqrt()
    }
}

/// Eq. 4.7 with clamping: F^sq in [f_min, f_max] → I in [i_hi, i_lo].
#[inline]
pub fn intensity(fsq: f64, f_min: f64, f_max: f64, i_hi: f64, i_lo: f64) -> f64 {
    if fsq.is_nan() || fsq <= f_min {
        return i_hi;
    }
    if fsq >= f_max {
        return i_lo;
    }
    let s = (fsq - f_min) / (f_max - f_min);
    (i_hi + s * (i_lo - i_hi)).clamp(i_hi.min(i_lo), i_hi.max(i_lo))
}

/// Settings of the estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradientSettings {
    /// Secant or normal slope.
    pub mode: SlopeMode,
    /// Smallest move that updates the anchor, mesh units.
    pub min_step: f64,
    /// Largest move per tick taken as motion (longer: a jump), mesh units.
    pub max_step: f64,
    /// F_pz, N.
    pub normal_force: f64,
    /// Height of the screen plane, where rays that miss the mesh land.
    pub floor: f64,
}

/// The estimate of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// tan α.
    pub slope: f64,
    /// F^sq, √N.
    pub fsq: f64,
    /// The hit (height, triangle), or the floor.
    pub hit: Option<Hit>,
    /// The height under the finger (hit or floor), mesh units.
    pub z: f64,
    /// True when this tick produced a new slope (not held).
    pub fresh: bool,
}

/// The estimator's state between ticks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gradient {
    /// Settings.
    pub s: GradientSettings,
    anchor: Option<[f64; 3]>,
    dir: Option<[f64; 2]>,
    slope: f64,
}

impl Gradient {
    /// A fresh estimator (slope 0, no anchor).
    pub fn new(s: GradientSettings) -> Self {
        Gradient { s, anchor: None, dir: None, slope: 0.0 }
    }

    /// Back to t = 0.
    pub fn reset(&mut self) {
        *self = Gradient::new(self.s);
    }

    /// Continues `from`'s estimate on another mesh (a live scene switch):
    /// the same anchor point (its height read on this mesh) and direction
    /// of motion, and as the held slope this mesh's slope at the anchor
    /// along that direction — what the secant tends to — so the first
    /// ticks on the new mesh need no run-up of `min_step`.
    pub fn rebase(&mut self, from: &Gradient, mesh: &Mesh, rc: &RayCaster) {
        self.reset();
        let Some([x, y, _]) = from.anchor else { return };
        let hit = rc.cast(x, y);
        self.anchor = Some([x, y, hit.map_or(self.s.floor, |h| h.z)]);
        self.dir = from.dir;
        if let (Some(d), Some(h)) = (self.dir, hit) {
            let n = mesh.normals[h.tri as usize];
            let slope = if n[2] != 0.0 { -(n[0] * d[0] + n[1] * d[1]) / n[2] } else { 0.0 };
            self.slope = if slope.is_finite() { slope } else { 0.0 };
        }
    }

    /// One tick at the touch point (x, y), mesh units. A non-finite point
    /// holds everything.
    pub fn step(&mut self, mesh: &Mesh, rc: &RayCaster, x: f64, y: f64) -> Estimate {
        let hit = if x.is_finite() && y.is_finite() { rc.cast(x, y) } else { None };
        let z = hit.map_or(self.s.floor, |h| h.z);
        let mut fresh = false;
        if x.is_finite() && y.is_finite() {
            match self.anchor {
                None => self.anchor = Some([x, y, z]),
                Some(a) => {
                    let (dx, dy) = (x - a[0], y - a[1]);
                    let dr = dx.hypot(dy);
                    if dr > self.s.max_step {
                        self.anchor = Some([x, y, z]);
                        self.dir = None;
                    } else if dr >= self.s.min_step && dr > 0.0 {
                        self.dir = Some([dx / dr, dy / dr]);
                        if self.s.mode == SlopeMode::Secant {
                            self.slope = (z - a[2]) / dr;
                            fresh = true;
                        }
                        self.anchor = Some([x, y, z]);
                    }
                }
            }
            if self.s.mode == SlopeMode::Normal {
                if let Some(d) = self.dir {
                    self.slope = match hit {
                        Some(h) => {
                            let n = mesh.normals[h.tri as usize];
                            // The slope does not depend on the normal's sign.
                            if n[2] != 0.0 {
                                -(n[0] * d[0] + n[1] * d[1]) / n[2]
                            } else {
                                0.0
                            }
                        }
                        None => 0.0,
                    };
                    fresh = true;
                }
            }
        }
        if !self.slope.is_finite() {
            self.slope = 0.0;
        }
        let fsq = signed_sqrt(-self.s.normal_force * self.slope);
        Estimate { slope: self.slope, fsq, hit, z, fresh }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::scenes::grid;

    #[test]
    fn eq_4_7_maps_the_interval_and_clamps() {
        assert_eq!(intensity(-1.0, -1.0, 1.0, 1.0, 0.3), 1.0);
        assert_eq!(intensity(1.0, -1.0, 1.0, 1.0, 0.3), 0.3);
        assert!((intensity(0.0, -1.0, 1.0, 1.0, 0.3) - 0.65).abs() < 1e-15);
        // The dissertation's closed form.
        let (fmin, fmax) = (-0.8, 1.3);
        for k in 0..=20 {
            let f = fmin + (fmax - fmin) * k as f64 / 20.0;
            let eq = (0.7 * f + 0.3 * fmin - fmax) / (fmin - fmax);
            assert!((intensity(f, fmin, fmax, 1.0, 0.3) - eq).abs() < 1e-14);
        }
        assert_eq!(intensity(-5.0, fmin, fmax, 1.0, 0.3), 1.0);
        assert_eq!(intensity(5.0, fmin, fmax, 1.0, 0.3), 0.3);
        // Flat mesh: F_min = F_max = 0.
        assert_eq!(intensity(0.0, 0.0, 0.0, 1.0, 0.3), 1.0);
        assert_eq!(intensity(f64::NAN, 0.0, 0.0, 1.0, 0.3), 1.0);
        assert_eq!(signed_sqrt(-4.0), -2.0);
        assert_eq!(signed_sqrt(0.25), 0.5);
    }

    fn ramp() -> (Mesh, RayCaster) {
        // z = 0.5·x: uphill along +x.
        let m = grid(10, 10, [0.0, 10.0], [0.0, 10.0], |x, _| 0.5 * x);
        let rc = RayCaster::new(&m);
        (m, rc)
    }

    fn settings(mode: SlopeMode) -> GradientSettings {
        GradientSettings { mode, min_step: 0.05, max_step: 1.0, normal_force: 1.0, floor: 0.0 }
    }

    #[test]
    fn secant_and_normal_give_the_plane_slope_in_any_direction() {
        let (m, rc) = ramp();
        for mode in [SlopeMode::Secant, SlopeMode::Normal] {
            for deg in [0.0f64, 30.0, 90.0, 180.0, 225.0] {
                let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
                let mut g = Gradient::new(settings(mode));
                let mut e = None;
                for k in 0..40 {
                    let r = 0.1 * k as f64;
                    e = Some(g.step(&m, &rc, 5.0 + r * c - 2.0 * c, 5.0 + r * s - 2.0 * s));
                }
                let e = e.unwrap();
                // Moving uphill resists: F = −0.5·cos(angle).
                let want = 0.5 * c;
                assert!((e.slope - want).abs() < 1e-12, "{mode:?} {deg}: {} vs {want}", e.slope);
                assert_eq!(e.fsq, signed_sqrt(-e.slope));
            }
        }
    }

    #[test]
    fn a_stationary_finger_holds_without_dividing_by_zero() {
        let (m, rc) = ramp();
        for mode in [SlopeMode::Secant, SlopeMode::Normal] {
            let mut g = Gradient::new(settings(mode));
            for k in 0..10 {
                g.step(&m, &rc, 2.0 + 0.1 * k as f64, 5.0);
            }
            let moving = g.step(&m, &rc, 3.0, 5.0);
            for k in 0..1000 {
                // Standing still, then creeping by less than min_step in total.
                let e = g.step(&m, &rc, 3.0 + 1e-5 * (k % 3) as f64, 5.0);
                assert_eq!(e.slope, moving.slope);
                assert!(e.fsq.is_finite());
            }
            assert!((moving.slope - 0.5).abs() < 1e-12);
        }
        // The first tick has no anchor: slope 0.
        let mut g = Gradient::new(settings(SlopeMode::Secant));
        assert_eq!(g.step(&m, &rc, 3.0, 3.0).slope, 0.0);
    }

    #[test]
    fn jumps_restart_and_off_mesh_lands_on_the_floor() {
        let (m, rc) = ramp();
        let mut g = Gradient::new(settings(SlopeMode::Secant));
        g.step(&m, &rc, 1.0, 1.0);
        g.step(&m, &rc, 1.1, 1.0);
        let before = g.step(&m, &rc, 1.2, 1.0).slope;
        let e = g.step(&m, &rc, 8.0, 8.0); // 9.6 units in one tick: a jump.
        assert_eq!(e.slope, before);
        assert!(!e.fresh);
        // Walking off the mesh at x = 10 (z = 5) onto the floor at z = 0: a drop.
        let mut g = Gradient::new(settings(SlopeMode::Secant));
        g.step(&m, &rc, 9.9, 5.0);
        let e = g.step(&m, &rc, 10.3, 5.0);
        assert!(e.hit.is_none());
        assert!((e.slope - (0.0 - 4.95) / 0.4).abs() < 1e-9);
        assert!(e.fsq > 0.0); // a drop assists: F > 0
    }
}
