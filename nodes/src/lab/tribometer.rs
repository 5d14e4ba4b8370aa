//! `sim.tribometer`: the linear tribometer's carriage and stylus.

use super::tribometer_model::TribometerModel;
use super::{profile_of, INTEGRATOR, PROFILE, SUBSTEPS};
use evflow_engine::ports::OutPort;
use evflow_engine::typed_params::{Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `sim.tribometer`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sim.tribometer",
    "lab",
    Role::Source,
    "Virtual linear tribometer: trapezoidal left/right passes of a weighted stylus → position, velocity, load.",
    build,
)
.doc(
    "The motorized linear tribometer of dissertation §5.1.1. The carriage follows a trapezoidal \
     velocity profile over the travel (8 cm) at `speed` (3–7 cm/s in the dissertation), resting \
     `dwell_s` before each pass; passes alternate right (+x) and left (−x), starting at the left end. \
     The stylus (`mass`, 60–110 g) rides in a vertical linear bearing with Coulomb friction and \
     viscous damping and rests on the sample through the pen tip's normal stiffness and damping; the \
     sample is slightly tilted and wavy (profile), so the stylus moves vertically and the bearing \
     friction makes the load differ between the two directions (m·g ± F_b) — a real rig's \
     direction-dependent load. Outputs, at the node's `rate` (1 kHz, or 10 kHz for characterization), \
     each at the end of its sample: carriage `position`, the mean `velocity` over the sample (so the \
     displacement a display or texture integrates is exactly the carriage's), and the normal `load` \
     on the sample (≥ 0; 0 if the stylus lifts off). \n\n\
     The tribometer measures nothing itself: feed `velocity` and `load` to `sim.display` (or a texture), \
     and the surface's force with `velocity` to `sim.forcesensor`, which adds the sensor's resonance, \
     direction-dependent bias, drift, noise and 16-bit quantization — an acyclic graph. With `passes` > 0 \
     the run ends after the last pass and a final dwell; `speed` = 0 rests at the left end forever. \
     Integration: `exact` advances the stylus by its zero-order-hold matrix exponential with the \
     bearing friction solved implicitly as a set-valued law (stuck stylus stays exactly still); the \
     contact switches between touching and lifted at substep starts. Checked against: the analytic \
     trapezoid, the static load m·g, the m·g ± F_b loads of the two directions, passivity, and the \
     stiff profile at 1 kHz.",
)
.ports(PORTS)
.params(&[PROFILE.spec(), SPEED.spec(), MASS.spec(), PASSES.spec(), RATE.spec(), INTEGRATOR.spec(), SUBSTEPS.spec()])
.rate_param(RATE.name())
.example("speed = 5.0\nmass = 85.0\npasses = 2\nrate = 1000.0");

/// The ports: the carriage's position and velocity and the stylus's load out.
const PORTS: &[PortSpec] = &[
    PortSpec::output("position", "m", "carriage position from the left end of the travel"),
    PortSpec::output("velocity", "m/s", "carriage velocity (mean over the sample; + is rightward)"),
    PortSpec::output("load", "N", "normal force of the pen tip on the sample"),
];
/// `position`: the carriage position.
const POSITION: OutPort = OutPort::named(PORTS, "position");
/// `velocity`: the carriage velocity.
const VELOCITY: OutPort = OutPort::named(PORTS, "velocity");
/// `load`: the pen tip's normal force.
const LOAD: OutPort = OutPort::named(PORTS, "load");

/// `speed`: the carriage speed of the constant-speed part.
const SPEED: Float =
    Float::new("speed", 0.0, 50.0, 5.0, "cm/s", "carriage speed of the constant-speed part (0 = rest)");
/// `mass`: the stylus mass.
const MASS: Float = Float::new("mass", 1.0, 1000.0, 85.0, "g", "stylus mass (sets the load m·g)");
/// `passes`: passes to run (0: endless).
const PASSES: Int = Int::new("passes", 0, 1_000_000, 2, "1", "passes to run, alternating right and left (0 = endless)");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1.0, 1e6, 1000.0, "Hz", "sample rate");

struct SimTribometer {
    model: TribometerModel,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let profile = profile_of(p, ctx)?;
    let method = INTEGRATOR.get(p);
    let model = TribometerModel::new(
        &profile,
        ctx.rate,
        SPEED.get(p) * 1e-2,
        MASS.get(p) * 1e-3,
        PASSES.get(p) as u64,
        method,
        SUBSTEPS.count(p),
    )
    .map_err(|m| NodeError::param(PROFILE.name(), m))?;
    Ok(Box::new(SimTribometer { model }))
}

impl Node for SimTribometer {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let (p, v, l) = self.model.step();
            io.output(POSITION)[i] = p;
            io.output(VELOCITY)[i] = v;
            io.output(LOAD)[i] = l;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.model.reset();
    }

    fn remaining(&self) -> Option<u64> {
        self.model.total_samples().map(|t| t.saturating_sub(self.model.produced()))
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(super::health("sim.tribometer", self.model.diverged, "; use integrator = \"exact\" or more substeps", 0))
    }
}
