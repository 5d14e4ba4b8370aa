//! `sim.forcesensor`: the tribometer's force sensor and acquisition.

use super::sensor_model::SensorModel;
use super::{profile_of, seed_of, INTEGRATOR, NOISE, PROFILE, SEED, SUBSTEPS};
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `sim.forcesensor`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sim.forcesensor",
    "lab",
    Role::Filter,
    "Virtual force sensor of the tribometer: surface force → acquired lateral force (resonance, bias, noise, 16 bits).",
    build,
)
.doc(
    "The six-axis force sensor of the tribometer's stylus and its acquisition (dissertation §5.1.1, \
     §3.1.1), lateral channel. The force the surface applies to the pen (`surface_force`, e.g. from \
     `sim.display`) drives a second-order resonance of unit DC gain (the pen's mass on the sensor's \
     stiffness: `resonance_hz`, `damping_ratio`); a DC bias is added that depends on the direction of \
     motion read from `velocity` (`bias_right_n` / `bias_left_n`, settling with `bias_time_s` after \
     each reversal; zero before the first motion, as after taring), plus slow thermal drift and white \
     noise; the sum is clipped to ±`full_scale_n` and quantized to `bits` (16). This is why recordings \
     are high-passed at 10 Hz before use (§5.1.1). All ports at the node's rate. Integration of the \
     resonance: `exact` (zero-order-hold matrix exponential, stable at any resonance), or `rk4`/`euler` \
     for comparison. Checked against: the analytic step response of a damped oscillator, the bias \
     difference between directions, the noise rms, quantization to the converter's step, passivity.",
)
.ports(PORTS)
.params(&[PROFILE.spec(), INTEGRATOR.spec(), SUBSTEPS.spec(), NOISE.spec(), SEED.spec()])
.example("profile = \"\"\nnoise = 1.0");

/// The ports: the surface's force and the carriage velocity in, the acquired force out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("surface_force", "N", "lateral force the surface applies to the pen"),
    PortSpec::input("velocity", "m/s", "carriage velocity (its sign selects the bias)"),
    PortSpec::output("force", "N", "acquired lateral force"),
];
/// `surface_force`: the force the surface applies to the pen.
const SURFACE_FORCE: InPort = InPort::named(PORTS, "surface_force");
/// `velocity`: the carriage velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// `force`: the acquired lateral force.
const FORCE: OutPort = OutPort::named(PORTS, "force");

struct SimForceSensor {
    model: SensorModel,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let profile = profile_of(p, ctx)?;
    let method = INTEGRATOR.get(p);
    let seed = seed_of(p, ctx);
    let model = SensorModel::new(&profile, ctx.rate, method, SUBSTEPS.count(p), NOISE.get(p), seed)
        .map_err(|m| NodeError::param(PROFILE.name(), m))?;
    Ok(Box::new(SimForceSensor { model }))
}

impl Node for SimForceSensor {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let (f, v) = (io.input(SURFACE_FORCE)[i], io.input(VELOCITY)[i]);
            io.output(FORCE)[i] = self.model.step(f, v);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.model.reset();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(super::health("sim.forcesensor", self.model.diverged, "", self.model.bad_inputs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use std::path::Path;

    fn single(params: &str, block: usize) -> Single<'_> {
        let n = 2000;
        let f: Vec<f64> = (0..n).map(|i| 0.3 * ((i as f64) * 0.05).sin()).collect();
        let v: Vec<f64> = (0..n).map(|i| if (i / 500) % 2 == 0 { 0.05 } else { -0.05 }).collect();
        Single::new(&SPEC, params)
            .input("surface_force", f, 1000.0)
            .input("velocity", v, 1000.0)
            .output("force")
            .ticks(n as u64)
            .block(block)
            .base_dir(Path::new(env!("CARGO_MANIFEST_DIR")))
    }

    #[test]
    fn block_and_per_sample_agree_and_reset_replays() {
        for params in ["", "profile = \"../graphs/lab/stiff.toml\"\nnoise = 50.0"] {
            let a = single(params, 1).run().unwrap();
            assert_eq!(a, single(params, 100).run().unwrap(), "{params}");
            assert!(a[0].iter().all(|x| x.is_finite()));
            let (mut plan, idx) = single(params, 100).plan().unwrap();
            let mut again = Vec::new();
            for _ in 0..20 {
                plan.step(100).unwrap();
                again.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            plan.reset();
            let mut third = Vec::new();
            for _ in 0..20 {
                plan.step(100).unwrap();
                third.extend_from_slice(plan.output("dut", idx[0]).unwrap());
            }
            assert_eq!(again, third);
            assert_eq!(a[0], again);
        }
    }
}
