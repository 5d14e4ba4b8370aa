//! `sim.texture`: the texture samples of the simulated lab — the six of
//! dissertation §5.3 and the rippled paper of §6.3 — as friction surfaces
//! a tribometer's stylus or the virtual user's finger slides on
//! ([`surface`] the model, [`samples`] the seven definitions).

pub mod generated;
pub mod samples;
pub mod surface;

#[cfg(test)]
mod chain_tests;
#[cfg(test)]
mod tests;

use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Float, Text};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};
use surface::Surface;

/// Declaration of `sim.texture`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sim.texture",
    "lab",
    Role::Filter,
    "Virtual texture sample: position, velocity and load of a stylus or finger → lateral friction force.",
    build,
)
.doc(
    "A texture sample on the tribometer (dissertation §5.1.1, §5.3) or under the virtual user's finger. \
Friction F = μ(x)·N·tanh(v/0.5 mm/s), opposing the motion (positive when moving toward +x, as \
`sim.display`), zero at rest. μ(x) = μ₀·(1 + m(x)): the modulation m is a sum of spatial sinusoids — \
the sample's periodic pattern and a random texture of many sinusoids with fixed wavelengths and phases \
(broadband, or around a preferred scale for the patternless felt and scrunched paper), so every scan of \
a sample meets the same surface and repeated recordings differ only by the sensor's noise — each \
attenuated by the contact patch, exp(−2π²σ²/λ²), with σ = σ₁·(N/1 N)^{1/3} (Hertzian growth with the \
load; σ₁ large for the soft samples). The plastic sheet's ridge harmonics grow with the load as \
(N/N₈₅)^1.5 (at most ×2), as §5.3.1 saw minor components emphasized at heavier mass. At a constant speed \
a component of wavelength λ sounds at v/λ, the linear frequency–velocity relation of §6.3; the main \
wavelengths (0.9–2.5 mm) put the main component above the 10 Hz high-pass of §5.1.1 at 3 cm/s; the \
power grows with the load (§5.3.1); the soft samples (chair and felt fabric) keep little power below \
1 mm, the rough ones much. The seven samples, with their values and reasons: `docs/simulated-lab.md` \
(Texture samples). `generated-<seed>` names a generated sample: a surface drawn from the seed within \
the ranges the seven cover (the same seed, the same surface; `lab::texture::generated`).\n\n\
**Ports** (at the node's rate): `position` (m), `velocity` (m/s), `load` (N) from `sim.tribometer` or \
`sim.user`; `force` (N) to `sim.forcesensor`. Non-finite inputs give 0 N.\n\n\
**Parameters.** `sample`; `friction` overrides μ₀ and `contact` overrides σ₁ (0: the sample's).\n\n\
Checked against: the closed-form patch attenuation (numerical Gaussian average); on the model and on \
recordings through tribometer, force sensor and 10 Hz high-pass: the main frequency against 3–7 cm/s is \
a line (R² > 0.99) of slope 1/λ of a main component; power rising with load; the plastic sheet's \
harmonics rising with load while the dotted sheet keeps its spectral shape; soft versus rough \
high-frequency power; mean friction 0.075–0.25 N at 60–110 g (§3.2.1); repeated recordings (sensor \
seeds) against different samples (E_s); finite bounded force at speed 0 and 50 cm/s and loads of 1 g \
and 1000 g.",
)
.ports(PORTS)
.params(&[SAMPLE.spec(), FRICTION.spec(), CONTACT.spec()])
.example("sample = \"felt-fabric\"");

/// The ports: the contact's position, velocity and load in, the friction force out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("position", "m", "position of the contact along the scan"),
    PortSpec::input("velocity", "m/s", "sliding velocity of the contact"),
    PortSpec::input("load", "N", "normal load of the contact"),
    PortSpec::output("force", "N", "lateral friction force (positive opposes +x motion)"),
];
/// `position`: the contact's position along the scan.
const POSITION: InPort = InPort::named(PORTS, "position");
/// `velocity`: the contact's sliding velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// `load`: the contact's normal load.
const LOAD: InPort = InPort::named(PORTS, "load");
/// `force`: the lateral friction force.
const FORCE: OutPort = OutPort::named(PORTS, "force");

/// `sample`: the texture sample, by name.
const SAMPLE: Text = Text::new(
    "sample",
    "dotted-sheet",
    "texture sample (§5.3, §6.3): dotted-sheet, chair-fabric, felt-fabric, painting-canvas, plastic-sheet, \
scrunched-paper, rippled-paper, or generated-<seed> (a generated sample, seed 0–2⁶⁴−1)",
);
/// `friction`: μ₀, overriding the sample's.
const FRICTION: Float = Float::new("friction", 0.0, 2.0, 0.0, "1", "base friction coefficient μ₀ (0: the sample's)");
/// `contact`: σ₁, overriding the sample's.
const CONTACT: Float = Float::new("contact", 0.0, 0.01, 0.0, "m", "contact half-width at 1 N, σ₁ (0: the sample's)");

/// A scan over a sample: the surface and its per-component gains, updated
/// as the load moves — the force `sim.texture` outputs, sample by sample,
/// for any code that needs the same numbers (the live study's stroke).
#[derive(Debug, Clone)]
pub struct TextureScan {
    surface: Surface,
    gains: Vec<f64>,
    /// The load the gains were computed for.
    gains_load: f64,
}

impl TextureScan {
    /// A scan over `surface`, at rest.
    pub fn new(surface: Surface) -> Self {
        let gains = vec![1.0; surface.components.len()];
        let mut scan = TextureScan { surface, gains, gains_load: f64::NAN };
        scan.update_gains(0.0);
        scan
    }

    /// The surface scanned.
    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    /// Recomputes the patch attenuations when the load moved by more than
    /// 0.1 % (they change with its cube root: an error below 0.03 %).
    fn update_gains(&mut self, load: f64) {
        let load = if load.is_finite() { load.max(0.0) } else { 0.0 };
        if (load - self.gains_load).abs() > 1e-3 * self.gains_load.abs() || self.gains_load.is_nan() {
            self.surface.gains(load, &mut self.gains);
            self.gains_load = load;
        }
    }

    /// The friction force at position `x` (m), velocity `v` (m/s) and load `load` (N).
    pub fn force(&mut self, x: f64, v: f64, load: f64) -> f64 {
        self.update_gains(load);
        self.surface.force(x, v, load, &self.gains)
    }

    /// μ(x)·N at this load: the force's magnitude while sliding, its
    /// direction left out.
    pub fn magnitude(&mut self, x: f64, load: f64) -> f64 {
        self.update_gains(load);
        let n = if load.is_finite() { load.max(0.0) } else { 0.0 };
        self.surface.mu_at(x, &self.gains).max(0.0) * n
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.gains_load = f64::NAN;
        self.update_gains(0.0);
    }
}

struct SimTexture {
    scan: TextureScan,
}

fn build(p: &Params, _ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let name = SAMPLE.get(p);
    let mut surface = samples::lookup(name).map_err(|e| NodeError::param(SAMPLE.name(), e))?;
    if FRICTION.get(p) > 0.0 {
        surface.mu = FRICTION.get(p);
    }
    if CONTACT.get(p) > 0.0 {
        surface.sigma_1n = CONTACT.get(p);
    }
    Ok(Box::new(SimTexture { scan: TextureScan::new(surface) }))
}

impl Node for SimTexture {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        for k in 0..n {
            let (x, v, load) = (io.input(POSITION)[k], io.input(VELOCITY)[k], io.input(LOAD)[k]);
            io.output(FORCE)[k] = self.scan.force(x, v, load);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.scan.reset();
    }
}
