//! `narx.train`: buffers a recording of force and actuation and, when the
//! stream ends, trains an inverse NARX model and writes the model file.

use super::fit::{fit, Algorithm, FitConfig};
use super::model::Condition;
use super::pairs::GatedPairs;
use super::train::Options;
use crate::filters::segment::{Gates, GATES};
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::{Choice, Flag, Float, Floats, Int, Text};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, Summary};
use std::path::PathBuf;

/// Declaration of `narx.train`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "narx.train",
    "narx",
    Role::Sink,
    "Trains an inverse NARX model (force → actuation) on the stream and writes the model file at the end.",
    build,
)
.doc(
    "Dissertation §5.2.1 (Eq. 5.1, Fig. 5.3(a)): identifies the *inverse* dynamics of the display — \
     the actuation u[n] from the measured lateral force — with a NARX network trained open loop \
     (series-parallel: the feedback taps hold the true past actuation). One model per experimental \
     condition (§5.2.2); `mass_g` and `speed_cm_s` are written into the model.\n\n\
     **Ports.** `x`: the force (N), typically the sensor force high-passed at 10 Hz (§5.1.1). `y`: the \
     actuation that produced it (1 = 50 V, ±1 = 100 Vpp), sample-aligned with `x`. Both at the node's \
     rate, which is written into the model; the taps count samples at that rate.\n\n\
     **Network.** Regressor [y[n−1] … y[n−k_y], x[n+d] … x[n−k_x]] (k_y = `feedback`, k_x = `input`, d \
     the look-ahead; d = −1 is Eq. 5.1 exactly), `hidden` tanh layers (default 15-10-5, §5.2.1), one \
     linear output. Inputs and targets are mapped to [−1, 1] (MATLAB `mapminmax`). With `alignment = \
     \"xcorr\"` d is the end of the force response to a change of u, found by cross-correlating the \
     squared increment (u[n] − u[n−1])² with the force (up to `max_lookahead`): a square-law display's \
     force is even in u, so u itself hardly correlates with it.\n\n\
     **Training.** `algorithm = \"lm\"`: Levenberg–Marquardt as MATLAB `trainlm` (dX = −(JᵀJ + μI)⁻¹Jᵀe, \
     μ = `mu` ×0.1 after an improving step, ×10 otherwise, stop above `mu_max`, below `min_grad`, after \
     `epochs` or after `max_fail` rising validation errors, keeping the best validation weights). \
     `adam`: Adam with `learning_rate` and `batch`. The validation block is the last `validation` \
     fraction of the recording, contiguous. Progress (epoch, errors, μ, time) goes to stderr when \
     `progress` is set.\n\n\
     **Excitation and feedback taps.** A PRBS obeys its shift-register recurrence (PRBS9: u[n] = \
     u[n−4]·u[n−9]); with k_y ≥ 9 feedback taps a network learns that recurrence and ignores the force \
     (the dissertation's k_y = 10 on PRBS9 does exactly that on the simulated lab: perfect open-loop and \
     closed-loop scores on PRBS9, with the force replaced by noise too, and chance on any other \
     excitation). Train on an excitation no past of which predicts the next value within the taps — a \
     random binary sequence, or a PRBS of order above k_y — and keep k_y small (default 1). The node \
     checks this itself: it runs the trained model closed loop on the validation block once with the \
     force and once with the force replaced by noise; both scores go into the model and the summary, \
     and a warning is printed when the noise-force score is above chance.\n\n\
     **Errors.** A constant channel, a non-finite sample, or a recording too short for the network \
     (fewer training rows than weights) stops the run with an error saying so; nothing is written. The \
     model file (docs/narx.md) is written through a temporary file and a rename.\n\n\
     **Summary.** `train_mse`, `validation_mse` (open loop, normalized), closed-loop `sign_agreement`, \
     `transition_agreement`, `rms` on the validation block, `noise_force_transition_agreement`, `epochs`, \
     `seconds` (training time; left out, and 0 in the model, with `record_time = false`, for byte-identical \
     reruns). `skip` and `samples` cut one stretch out of the stream (e.g. the constant-speed part of a \
     tribometer pass, where the pen slides and the force carries the actuation). Each entry of `gate` \
     adds an input of that name; with gates only the samples where every gate is above 0.5 are kept \
     and the kept stretches are concatenated — fed by `segment`, the constant-speed segments of all \
     passes, extracted and concatenated as §5.1.1 does (a few regressor rows then span a join, as in \
     the dissertation's concatenated data).\n\n\
     Checked against: finite-difference Jacobians, an exactly solvable linear least-squares problem, \
     MATLAB's `mapminmax` values, early stopping on pure noise, and the simulated lab \
     (nodes/tests/narx_lab.rs).",
)
.ports(PORTS)
.params(&[
    PATH.spec(),
    HIDDEN.spec(),
    FEEDBACK.spec(),
    INPUT.spec(),
    ALIGNMENT.spec(),
    LOOKAHEAD.spec(),
    MAX_LOOKAHEAD.spec(),
    ALGORITHM.spec(),
    EPOCHS.spec(),
    MAX_FAIL.spec(),
    VALIDATION.spec(),
    MU.spec(),
    MU_MAX.spec(),
    MIN_GRAD.spec(),
    LEARNING_RATE.spec(),
    BATCH.spec(),
    SKIP.spec(),
    SAMPLES.spec(),
    SEED.spec(),
    MASS_G.spec(),
    SPEED_CM_S.spec(),
    PROGRESS.spec(),
    GATES.spec(),
    RECORD_TIME.spec(),
])
.offline_only("it buffers the whole recording in memory and trains when the run ends")
.example(
    "path = \"model.json\"\nhidden = [4]\nfeedback = 1\ninput = 3\nepochs = 5\nmass_g = 85.0\nspeed_cm_s = 4.0\nprogress = false",
);

/// The ports: force, actuation and the gates.
const PORTS: &[PortSpec] = &[
    PortSpec::input("x", "N", "force, the network's input (e.g. the sensor force high-passed at 10 Hz)"),
    PortSpec::input("y", "1", "actuation that produced the force, the network's target"),
    PortSpec::input("gate", "1", "one per `gate` entry: the sample is kept only where every gate is above 0.5")
        .per(GATES.name()),
];
/// The force, the network's input.
const X: InPort = InPort::named(PORTS, "x");
/// The actuation, the network's target.
const Y: InPort = InPort::named(PORTS, "y");
/// The first gate.
const GATE: InPort = InPort::named(PORTS, "gate");

/// How the look-ahead d is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Alignment {
    /// By cross-correlating the squared increment of u with the force.
    Xcorr,
    /// `lookahead`, as given.
    Fixed,
}

/// `path`: the model file to write.
const PATH: Text = Text::new("path", "", "model file to write (JSON), relative to the run's output folder").required();
/// `hidden`: the hidden layer sizes.
const HIDDEN: Floats =
    Floats::new("hidden", 1.0, 1000.0, "neurons", "hidden layer sizes (empty = 15, 10, 5 as §5.2.1)");
/// `feedback`: the feedback taps k_y.
const FEEDBACK: Int = Int::new("feedback", 0, 100, 1, "samples", "feedback taps k_y: y[n−1] … y[n−k_y]");
/// `input`: the input taps k_x.
const INPUT: Int = Int::new("input", 0, 1000, 10, "samples", "input taps behind the output sample: x[n] … x[n−k_x]");
/// `alignment`: how the look-ahead d is chosen.
const ALIGNMENT: Choice<Alignment> = Choice::new(
    "alignment",
    &["xcorr", "fixed"],
    &[Alignment::Xcorr, Alignment::Fixed],
    "xcorr",
    "how the look-ahead d is chosen",
);
/// `lookahead`: d with a fixed alignment.
const LOOKAHEAD: Int =
    Int::new("lookahead", -1000, 1000, 0, "samples", "look-ahead d when `alignment = \"fixed\"` (−1 = Eq. 5.1)");
/// `max_lookahead`: the largest d the cross-correlation may choose.
const MAX_LOOKAHEAD: Int =
    Int::new("max_lookahead", 0, 1000, 10, "samples", "largest d the cross-correlation may choose");
/// `algorithm`: the training algorithm.
const ALGORITHM: Choice<Algorithm> = Choice::new(
    "algorithm",
    &["lm", "adam"],
    &[Algorithm::Lm, Algorithm::Adam],
    "lm",
    "Levenberg–Marquardt (trainlm) or Adam",
);
/// `epochs`: the largest number of epochs.
const EPOCHS: Int = Int::new("epochs", 1, 1_000_000, 1000, "1", "largest number of epochs");
/// `max_fail`: validation failures in a row that stop training.
const MAX_FAIL: Int = Int::new("max_fail", 1, 1000, 6, "1", "validation failures in a row that stop training");
/// `validation`: the fraction kept for validation.
const VALIDATION: Float =
    Float::new("validation", 0.0, 0.89, 0.15, "1", "fraction of the recording at its end kept for validation");
/// `mu`: LM's initial damping.
const MU: Float = Float::new("mu", 1e-12, 1e10, 1e-3, "1", "LM: initial damping μ");
/// `mu_max`: LM's largest damping.
const MU_MAX: Float = Float::new("mu_max", 1e-6, 1e30, 1e10, "1", "LM: largest μ before training stops");
/// `min_grad`: the gradient norm that stops training.
const MIN_GRAD: Float = Float::new("min_grad", 0.0, 1.0, 1e-7, "1", "stop when the MSE gradient norm falls below this");
/// `learning_rate`: Adam's step size.
const LEARNING_RATE: Float = Float::new("learning_rate", 1e-9, 1.0, 1e-3, "1", "Adam: step size");
/// `batch`: Adam's mini-batch size.
const BATCH: Int = Int::new("batch", 1, 1_000_000, 64, "samples", "Adam: mini-batch size");
/// `skip`: samples left out at the start.
const SKIP: Int =
    Int::new("skip", 0, 1_000_000_000, 0, "samples", "samples at the start left out (e.g. the tribometer's dwell)");
/// `samples`: samples used after `skip`.
const SAMPLES: Int = Int::new(
    "samples",
    0,
    1_000_000_000,
    0,
    "samples",
    "samples used after `skip` (0 = all; e.g. one constant-speed stretch)",
);
/// `seed`: the seed of the initial weights.
const SEED: Int = Int::new("seed", 0, 1 << 53, 0, "1", "seed of the initial weights (0 = derived from the run's seed)");
/// `mass_g`: the condition's stylus mass.
const MASS_G: Float = Float::new("mass_g", 0.0, 1e6, 0.0, "g", "condition: stylus mass (0 = not recorded)");
/// `speed_cm_s`: the condition's scanning speed.
const SPEED_CM_S: Float =
    Float::new("speed_cm_s", 0.0, 1e6, 0.0, "cm/s", "condition: scanning speed (0 = not recorded)");
/// `progress`: whether each epoch is printed.
const PROGRESS: Flag = Flag::new("progress", true, "print each epoch to stderr");
/// `record_time`: whether the training time is written.
const RECORD_TIME: Flag = Flag::new(
    "record_time",
    true,
    "write the training time into the model and the summary (off: byte-identical reruns)",
);

struct Train {
    path: PathBuf,
    shown: String,
    node: String,
    cfg: FitConfig,
    skip: usize,
    take: usize,
    progress: bool,
    record_time: bool,
    pairs: GatedPairs,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let mut hidden = Vec::new();
    for (i, &h) in HIDDEN.get(p).iter().enumerate() {
        if h.fract() != 0.0 || h < 1.0 {
            return Err(NodeError::param(
                HIDDEN.name(),
                format!("entry {i} is {h}: layer sizes are whole numbers ≥ 1"),
            ));
        }
        hidden.push(h as usize);
    }
    if hidden.is_empty() {
        hidden = vec![15, 10, 5];
    }
    let lookahead = match ALIGNMENT.get(p) {
        Alignment::Fixed => Some(LOOKAHEAD.get(p)),
        Alignment::Xcorr => None,
    };
    let (feedback, input) = (FEEDBACK.count(p), INPUT.count(p));
    if let Some(d) = lookahead {
        if d < -(input as i64) {
            return Err(NodeError::param(
                LOOKAHEAD.name(),
                format!("{d} leaves no input tap with input = {input} (the window x[n+d] … x[n−input] is empty)"),
            ));
        }
    }
    let algorithm = ALGORITHM.get(p);
    let seed = match SEED.get(p) {
        0 => ctx.node_seed() >> 11,
        s => s as u64,
    };
    let set = |v: f64| (v != 0.0).then_some(v);
    let options = Options {
        max_epochs: EPOCHS.count(p),
        max_fail: MAX_FAIL.count(p),
        min_grad: MIN_GRAD.get(p),
        mu: MU.get(p),
        mu_max: MU_MAX.get(p),
        learning_rate: LEARNING_RATE.get(p),
        batch: BATCH.count(p),
        ..Options::default()
    };
    let cfg = FitConfig {
        hidden,
        feedback,
        input,
        lookahead,
        max_lookahead: MAX_LOOKAHEAD.count(p),
        validation: VALIDATION.get(p),
        algorithm,
        options,
        seed,
        condition: Condition { mass_g: set(MASS_G.get(p)), speed_cm_s: set(SPEED_CM_S.get(p)) },
        rate_hz: ctx.rate,
    };
    let gates = Gates::from_params(p, GATE)?;
    let path = PATH.get(p);
    if path.is_empty() {
        return Err(NodeError::param(PATH.name(), "name the model file to write"));
    }
    Ok(Box::new(Train {
        path: ctx.output_path(PATH.name(), path)?,
        shown: path.to_string(),
        node: ctx.node.clone(),
        cfg,
        skip: SKIP.count(p),
        take: match SAMPLES.count(p) {
            0 => usize::MAX,
            n => n,
        },
        progress: PROGRESS.get(p),
        record_time: RECORD_TIME.get(p),
        pairs: GatedPairs::new(X, Y, gates),
    }))
}

impl Node for Train {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.pairs.reserve(ctx.max_block);
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        self.pairs.push(io, self.skip, self.take);
        Ok(())
    }

    fn reset(&mut self) {
        self.pairs.clear();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let (node, progress) = (&self.node, self.progress);
        let mut report = |e: &super::train::Epoch| {
            if progress {
                eprintln!(
                    "narx.train `{node}`: epoch {:>4}  train MSE {:.6}  validation MSE {:.6}  mu {:.1e}  {:.2} s",
                    e.epoch, e.train_mse, e.val_mse, e.mu, e.seconds
                );
            }
        };
        let mut model = fit(&self.pairs.x, &self.pairs.y, &self.cfg, &mut report).map_err(|e| match e {
            super::error::NarxError::Data(m) => NodeError::Data(format!(
                "{m}{}{}",
                if self.skip > 0 {
                    format!(" (after skipping the first {} samples)", self.skip)
                } else {
                    String::new()
                },
                if self.pairs.gates.any() {
                    format!(" (the gates kept {} of {} samples)", self.pairs.x.len(), self.pairs.seen)
                } else {
                    String::new()
                }
            )),
            other => other.into(),
        })?;
        let seconds = model.training.seconds;
        if !self.record_time {
            model.training.seconds = 0.0;
        }
        model.save(&self.path)?;
        let t = &model.training;
        let mut s = Summary::default().value("train_mse", t.train_mse, "1").value("epochs", t.epochs as f64, "1");
        if self.record_time {
            s = s.value("seconds", t.seconds, "s");
        }
        if let Some(v) = t.validation_mse {
            s = s.value("validation_mse", v, "1");
        }
        if let Some(c) = t.closed_loop {
            s = s
                .value("sign_agreement", c.sign_agreement, "1")
                .value("transition_agreement", c.transition_agreement, "1")
                .value("rms", c.rms, "1");
        }
        if let Some(c) = t.closed_loop_noise_force {
            s = s.value("noise_force_transition_agreement", c.transition_agreement, "1");
            if c.transition_agreement > 0.6 || c.sign_agreement > 0.6 {
                s = s.line(format!(
                    "narx.train `{}`: WARNING: with the force replaced by noise the closed loop still agrees with the \
                     reference (sign {:.2}, transitions {:.2}): the network predicts u from its own past, not from the \
                     force — use fewer feedback taps or an excitation its past does not predict (docs/narx.md)",
                    self.node, c.sign_agreement, c.transition_agreement
                ));
            }
        }
        Ok(s.line(format!(
            "wrote {} ({} samples, taps {}/{}/{}, {} epochs, {}{})",
            self.shown,
            t.samples,
            model.delays.feedback,
            model.delays.input,
            model.delays.lookahead,
            t.epochs,
            t.stop.describe(),
            if self.record_time { format!(", {seconds:.2} s") } else { String::new() }
        )))
    }
}
