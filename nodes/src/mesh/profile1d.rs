//! `profile1d`: the basic gradient algorithm of the formative study
//! (dissertation §3.2.1) — a 1-D Gaussian bump, hole or flat surface, its
//! tangential force profile and the IP0.5 / IP0.7 intensity profiles.

use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Choice, Float};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `profile1d`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "profile1d",
    "mesh",
    Role::Filter,
    "1-D Gaussian bump/hole/flat profile of §3.2.1: height, tangential force (Eq. 3.2) and IP0.5/IP0.7 intensity.",
    build,
)
.doc(
    "The formative study's rendering (dissertation §3.2.1) for a finger scanning along x from left to \
right, as in the study.\n\n\
**Geometry** (Eq. 3.1): y(x) = h·exp(−(x − μ)²/(2σ²)) on a profile of `length` (5 cm) centred at μ, \
zero outside; h defaults to Eq. 3.1's peak 1/(√(2π)σ) = 0.798 cm for σ = 0.5 cm (\"height 0.8 cm\"). \
A hole is −y, a flat surface y = 0.\n\n\
**Force** (Eq. 3.2): F_px = −F_py·tan α, tan α = dy/dx = −(x − μ)/σ²·y, with F_py = `normal_force` \
(1 N in the study). F_px < 0 resists the motion while ascending, > 0 assists while descending.\n\n\
**Intensity.** The force normalized by its peak F_py·h·e^(−1/2)/σ (so it spans −1 … 1 N) is mapped \
to the intensity: IP0.5 linearly, −1 N → 1.0, 0 N → 0.5, 1 N → 0.0. IP0.7 uses the offset 0.7 \
(where the display gives half its full-scale force, §3.1.2) with a piecewise-linear profile along x \
(Fig. 3.6b, d): knots at μ − w/2, μ − σ, μ, μ + σ, μ + w/2 (w = `width`, 2.6 cm, the feature's \
width), with the values 0.7, then 1.0 where the force resists most (0.0 where it assists most), 0.7 \
at the summit, the opposite extreme, 0.7; 0.7 outside. The figure itself is not in the text, so \
these knots are this implementation's reading of it. A flat surface gets the constant maximum \
intensity 1.0 under both profiles, as in the study.\n\n\
**Ports:** `x` the touch position (m) at any rate; outputs at the same rate. **Checked against:** \
the analytic peak height, slope and force at x = μ ± σ, a numerical derivative of y, and the \
IP0.5/IP0.7 knot values (unit tests).",
)
.ports(PORTS)
.params(&[
    SHAPE.spec(),
    PROFILE.spec(),
    CENTER.spec(),
    SIGMA.spec(),
    HEIGHT.spec(),
    LENGTH.spec(),
    WIDTH.spec(),
    NORMAL_FORCE.spec(),
])
.bound(output_bound)
.example("shape = \"bump\"\nprofile = \"ip0.7\"");

/// The ports: the touch position in; height, force and intensity out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("x", "m", "touch position along the scan"),
    PortSpec::output("height", "cm", "surface height y(x)"),
    PortSpec::output("force", "N", "tangential force F_px (Eq. 3.2), positive assists +x motion"),
    PortSpec::output("intensity", "1", "grain intensity (IP0.5 or IP0.7)"),
];
/// `x`: the touch position.
const X: InPort = InPort::named(PORTS, "x");
/// `height` (the port): the surface height y(x).
const HEIGHT_OUT: OutPort = OutPort::named(PORTS, "height");
/// `force`: the tangential force F_px.
const FORCE: OutPort = OutPort::named(PORTS, "force");
/// `intensity`: the grain intensity.
const INTENSITY: OutPort = OutPort::named(PORTS, "intensity");

/// `shape`: the surface.
const SHAPE: Choice<Shape1d> = Choice::new(
    "shape",
    &["bump", "hole", "flat"],
    &[Shape1d::Bump, Shape1d::Hole, Shape1d::Flat],
    "bump",
    "the surface",
);
/// `profile`: the force-to-intensity mapping.
const PROFILE: Choice<IntensityProfile> = Choice::new(
    "profile",
    &["ip0.5", "ip0.7"],
    &[IntensityProfile::Ip05, IntensityProfile::Ip07],
    "ip0.5",
    "force-to-intensity mapping",
);
/// `center`: μ.
const CENTER: Float = Float::new("center", -1e3, 1e3, 0.0, "cm", "μ, centre of the feature");
/// `sigma`: σ of the Gaussian.
const SIGMA: Float = Float::new("sigma", 1e-3, 100.0, 0.5, "cm", "σ of the Gaussian");
/// `height`: the peak height h.
const HEIGHT: Float = Float::new("height", 0.0, 100.0, 0.0, "cm", "peak height h; 0 = Eq. 3.1's 1/(√(2π)σ)");
/// `length`: the profile's length.
const LENGTH: Float = Float::new("length", 1e-3, 1e3, 5.0, "cm", "length of the profile (zero outside)");
/// `width`: the feature width w.
const WIDTH: Float = Float::new("width", 1e-3, 1e3, 2.6, "cm", "feature width w (IP0.7 knots at μ ± w/2)");
/// `normal_force`: F_py.
const NORMAL_FORCE: Float = Float::new("normal_force", 0.0, 100.0, 1.0, "N", "F_py, the assumed normal force");

/// Surface kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape1d {
    /// Gaussian bump.
    Bump,
    /// Gaussian hole (inverted bump).
    Hole,
    /// Flat.
    Flat,
}

/// Intensity profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntensityProfile {
    /// Linear, offset 0.5.
    Ip05,
    /// Piecewise linear, offset 0.7.
    Ip07,
}

/// The 1-D profile of §3.2.1 (lengths in cm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile1d {
    /// Surface.
    pub shape: Shape1d,
    /// Mapping.
    pub profile: IntensityProfile,
    /// μ.
    pub mu: f64,
    /// σ.
    pub sigma: f64,
    /// Peak height h.
    pub h: f64,
    /// Profile length.
    pub length: f64,
    /// Feature width.
    pub width: f64,
    /// F_py.
    pub f_py: f64,
}

/// One sample of the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample1d {
    /// y, cm.
    pub y: f64,
    /// tan α.
    pub slope: f64,
    /// F_px, N.
    pub force: f64,
    /// Intensity.
    pub intensity: f64,
}

/// IP0.7's force-to-intensity knot map: 0.7 at 0, 1.0 at −1, 0.0 at +1.
fn ip07_level(f_n: f64) -> f64 {
    if f_n <= 0.0 {
        0.7 - 0.3 * f_n
    } else {
        0.7 - 0.7 * f_n
    }
}

impl Profile1d {
    /// The study's profile: μ = 0, σ = 0.5 cm, Eq. 3.1's peak, 5 cm, 2.6 cm, 1 N.
    pub fn study(shape: Shape1d, profile: IntensityProfile) -> Self {
        Profile1d { shape, profile, mu: 0.0, sigma: 0.5, h: 0.0, length: 5.0, width: 2.6, f_py: 1.0 }.resolved()
    }

    /// Replaces h = 0 by Eq. 3.1's peak 1/(√(2π)σ).
    pub fn resolved(mut self) -> Self {
        if self.h == 0.0 {
            self.h = 1.0 / ((2.0 * std::f64::consts::PI).sqrt() * self.sigma);
        }
        self
    }

    fn sign(&self) -> f64 {
        match self.shape {
            Shape1d::Bump => 1.0,
            Shape1d::Hole => -1.0,
            Shape1d::Flat => 0.0,
        }
    }

    /// The profile at x (cm).
    pub fn at(&self, x: f64) -> Sample1d {
        if self.shape == Shape1d::Flat || !x.is_finite() {
            return Sample1d { y: 0.0, slope: 0.0, force: 0.0, intensity: 1.0 };
        }
        let d = x - self.mu;
        let (y, slope) = if d.abs() <= 0.5 * self.length {
            let y = self.sign() * self.h * (-(d * d) / (2.0 * self.sigma * self.sigma)).exp();
            (y, -d / (self.sigma * self.sigma) * y)
        } else {
            (0.0, 0.0)
        };
        let force = -self.f_py * slope;
        let peak = self.f_py * self.h * (-0.5f64).exp() / self.sigma;
        let f_n = if peak > 0.0 { (force / peak).clamp(-1.0, 1.0) } else { 0.0 };
        let intensity = match self.profile {
            IntensityProfile::Ip05 => 0.5 * (1.0 - f_n),
            IntensityProfile::Ip07 => self.ip07(d),
        };
        Sample1d { y, slope, force, intensity }
    }

    /// IP0.7 along x, piecewise linear between the knots.
    fn ip07(&self, d: f64) -> f64 {
        let s = self.sign();
        let xs = [-0.5 * self.width, -self.sigma, 0.0, self.sigma, 0.5 * self.width];
        // Normalized force at the knots: −1 (resisting) before a bump's summit, +1 after.
        let levels = [0.7, ip07_level(-s), 0.7, ip07_level(s), 0.7];
        if d <= xs[0] || d >= xs[4] {
            return 0.7;
        }
        for k in 0..4 {
            if d <= xs[k + 1] {
                let t = (d - xs[k]) / (xs[k + 1] - xs[k]);
                return levels[k] + t * (levels[k + 1] - levels[k]);
            }
        }
        0.7
    }
}

struct Profile1dNode(Profile1d);

/// The output bound the stability suite checks: the intensity lies in [0, 1].
fn output_bound(_: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("intensity", 1.0, "an intensity in [0, 1]".into()))
}

fn build(p: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let (shape, profile) = (SHAPE.get(p), PROFILE.get(p));
    let width = WIDTH.get(p);
    let sigma = SIGMA.get(p);
    if width <= 2.0 * sigma {
        return Err(NodeError::param(
            WIDTH.name(),
            format!("must exceed 2σ = {} cm (the IP0.7 knots at ±σ)", 2.0 * sigma),
        ));
    }
    Ok(Box::new(Profile1dNode(
        Profile1d {
            shape,
            profile,
            mu: CENTER.get(p),
            sigma,
            h: HEIGHT.get(p),
            length: LENGTH.get(p),
            width,
            f_py: NORMAL_FORCE.get(p),
        }
        .resolved(),
    )))
}

impl Node for Profile1dNode {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let s = self.0.at(io.input(X)[i] * 100.0);
            io.output(HEIGHT_OUT)[i] = s.y;
            io.output(FORCE)[i] = s.force;
            io.output(INTENSITY)[i] = s.intensity;
        }
        Ok(())
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    #[test]
    fn gaussian_bump_matches_eq_3_1_and_3_2() {
        let p = Profile1d::study(Shape1d::Bump, IntensityProfile::Ip05);
        let peak = 1.0 / (2.0 * std::f64::consts::PI).sqrt() / 0.5;
        assert!((p.at(0.0).y - peak).abs() < 1e-15);
        assert!((peak - 0.7978845608028654).abs() < 1e-15); // "height of 0.8 cm"
                                                            // At x = ±σ: tan α = ∓y(σ)/σ, the steepest points.
        let ys = peak * (-0.5f64).exp();
        let a = p.at(-0.5);
        assert!((a.slope - ys / 0.5).abs() < 1e-14 && (a.force + ys / 0.5).abs() < 1e-14);
        assert!((p.at(0.5).force - ys / 0.5).abs() < 1e-14);
        // Ascending resists (F < 0), descending assists (F > 0), zero at the summit.
        assert!(p.at(-1.0).force < 0.0 && p.at(1.0).force > 0.0 && p.at(0.0).force == 0.0);
        // The slope is the derivative of the height.
        for x in [-1.7, -0.9, -0.2, 0.3, 1.1] {
            let h = 1e-6;
            let num = (p.at(x + h).y - p.at(x - h).y) / (2.0 * h);
            assert!((p.at(x).slope - num).abs() < 1e-8);
        }
        // Width ≈ 2.6 cm: the bump is below 4 % of its peak outside ±1.3 cm.
        assert!(p.at(1.3).y < 0.04 * peak && p.at(1.0).y > 0.1 * peak);
        // Zero outside the 5 cm profile; a hole is the negative.
        assert_eq!(p.at(2.6).y, 0.0);
        let hole = Profile1d::study(Shape1d::Hole, IntensityProfile::Ip05);
        assert_eq!(hole.at(0.3).y, -p.at(0.3).y);
        assert_eq!(hole.at(0.3).force, -p.at(0.3).force);
    }

    #[test]
    fn ip05_maps_minus_one_newton_to_full_intensity() {
        let p = Profile1d::study(Shape1d::Bump, IntensityProfile::Ip05);
        assert!((p.at(-0.5).intensity - 1.0).abs() < 1e-14);
        assert!((p.at(0.0).intensity - 0.5).abs() < 1e-15);
        assert!(p.at(0.5).intensity.abs() < 1e-14);
        assert!((p.at(2.4).intensity - 0.5).abs() < 1e-4);
        let hole = Profile1d::study(Shape1d::Hole, IntensityProfile::Ip05);
        assert!(hole.at(-0.5).intensity.abs() < 1e-14);
        let flat = Shape1d::Flat;
        assert_eq!(Profile1d::study(flat, IntensityProfile::Ip05).at(0.1).intensity, 1.0);
        assert_eq!(Profile1d::study(flat, IntensityProfile::Ip07).at(0.1).intensity, 1.0);
    }

    #[test]
    fn ip07_is_piecewise_linear_through_its_knots() {
        let p = Profile1d::study(Shape1d::Bump, IntensityProfile::Ip07);
        for (x, want) in [(-1.3, 0.7), (-0.5, 1.0), (0.0, 0.7), (0.5, 0.0), (1.3, 0.7), (-2.0, 0.7), (2.0, 0.7)] {
            assert!((p.at(x).intensity - want).abs() < 1e-15, "{x}");
        }
        // Midpoints are means of their knots.
        assert!((p.at(-0.9).intensity - 0.85).abs() < 1e-12);
        assert!((p.at(0.25).intensity - 0.35).abs() < 1e-12);
        let hole = Profile1d::study(Shape1d::Hole, IntensityProfile::Ip07);
        assert!((hole.at(-0.5).intensity - 0.0).abs() < 1e-15 && (hole.at(0.5).intensity - 1.0).abs() < 1e-15);
        // More than 0.7 exactly where the force resists.
        for k in -25..=25 {
            let x = k as f64 * 0.05;
            let s = p.at(x);
            if s.force < -1e-9 && x.abs() < 1.3 {
                assert!(s.intensity > 0.7, "{x}");
            }
            if s.force > 1e-9 && x.abs() < 1.3 {
                assert!(s.intensity < 0.7, "{x}");
            }
        }
    }

    #[test]
    fn the_node_takes_metres() {
        let x = vec![-0.005, 0.0, 0.005];
        let out = Single::new(&SPEC, "shape = \"bump\"\nprofile = \"ip0.5\"")
            .input("x", x, 1000.0)
            .outputs(["height", "force", "intensity"])
            .ticks(3)
            .block(2)
            .run()
            .unwrap();
        assert!((out[0][1] - 0.7978845608028654).abs() < 1e-15);
        assert!((out[2][0] - 1.0).abs() < 1e-14 && out[2][2].abs() < 1e-14);
        assert!(out[1][0] < 0.0);
    }
}
