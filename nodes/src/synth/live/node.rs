//! `synth.live`: the actuation synthesized at every tick, through the
//! display's forward model at the finger's condition, for the texture force
//! the finger is about to meet.

use super::envelope::{EnvelopeModel, ModelGrid};
use super::horizon::Horizon;
use super::tracking_highpass::TrackingHighpass;
use super::window_min::WindowMin;
use crate::filters::butterworth::design::{butterworth, Kind};
use crate::filters::butterworth::sos::Cascade;
use crate::synth::model_file::ForwardModel;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Float, Int, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};
use std::time::{Duration, Instant};

/// Declaration of `synth.live`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "synth.live",
    "synth",
    Role::Filter,
    "Live synthesis on a receding horizon: the carrier envelope whose force, through the forward models blended at the finger's load and speed, follows the texture force ahead.",
    build,
)
.doc(
    "Renders a texture by synthesizing the actuation at every tick for the force the finger is about to \
     meet, instead of playing signals made beforehand for a condition the finger never holds \
     (dissertation chapter 6 renders those; docs/texture.md §9 compares both). The target is the \
     texture's force against travelled distance — e.g. `interp` over the recorded forces of the grid \
     (improved scheme, Eq. 6.4) played position-locked by `playback` with the same `lookahead` L, so \
     that at tick n this node receives the force of sample n + L along the finger's predicted path; \
     the horizon H is L + 1 samples.\n\n\
     **Target.** The force in is high-passed at `highpass` Hz (second-order Butterworth; 0 passes it \
     whole) before the synthesis aims at it: below about 20 Hz the display's own response to the \
     stroke's reversals already exceeds what the real surface gives, and aiming at the target's slow \
     part there only adds to it (chosen on the tuning displays of the display family, docs/texture.md \
     §9.6). With `highpass_spatial` = k > 0 the cut-off follows the finger instead: k·|`velocity`| Hz, \
     from 1 Hz up to `highpass` (a state-variable filter whose cut-off may move every sample, \
     `nodes/src/synth/live/tracking_highpass.rs`) — better for slow fingers, not the default (measured \
     over every user on the tuning displays, docs/texture.md §9.6). `target` is the force aimed at, \
     after the high-pass.\n\n\
     **Model.** The forward models of `models` (written by `forward.train`, one per trained condition, \
     covering every combination of their loads and speeds) are blended bilinearly at the finger's \
     (`load`, |`velocity`|), clamped to the grid, `update_rate` times a second, and seen through a \
     Nyquist-rate carrier: u[n] = (−1)ⁿ·a[n], the envelope a in [0, `bound`] \
     (`nodes/src/synth/live/envelope.rs`).\n\n\
     **Each tick** minimizes over the next H envelopes Σ(y − c − b − f)² + β·Σa², y the model's \
     force, f the target, β the models' learned noise slope × `noise`, b the offset: `offset` × the \
     least that renders every trough of the target seen over the last `window` ms (a square law only \
     adds friction; the 10 Hz high-pass removes b). Starts: the previous solution shifted by one tick, \
     and the square-law envelope √((f + b)/κ); then `iterations` projected gradient steps with the \
     Barzilai–Borwein length, none of which raises the objective. The first envelope is played; below \
     `rest_speed` nothing is, and up to `full_speed` it fades in (a resting finger feels nothing). \
     Worst case per tick: `iterations` + 2 evaluations of H·(M² + 3M) multiply-adds (M the \
     models' memory). **Fallback:** when the iterations (or the `budget` in µs, when set) run out, \
     the best envelope found is played — never worse than the better start; a model without carrier \
     gain plays nothing. Nothing is allocated while running (tests/live_alloc.rs).\n\n\
     **Ports** (node rate, 1 kHz): in `force` (N, the target friction force `lookahead` samples \
     ahead), `load` (g), `velocity` (cm/s, signed); out `u` (1 = 50 V), `target` (N, the target at \
     this tick), `predicted` (N, the force change the model expects now, to set beside `target`), \
     `iterations` and `fallbacks` (running counts since the start: their rates are the synthesis' \
     iterations and fallbacks per second, which the studio shows). Non-finite inputs (and a force so \
     large that the high-pass overflows) are read as 0 and counted. Summary: mean iterations, \
     fallbacks, budget stops, the objective's mean reduction.",
)
.ports(PORTS)
.params(&[
    MODELS.spec(),
    LOOKAHEAD.spec(),
    ITERATIONS.spec(),
    OFFSET.spec(),
    WINDOW.spec(),
    HIGHPASS.spec(),
    HIGHPASS_SPATIAL.spec(),
    BOUND.spec(),
    NOISE.spec(),
    REST_SPEED.spec(),
    FULL_SPEED.spec(),
    UPDATE_RATE.spec(),
    BUDGET.spec(),
])
.bound(output_bound)
.example("models = [\"models/forward-60g-3cms.json\", \"models/forward-60g-7cms.json\", \"models/forward-110g-3cms.json\", \"models/forward-110g-7cms.json\"]\nlookahead = 15\niterations = 4");

/// The ports: the target force and the finger's condition in; the
/// actuation and what the synthesis did out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("force", "N", "target friction force, `lookahead` samples ahead"),
    PortSpec::input("load", "g", "finger's normal load"),
    PortSpec::input("velocity", "cm/s", "finger's signed velocity"),
    PortSpec::output("u", "1", "actuation: the envelope on a Nyquist-rate carrier"),
    PortSpec::output("target", "N", "the target force at this tick").view(),
    PortSpec::output("predicted", "N", "the force change the model expects from the actuation now").view(),
    PortSpec::output("iterations", "1", "optimizer iterations made since the start (a running count)").view(),
    PortSpec::output("fallbacks", "1", "ticks played from a fallback since the start (a running count)").view(),
];
/// The target force, `lookahead` samples ahead.
const FORCE: InPort = InPort::named(PORTS, "force");
/// The finger's normal load.
const LOAD: InPort = InPort::named(PORTS, "load");
/// The finger's signed velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// The actuation.
const U: OutPort = OutPort::named(PORTS, "u");
/// The target force at this tick.
const TARGET: OutPort = OutPort::named(PORTS, "target");
/// The force change the model expects.
const PREDICTED: OutPort = OutPort::named(PORTS, "predicted");
/// The running count of optimizer iterations (the port `iterations`).
const ITERATIONS_OUT: OutPort = OutPort::named(PORTS, "iterations");
/// The running count of fallbacks.
const FALLBACKS: OutPort = OutPort::named(PORTS, "fallbacks");

/// `models`: the forward model files, one per trained condition.
const MODELS: Words = Words::new("models", "forward model files (forward.train), one per trained condition").required();
/// `lookahead`: how far ahead the target arrives.
const LOOKAHEAD: Int = Int::new(
    "lookahead",
    0,
    63,
    15,
    "samples",
    "how far ahead the target arrives (playback's lookahead); the horizon is one more",
);
/// `iterations`: optimizer iterations per tick.
const ITERATIONS: Int = Int::new("iterations", 0, 200, 4, "1", "optimizer iterations per tick (the fixed worst case)");
/// `offset`: the offset, in units of the least that renders every trough.
const OFFSET: Float =
    Float::new("offset", 0.0, 10.0, 0.25, "1", "offset, in units of the least that renders every trough");
/// `window`: how far back the troughs count.
const WINDOW: Float =
    Float::new("window", 1.0, 10_000.0, 200.0, "ms", "how far back the target's troughs count for the offset");
/// `highpass`: the cut-off of the target's high-pass.
const HIGHPASS: Float = Float::new(
    "highpass",
    0.0,
    200.0,
    20.0,
    "Hz",
    "the target is high-passed here before the synthesis aims at it (second order; 0: not filtered)",
);
/// `highpass_spatial`: the cut-off against travelled distance, when it follows the speed.
const HIGHPASS_SPATIAL: Float = Float::new(
    "highpass_spatial",
    0.0,
    100.0,
    0.0,
    "1/cm",
    "when > 0, the high-pass follows the finger: cut-off = this × |velocity| Hz, from 1 Hz up to `highpass` (200 Hz if 0)",
);
/// Order of the target's high-pass.
const HIGHPASS_ORDER: usize = 2;
/// The range a speed-following cut-off is held in (Hz), its top lowered
/// to `highpass` when set.
const TRACKING_RANGE: (f64, f64) = (1.0, 200.0);

/// The target's high-pass.
enum Highpass {
    /// The target is aimed at whole.
    Off,
    /// At a fixed cut-off.
    Fixed(Cascade),
    /// At a cut-off of `per_cm` × |velocity|.
    Tracking { filter: TrackingHighpass, per_cm: f64 },
}

impl Highpass {
    /// The target sample `f` filtered, the finger at speed `v`; `None` when
    /// the filter overflowed (it then starts again from rest).
    fn tick(&mut self, f: f64, v: f64) -> Option<f64> {
        let g = match self {
            Highpass::Off => return Some(f),
            Highpass::Fixed(c) => c.tick(f),
            Highpass::Tracking { filter, per_cm } => {
                filter.set_cutoff(*per_cm * v.abs());
                filter.tick(f)
            }
        };
        if g.is_finite() {
            Some(g)
        } else {
            self.reset();
            None
        }
    }

    fn reset(&mut self) {
        match self {
            Highpass::Off => {}
            Highpass::Fixed(c) => c.reset(),
            Highpass::Tracking { filter, .. } => filter.reset(),
        }
    }
}
/// `bound`: the largest envelope.
const BOUND: Float = Float::new("bound", 1e-6, 2.0, 1.0, "1", "largest envelope |u| (1 = 50 V)");
/// `noise`: the scale on the learned noise slope.
const NOISE: Float = Float::new("noise", 0.0, 1e6, 1.0, "1", "scale on the models' learned noise slope β");
/// `rest_speed`: below it nothing is played.
const REST_SPEED: Float = Float::new("rest_speed", 0.0, 1e3, 0.3, "cm/s", "below this speed nothing is played");
/// `full_speed`: from it on the synthesis plays in full.
const FULL_SPEED: Float =
    Float::new("full_speed", 0.0, 1e3, 1.0, "cm/s", "from this speed on the synthesis plays in full");
/// `update_rate`: how often the models are blended.
const UPDATE_RATE: Float =
    Float::new("update_rate", 0.01, 1e6, 100.0, "Hz", "how often the models are blended at the finger's condition");
/// `budget`: the time a tick may take.
const BUDGET: Float =
    Float::new("budget", 0.0, 1e6, 0.0, "µs", "stop iterating once a tick has taken this long (0: no deadline)");

struct Live {
    grid: ModelGrid,
    model: EnvelopeModel,
    horizon: Horizon,
    troughs: WindowMin,
    /// The target's high-pass.
    highpass: Highpass,
    /// The targets of samples n … n+H−1.
    ahead: Vec<f64>,
    offset: f64,
    bound: f64,
    noise: f64,
    rest: f64,
    full: f64,
    every: u64,
    budget: Option<Duration>,
    iterations: usize,
    n: u64,
    // Summary.
    total_iterations: u64,
    fallbacks: u64,
    budget_stops: u64,
    bad_inputs: u64,
    reduction: f64,
    optimized_ticks: u64,
}

/// The output bound the stability suite checks: |u| ≤ `bound`.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("u", b.num(&BOUND.spec()), "|u| ≤ bound".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let names = MODELS.get(p);
    if names.is_empty() {
        return Err(NodeError::param(MODELS.name(), "name at least one forward model file (written by forward.train)"));
    }
    let mut entries = Vec::with_capacity(names.len());
    for name in names {
        let path = ctx.path(name);
        let fm = ForwardModel::load(&path)?;
        if (fm.rate_hz - ctx.rate).abs() > 1e-9 * ctx.rate {
            return Err(NodeError::file(
                &path,
                format!(
                    "field `rate_hz`: the model was identified at {} Hz, the node runs at {} Hz",
                    fm.rate_hz, ctx.rate
                ),
            ));
        }
        let (Some(mass), Some(speed)) = (fm.condition.mass_g, fm.condition.speed_cm_s) else {
            return Err(NodeError::file(
                &path,
                "field `condition`: the model records no mass_g and speed_cm_s, so it has no place in the grid \
                 (identify it with forward.train's mass_g and speed_cm_s set)",
            ));
        };
        let volterra = fm.volterra().map_err(|e| NodeError::file(&path, e))?;
        entries.push(((mass, speed.abs()), EnvelopeModel::of(&volterra, fm.noise.per_u2_n2)));
    }
    let grid = ModelGrid::new(entries, names).map_err(|e| NodeError::param(MODELS.name(), e.to_string()))?;
    let (rest, full) = (REST_SPEED.get(p), FULL_SPEED.get(p));
    if full < rest {
        return Err(NodeError::param(FULL_SPEED.name(), format!("{full} cm/s is below rest_speed = {rest} cm/s")));
    }
    let h = LOOKAHEAD.count(p) + 1;
    let m = grid.memory();
    let window = ((WINDOW.get(p) * 1e-3 * ctx.rate).round() as usize).max(1);
    let budget = BUDGET.get(p);
    let cutoff = HIGHPASS.get(p);
    let per_cm = HIGHPASS_SPATIAL.get(p);
    let highpass = if per_cm > 0.0 {
        let (lo, hi) = TRACKING_RANGE;
        let ceiling = if cutoff > 0.0 { cutoff } else { hi };
        Highpass::Tracking { filter: TrackingHighpass::new(ctx.rate, lo, ceiling), per_cm }
    } else if cutoff > 0.0 {
        let sections = butterworth(Kind::Highpass, HIGHPASS_ORDER, cutoff, ctx.rate)
            .map_err(|e| NodeError::param(HIGHPASS.name(), e.to_string()))?;
        Highpass::Fixed(Cascade::new(&sections))
    } else {
        Highpass::Off
    };
    Ok(Box::new(Live {
        highpass,
        model: EnvelopeModel::zeros(m),
        horizon: Horizon::new(m, h),
        troughs: WindowMin::new(window),
        ahead: vec![0.0; h],
        grid,
        offset: OFFSET.get(p),
        bound: BOUND.get(p),
        noise: NOISE.get(p),
        rest,
        full,
        every: ((ctx.rate / UPDATE_RATE.get(p)).round() as u64).max(1),
        budget: (budget > 0.0).then(|| Duration::from_secs_f64(budget * 1e-6)),
        iterations: ITERATIONS.count(p),
        n: 0,
        total_iterations: 0,
        fallbacks: 0,
        budget_stops: 0,
        bad_inputs: 0,
        reduction: 0.0,
        optimized_ticks: 0,
    }))
}

impl Live {
    fn finite(&mut self, x: f64) -> f64 {
        if x.is_finite() {
            x
        } else {
            self.bad_inputs += 1;
            0.0
        }
    }

    /// The share of the synthesis played at speed |v|: 0 at rest, 1 from
    /// `full_speed`, a smoothstep between.
    fn gate(&self, v: f64) -> f64 {
        let v = v.abs();
        if v < self.rest {
            0.0
        } else if v >= self.full || self.full <= self.rest {
            1.0
        } else {
            let t = (v - self.rest) / (self.full - self.rest);
            t * t * (3.0 - 2.0 * t)
        }
    }
}

impl Node for Live {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let h = self.ahead.len();
        for k in 0..io.len() {
            let f = self.finite(io.input(FORCE)[k]);
            let load = self.finite(io.input(LOAD)[k]);
            let v = self.finite(io.input(VELOCITY)[k]);
            // A force near ±f64::MAX overflows the filter's state: it starts
            // again from rest, the sample read as 0.
            let f = self.highpass.tick(f, v).unwrap_or_else(|| {
                self.bad_inputs += 1;
                0.0
            });
            if self.n == 0 {
                self.ahead.fill(f);
            } else {
                self.ahead.copy_within(1.., 0);
                self.ahead[h - 1] = f;
            }
            let least = self.troughs.push(f);
            let b = self.offset * (-least).max(0.0);
            if self.n.is_multiple_of(self.every) {
                self.grid.at(load, v, &mut self.model);
                self.model.beta *= self.noise;
            }
            let deadline = self.budget.map(|d| Instant::now() + d);
            let out = self.horizon.step(self.n, &self.ahead, b, &self.model, self.bound, self.iterations, deadline);
            let a = (self.gate(v) * out.envelope).clamp(0.0, self.bound);
            self.horizon.commit(a);
            let sign = if self.n.is_multiple_of(2) { 1.0 } else { -1.0 };
            io.output(U)[k] = sign * a;
            io.output(TARGET)[k] = self.ahead[0];
            io.output(PREDICTED)[k] = if out.predicted.is_finite() { out.predicted - b } else { 0.0 };
            self.total_iterations += out.iterations as u64;
            self.fallbacks += u64::from(out.fallback);
            io.output(ITERATIONS_OUT)[k] = self.total_iterations as f64;
            io.output(FALLBACKS)[k] = self.fallbacks as f64;
            self.budget_stops += u64::from(out.budget_stop);
            if !out.fallback && out.start_objective > 0.0 {
                self.reduction += 1.0 - out.objective / out.start_objective;
                self.optimized_ticks += 1;
            }
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.horizon.reset();
        self.troughs.reset();
        self.highpass.reset();
        self.ahead.fill(0.0);
        self.n = 0;
        self.total_iterations = 0;
        self.fallbacks = 0;
        self.budget_stops = 0;
        self.bad_inputs = 0;
        self.reduction = 0.0;
        self.optimized_ticks = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let ticks = self.n.max(1) as f64;
        let (loads, speeds) = self.grid.axes();
        let mut s = Summary::default()
            .value("iterations_per_tick", self.total_iterations as f64 / ticks, "1")
            .value("fallbacks", self.fallbacks as f64, "ticks")
            .value("budget_stops", self.budget_stops as f64, "ticks")
            .value("objective_reduction", self.reduction / self.optimized_ticks.max(1) as f64, "1")
            .line(format!(
                "{} ticks over a {}-sample horizon, models at {loads:?} g × {speeds:?} cm/s: {:.2} iterations a tick, \
                 the objective {:.1} % below the better start on average, {} fallback(s), {} budget stop(s)",
                self.n,
                self.ahead.len(),
                self.total_iterations as f64 / ticks,
                100.0 * self.reduction / self.optimized_ticks.max(1) as f64,
                self.fallbacks,
                self.budget_stops
            ));
        if self.bad_inputs > 0 {
            s = s
                .value("bad_inputs", self.bad_inputs as f64, "samples")
                .line(format!("{} non-finite (or overflowing) input sample(s) were read as 0", self.bad_inputs));
        }
        Ok(s)
    }
}
