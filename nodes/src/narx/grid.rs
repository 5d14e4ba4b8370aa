//! `narx.grid`: inverse NARX models of several trained conditions run
//! closed loop side by side; the output is the model nearest to the user's
//! current load and velocity, switched with a crossfade — the live half of
//! rendering forces first (docs/texture.md §8.1).

use super::closed_loop::ClosedLoop;
use super::model::Model;
use super::nearest::nearest;
use super::node::TANH;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Float, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `narx.grid`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "narx.grid",
    "narx",
    Role::Filter,
    "Inverse NARX models over the (load, velocity) grid, run closed loop; the nearest condition's actuation out, switched with a crossfade.",
    build,
)
.doc(
    "Renders **forces first**: a force interpolated for the user's condition (`interp` over recorded \
     texture forces, Eq. 6.4) becomes an actuation through the inverse model (dissertation §5.2, \
     `narx`) of the trained condition nearest to the user's load and velocity. The dissertation \
     interpolates the models' actuations instead; on the simulated lab the weighted average of two \
     models' actuations renders neither, while forces first keeps Eq. 6.4's advantage (docs/texture.md \
     §8–8.1).\n\n\
     Every model runs closed loop on every sample (one forward pass each, nothing allocated), so each \
     is ready the moment it is chosen. At every update (`update_rate`, 10 Hz as `interp`'s) the node \
     picks the model whose condition is nearest to (`load`, |`velocity`|), each axis measured in units \
     of its span over the models (`nodes/src/narx/nearest.rs`; ties to the earlier model); a change \
     crossfades linearly from the old model's output to the new one's over `crossfade`.\n\n\
     **Ports** (all at the node's rate, the models' `rate_hz`): `force` (N), `load` (g), `velocity` \
     (cm/s, sign ignored) in; `u` (the chosen model's actuation, delayed by its look-ahead, as `narx`) \
     and `model` (index of the model heard, the newer during a crossfade) out.\n\n\
     **Parameters.** `models`: model files written by `narx.train` (relative to the graph file), each \
     with its condition (`condition.mass_g`, `condition.speed_cm_s`); two at one condition, a model \
     without a condition or one at another rate are refused when the graph is built, naming the file. \
     Outputs are bounded as `narx`'s. `tanh`: as `narx`'s (`exact` by default, or `fast`).",
)
.ports(PORTS)
.params(&[MODELS.spec(), UPDATE_RATE.spec(), CROSSFADE.spec(), TANH.spec()])
.example("models = [\"models/narx-60g-3cms.json\", \"models/narx-110g-7cms.json\"]");

/// The ports: force, load and velocity in; actuation and the model heard out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("force", "N", "desired lateral force"),
    PortSpec::input("load", "g", "user's normal load"),
    PortSpec::input("velocity", "cm/s", "user's scanning velocity (its magnitude is used)"),
    PortSpec::output("u", "1", "the nearest model's actuation, crossfaded on a change"),
    PortSpec::output("model", "1", "index into `models` of the model heard"),
];
/// The desired force.
const FORCE: InPort = InPort::named(PORTS, "force");
/// The user's normal load.
const LOAD: InPort = InPort::named(PORTS, "load");
/// The user's scanning velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// The actuation.
const U: OutPort = OutPort::named(PORTS, "u");
/// The index of the model heard.
const MODEL: OutPort = OutPort::named(PORTS, "model");

/// `models`: the model files, one per trained condition.
const MODELS: Words = Words::new("models", "model files written by narx.train, one per trained condition").required();
/// `update_rate`: how often the nearest model is chosen.
const UPDATE_RATE: Float = Float::new("update_rate", 0.01, 1000.0, 10.0, "Hz", "how often the nearest model is chosen");
/// `crossfade`: how long a switch takes.
const CROSSFADE: Float = Float::new("crossfade", 0.0, 1000.0, 10.0, "ms", "crossfade from one model to the next");

struct NarxGrid {
    loops: Vec<ClosedLoop>,
    conditions: Vec<(f64, f64)>,
    names: Vec<String>,
    /// Samples between choices; samples of a crossfade.
    every: u64,
    fade_len: usize,
    /// The model heard; the one faded from and samples of the fade done.
    current: usize,
    fade: Option<(usize, usize)>,
    /// Samples since t = 0; switches made.
    n: u64,
    switches: u64,
    /// Per-sample outputs of every model (scratch, sized once).
    ys: Vec<f64>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let names = MODELS.get(p);
    if names.is_empty() {
        return Err(NodeError::param(MODELS.name(), "name at least one model file (written by narx.train)"));
    }
    let tanh = TANH.get(p);
    let (mut loops, mut conditions) = (Vec::new(), Vec::new());
    for name in names {
        let path = ctx.path(name);
        let model = Model::load(&path)?;
        if (model.rate_hz - ctx.rate).abs() > 1e-9 * ctx.rate {
            return Err(NodeError::file(
                &path,
                format!(
                    "field `rate_hz`: the model was trained at {} Hz but the node runs at {} Hz",
                    model.rate_hz, ctx.rate
                ),
            ));
        }
        let (Some(m), Some(v)) = (model.condition.mass_g, model.condition.speed_cm_s) else {
            return Err(NodeError::file(
                &path,
                "field `condition`: the model records no mass_g and speed_cm_s, so it has no place in the grid \
                 (train it with narx.train's mass_g and speed_cm_s set)",
            ));
        };
        if let Some(k) = conditions.iter().position(|&(a, b)| a == m && b == v) {
            return Err(NodeError::file(
                &path,
                format!(
                    "field `condition`: {m} g, {v} cm/s is also the condition of `{}`; one model per condition",
                    names[k]
                ),
            ));
        }
        loops.push(model.closed_loop_with(tanh)?);
        conditions.push((m, v));
    }
    let every = ((ctx.rate / UPDATE_RATE.get(p)).round() as u64).max(1);
    let fade_len = (CROSSFADE.get(p) * 1e-3 * ctx.rate).round() as usize;
    let n = loops.len();
    Ok(Box::new(NarxGrid {
        loops,
        conditions,
        names: names.to_vec(),
        every,
        fade_len,
        current: 0,
        fade: None,
        n: 0,
        switches: 0,
        ys: vec![0.0; n],
    }))
}

impl Node for NarxGrid {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for k in 0..io.len() {
            let (f, m, v) = (io.input(FORCE)[k], io.input(LOAD)[k], io.input(VELOCITY)[k]);
            if self.n.is_multiple_of(self.every) {
                let want = nearest(&self.conditions, m, v.abs()).unwrap_or(0);
                if want != self.current {
                    // The first choice (t = 0) starts there; later ones crossfade.
                    self.fade = (self.fade_len > 0 && self.n > 0).then_some((self.current, 0));
                    self.switches += u64::from(self.n > 0);
                    self.current = want;
                }
            }
            for (y, cl) in self.ys.iter_mut().zip(&mut self.loops) {
                *y = cl.step(f);
            }
            let mut u = self.ys[self.current];
            if let Some((from, done)) = self.fade {
                let w = (done + 1) as f64 / (self.fade_len + 1) as f64;
                u = (1.0 - w) * self.ys[from] + w * u;
                self.fade = (done + 1 < self.fade_len).then_some((from, done + 1));
            }
            io.output(U)[k] = u;
            io.output(MODEL)[k] = self.current as f64;
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.loops.iter_mut().for_each(ClosedLoop::reset);
        self.current = 0;
        self.fade = None;
        self.n = 0;
        self.switches = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let clamped: u64 = self.loops.iter().map(|c| c.clamped).sum();
        let diverged: u64 = self.loops.iter().map(|c| c.diverged).sum();
        let mut s = Summary::default()
            .value("switches", self.switches as f64, "1")
            .value("clamped", clamped as f64, "samples")
            .value("diverged", diverged as f64, "samples");
        for (name, (m, v)) in self.names.iter().zip(&self.conditions) {
            s = s.line(format!("model {name}: {m} g, {v} cm/s"));
        }
        Ok(s)
    }
}
