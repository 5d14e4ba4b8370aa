//! `sim.user`: the virtual user of the simulated lab — a finger scanning
//! side to side ([`finger`]) as the rig's sensors report it: an IR touch
//! frame (40 Hz, quantized) and a load cell (40 Hz, noisy).

pub mod finger;

use crate::rate::clock::Clock;
use crate::rng::Rng;
use evflow_engine::ports::OutPort;
use evflow_engine::typed_params::{Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, RateSpec, Role, Summary};
use finger::{Finger, FingerSettings};

/// Declaration of `sim.user`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "sim.user",
    "lab",
    Role::Source,
    "Virtual user: a finger scanning side to side with a person's varying speed and pressure, as an IR frame and a load cell report it.",
    build,
)
.doc(
    "Stands in for a person at the display (dissertation §6.5: the user study's finger, tracked by an \
IR frame and a load cell). The finger strokes left and right over `travel` along the direction \
`direction` from (`origin_x`, `origin_y`) on the screen. Each stroke picks a cruising speed in \
[`speed_min`, `speed_max`] and a pressure (as a mass) in [`mass_min`, `mass_max`] uniformly; within \
the stroke both drift (Ornstein–Uhlenbeck, correlation time `wander`, rms 15 % of the range, kept in \
range) — 3–7 cm/s and 60–110 g by default, like the dissertation's conditions, and the limits allow \
the extremes (0–50 cm/s, 1–1000 g). Reversals are smooth: a raised-cosine stop and restart taking \
`reversal` seconds, braking so as to stop exactly at the end of the travel. Seeded (the graph's seed \
and the node name, or `seed`).\n\n\
**Outputs at the node's rate** (`rate`, 1 kHz): the truth — `position` along the stroke (m, from \
its start), signed `velocity` (m/s, mean over the sample: + away from the origin), `load` (N = \
mass·g), and the touch point `x`, `y` on the screen (m) for the mesh chain. **Outputs at `ir_rate`** \
(40 Hz, an IR touch frame's report rate): `ir_x`, `ir_y` — the touch point sampled at each frame and \
quantized to `ir_resolution` (0.5 mm by default, chosen: the dissertation does not give its frame's \
resolution; a frame interpolating one virtual beam between physical beams resolves half the beam pitch, \
Carroll Touch Touch System Programmer's Guide ch. 1) — and `load_cell`, the load sampled at each frame \
plus Gaussian noise of rms `load_noise` (N). §6.5.1's program read both every 25 ms (40 Hz); a `hold` \
node turns the reports into a 1 kHz sample-and-hold stream.\n\n\
Feed `load` and `velocity` to `sim.display` or `sim.texture`, `x`/`y` to `mesh.gradient`, and the \
sensor outputs to `foaw` and `interp` as a rig's would be. Checked against: the stroke stays on the \
travel, speed and load stay in their ranges, the velocity is the derivative of the position, \
reversals at both ends, bounded acceleration, frames exactly every 1/`ir_rate`, quantization to the \
resolution, determinism per seed, and finite bounded outputs at the extremes.",
)
.ports(PORTS)
.params(&[
    SPEED_MIN.spec(),
    SPEED_MAX.spec(),
    MASS_MIN.spec(),
    MASS_MAX.spec(),
    TRAVEL.spec(),
    DIRECTION.spec(),
    ORIGIN_X.spec(),
    ORIGIN_Y.spec(),
    REVERSAL.spec(),
    WANDER.spec(),
    IR_RATE.spec(),
    IR_RESOLUTION.spec(),
    LOAD_NOISE.spec(),
    SEED.spec(),
    RATE.spec(),
])
.rate_param(RATE.name())
.example("speed_min = 3.0\nspeed_max = 7.0\nmass_min = 60.0\nmass_max = 110.0\nir_rate = 40.0");

/// The ports: the finger's truth at the node's rate, the sensors' reports
/// at `ir_rate`.
const PORTS: &[PortSpec] = &[
    PortSpec::output("position", "m", "finger position along the stroke, from its start"),
    PortSpec::output("velocity", "m/s", "signed finger velocity along the stroke"),
    PortSpec::output("load", "N", "normal load of the finger"),
    PortSpec::output("x", "m", "touch point x on the screen"),
    PortSpec::output("y", "m", "touch point y on the screen"),
    PortSpec::output("ir_x", "m", "touch x as the IR frame reports it (quantized)").at(RateSpec::Param(IR_RATE.name())),
    PortSpec::output("ir_y", "m", "touch y as the IR frame reports it (quantized)").at(RateSpec::Param(IR_RATE.name())),
    PortSpec::output("load_cell", "N", "load as the load cell reports it (noisy)").at(RateSpec::Param(IR_RATE.name())),
];
/// `position`: the finger position along the stroke.
const POSITION: OutPort = OutPort::named(PORTS, "position");
/// `velocity`: the signed finger velocity.
const VELOCITY: OutPort = OutPort::named(PORTS, "velocity");
/// `load`: the finger's normal load.
const LOAD: OutPort = OutPort::named(PORTS, "load");
/// `x`: the touch point x.
const X: OutPort = OutPort::named(PORTS, "x");
/// `y`: the touch point y.
const Y: OutPort = OutPort::named(PORTS, "y");
/// `ir_x`: touch x as the IR frame reports it.
const IR_X: OutPort = OutPort::named(PORTS, "ir_x");
/// `ir_y`: touch y as the IR frame reports it.
const IR_Y: OutPort = OutPort::named(PORTS, "ir_y");
/// `load_cell`: the load as the load cell reports it.
const LOAD_CELL: OutPort = OutPort::named(PORTS, "load_cell");
/// The outputs of one report ([`SimUser::report`]), in its order.
const REPORT_PORTS: [OutPort; 3] = [IR_X, IR_Y, LOAD_CELL];

/// `speed_min`: the slowest cruising speed.
const SPEED_MIN: Float = Float::new("speed_min", 0.0, 50.0, 3.0, "cm/s", "slowest cruising speed");
/// `speed_max`: the fastest cruising speed.
const SPEED_MAX: Float = Float::new("speed_max", 0.0, 50.0, 7.0, "cm/s", "fastest cruising speed");
/// `mass_min`: the lightest pressure, as a mass.
const MASS_MIN: Float = Float::new("mass_min", 1.0, 1000.0, 60.0, "g", "lightest pressure, as a mass (load = mass·g)");
/// `mass_max`: the heaviest pressure, as a mass.
const MASS_MAX: Float = Float::new("mass_max", 1.0, 1000.0, 110.0, "g", "heaviest pressure, as a mass");
/// `travel`: the length of a stroke.
const TRAVEL: Float = Float::new("travel", 0.001, 1.0, 0.08, "m", "length of a stroke");
/// `direction`: the strokes' direction on the screen.
const DIRECTION: Float =
    Float::new("direction", -360.0, 360.0, 0.0, "deg", "direction of the strokes on the screen (0 = +x)");
/// `origin_x`: the screen x of the strokes' start.
const ORIGIN_X: Float = Float::new("origin_x", -1e6, 1e6, 0.0, "m", "screen x of the strokes' start");
/// `origin_y`: the screen y of the strokes' start.
const ORIGIN_Y: Float = Float::new("origin_y", -1e6, 1e6, 0.0, "m", "screen y of the strokes' start");
/// `reversal`: the time to stop and restart.
const REVERSAL: Float = Float::new("reversal", 0.002, 10.0, 0.1, "s", "time to stop and restart at a reversal");
/// `wander`: the drift's correlation time.
const WANDER: Float = Float::new("wander", 0.01, 100.0, 1.0, "s", "correlation time of the speed and pressure drift");
/// `ir_rate`: the report rate of the IR frame and load cell.
const IR_RATE: Float = Float::new("ir_rate", 1.0, 1000.0, 40.0, "Hz", "report rate of the IR frame and load cell");
/// `ir_resolution`: the IR frame's resolution.
const IR_RESOLUTION: Float = Float::new("ir_resolution", 0.0, 0.1, 0.0005, "m", "IR frame resolution (0: exact)");
/// `load_noise`: the load cell's rms noise.
const LOAD_NOISE: Float = Float::new("load_noise", 0.0, 10.0, 0.005, "N", "rms noise of the load cell");
/// `seed`: the random seed.
const SEED: Int = Int::new("seed", -1, i64::MAX, -1, "1", "random seed (−1: from the graph's seed and the node name)");
/// `rate`: the sample rate of the true outputs.
const RATE: Float = Float::new("rate", 1.0, 1e6, 1000.0, "Hz", "sample rate of the true outputs");

struct SimUser {
    settings: FingerSettings,
    seed: u64,
    finger: Finger,
    dir: (f64, f64),
    origin: (f64, f64),
    resolution: f64,
    load_noise: f64,
    noise: Rng,
    node_clock: Clock,
    ir_clock: Clock,
    /// Samples produced so far: at the node's rate and at the IR rate.
    sent: u64,
    ir_sent: u64,
    /// The last IR report (held if the engine asks for more reports than were due).
    last_ir: [f64; 3],
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let range = |lo: Float, hi: Float| -> Result<(f64, f64), NodeError> {
        let (a, b) = (lo.get(p), hi.get(p));
        if a > b {
            return Err(NodeError::param(lo.name(), format!("{} = {a} is above {} = {b}", lo.name(), hi.name())));
        }
        Ok((a, b))
    };
    let (s0, s1) = range(SPEED_MIN, SPEED_MAX)?;
    let (m0, m1) = range(MASS_MIN, MASS_MAX)?;
    let rate = ctx.rate;
    let ir_rate = IR_RATE.get(p);
    let ir_clock = Clock::new(ir_rate, ctx.base_rate, "ir_x")?;
    let node_clock = Clock::new(rate, ctx.base_rate, "position")?;
    if ir_rate > rate {
        return Err(NodeError::param(
            IR_RATE.name(),
            format!("ir_rate = {ir_rate} Hz is above the node's rate {rate} Hz"),
        ));
    }
    let settings = FingerSettings {
        travel: TRAVEL.get(p),
        speed: (s0 * 0.01, s1 * 0.01),
        mass: (m0 * 1e-3, m1 * 1e-3),
        reversal: REVERSAL.get(p),
        wander: WANDER.get(p),
        h: 1.0 / rate,
    };
    let seed = crate::lab::seed_or_node(SEED.get(p), ctx);
    let a = DIRECTION.get(p).to_radians();
    let mut node = SimUser {
        settings,
        seed,
        finger: Finger::new(settings, seed),
        dir: (a.cos(), a.sin()),
        origin: (ORIGIN_X.get(p), ORIGIN_Y.get(p)),
        resolution: IR_RESOLUTION.get(p),
        load_noise: LOAD_NOISE.get(p),
        noise: Rng::substream(seed, 4),
        node_clock,
        ir_clock,
        sent: 0,
        ir_sent: 0,
        last_ir: [0.0; 3],
    };
    node.reset();
    Ok(Box::new(node))
}

impl SimUser {
    fn touch(&self) -> (f64, f64) {
        let p = self.finger.position;
        (self.origin.0 + p * self.dir.0, self.origin.1 + p * self.dir.1)
    }

    fn quantize(&self, v: f64) -> f64 {
        if self.resolution > 0.0 {
            (v / self.resolution).round() * self.resolution
        } else {
            v
        }
    }

    /// The IR frame and load cell report of the finger's current state.
    fn report(&mut self) -> [f64; 3] {
        let (x, y) = self.touch();
        let noise = if self.load_noise > 0.0 { self.load_noise * self.noise.gaussian() } else { 0.0 };
        [self.quantize(x), self.quantize(y), self.finger.load() + noise]
    }
}

impl Node for SimUser {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        let n_ir = io.output_len(IR_X).min(io.output_len(IR_Y)).min(io.output_len(LOAD_CELL));
        let mut k_ir = 0;
        for q in 0..n {
            // Sample `sent` of the node's clock is the state after this step.
            self.finger.step();
            let (x, y) = self.touch();
            io.output(POSITION)[q] = self.finger.position;
            io.output(VELOCITY)[q] = self.finger.velocity;
            io.output(LOAD)[q] = self.finger.load();
            io.output(X)[q] = x;
            io.output(Y)[q] = y;
            // IR reports due at or before this sample take this state.
            while k_ir < n_ir && self.ir_clock.at_or_before(self.ir_sent, &self.node_clock, self.sent) {
                let r = self.report();
                self.last_ir = r;
                for (port, v) in REPORT_PORTS.into_iter().zip(r) {
                    io.output(port)[k_ir] = v;
                }
                k_ir += 1;
                self.ir_sent += 1;
            }
            self.sent += 1;
        }
        // Reports the engine counts in this call beyond those due (never expected): hold the last.
        while k_ir < n_ir {
            let r = self.last_ir;
            for (port, v) in REPORT_PORTS.into_iter().zip(r) {
                io.output(port)[k_ir] = v;
            }
            k_ir += 1;
            self.ir_sent += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.finger = Finger::new(self.settings, self.seed);
        self.noise = Rng::substream(self.seed, 4);
        self.sent = 0;
        self.ir_sent = 0;
        self.last_ir = [0.0; 3];
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(Summary::default().value("ir_reports", self.ir_sent as f64, "1"))
    }
}

#[cfg(test)]
mod tests;
