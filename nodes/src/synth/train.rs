//! `forward.train`: buffers an excitation recording (actuation and force)
//! and, when the stream ends, identifies the display's forward model and
//! writes the model file.

use super::model_file::{ForwardModel, Training};
use super::output_filter::OutputFilter;
use super::volterra_fit::{fit, FitConfig};
use crate::filters::segment::{Gates, GATES};
use crate::narx::model::{data_hash, Condition};
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::{Flag, Float, Int, Text};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, Summary};
use std::path::PathBuf;
use std::time::Instant;

/// Declaration of `forward.train`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "forward.train",
    "synth",
    Role::Sink,
    "Identifies a forward model of the display (actuation → force, a second-order Volterra NFIR) and writes the model file at the end.",
    build,
)
.doc(
    "The *forward* counterpart of `narx.train` (dissertation §5.2.1 identifies the inverse dynamics; \
     docs/synthesis.md): from an excitation recording it identifies how the display turns an actuation \
     into lateral force, for the optimized synthesis (`synth.optimize`).\n\n\
     **Model.** y[n] = c + Σ_i l_i u[n−i] + Σ_ij H_ij u[n−i] u[n−j], i, j < `memory`: a second-order \
     Volterra series with finite memory (a polynomial NFIR model). A square law between linear \
     dynamics — amplifier and circuit before it, electroadhesion lag, contact and sensor after it — is \
     exactly such a system, and its M(M+1)/2 + M + 1 parameters enter linearly: least squares, one \
     optimum, no initial weights. The recorded force went through the high-pass of §5.1.1 \
     (`highpass_order`, `highpass_hz`, 0 = none — set them as the graph's `butterworth` node); every \
     regressor is filtered the same way, so the kernel is the display's own.\n\n\
     **Ports.** `u`: the actuation (1 = 50 V); `force`: the force it produced (N), after the high-pass. \
     One model per condition (`mass_g`, `speed_cm_s` are written into it). Gates keep the samples of \
     the constant-speed forward stretches (`segment`), as for `narx.train`.\n\n\
     **Excitation.** Multilevel (a `prms` sequence) rather than binary: a ±1 sequence has u² ≡ 1 and \
     leaves the diagonal of H — the square law's amplitude response — unidentified. Keep its level \
     where the display slides smoothly (strong actuation can make the contact stick and slip, which no \
     second-order model holds; docs/synthesis.md), and step the level in blocks so the noise model \
     sees several actuation powers.\n\n\
     **Noise model.** The squared residual is regressed on the local mean of u² over `noise_window` \
     seconds: r² ≈ σ₀² + β·p. The synthesis weighs matching the force against the noise a stronger \
     actuation brings with β.\n\n\
     **Errors.** Non-finite samples, a constant force, an actuation of 0, too few kept samples for the \
     parameters (with the number needed) stop the run; nothing is written. The file (docs/synthesis.md) \
     is written through a temporary file and a rename.\n\n\
     **Summary.** `train_rel_rms`, `validation_rel_rms` (‖y − ŷ‖/‖y‖ on the fitted and the held-out \
     kept samples, from sums of squares scaled where plain ones would under- or overflow, so a \
     subnormal force has its true relative error; where the force is exactly 0 on those samples, \
     relative to the RMS force over all kept samples; with `validation = 0` nothing is held out and \
     `validation_rel_rms` is absent, `null` in the file), `carrier_gain` (N per unit² of a \
     Nyquist-rate carrier), `noise_floor`, `noise_per_u2`, \
     `samples`, `seconds`.\n\n\
     Checked against: exact recovery of a square law behind an FIR filter and a high-pass, a noise \
     model with known growth, the simulated lab (nodes/tests/forward_lab.rs).",
)
.ports(PORTS)
.params(&[
    PATH.spec(),
    MEMORY.spec(),
    HIGHPASS_ORDER.spec(),
    HIGHPASS_HZ.spec(),
    VALIDATION.spec(),
    RIDGE.spec(),
    NOISE_WINDOW.spec(),
    REWEIGHT.spec(),
    MASS_G.spec(),
    SPEED_CM_S.spec(),
    GATES.spec(),
    RECORD_TIME.spec(),
])
.offline_only("it buffers the whole recording in memory and identifies the model when the run ends")
.example("path = \"forward.json\"\nmemory = 8\nhighpass_order = 4\nhighpass_hz = 10.0\nmass_g = 85.0\nspeed_cm_s = 5.0");

/// The ports: actuation, force and the gates.
const PORTS: &[PortSpec] = &[
    PortSpec::input("u", "1", "actuation that drove the display"),
    PortSpec::input("force", "N", "force it produced, after the high-pass"),
    PortSpec::input("gate", "1", "one per `gate` entry: the sample is kept only where every gate is above 0.5")
        .per(GATES.name()),
];
/// The actuation.
const U: InPort = InPort::named(PORTS, "u");
/// The force it produced.
const FORCE: InPort = InPort::named(PORTS, "force");
/// The first gate.
const GATE: InPort = InPort::named(PORTS, "gate");

/// `path`: the model file to write.
const PATH: Text = Text::new("path", "", "model file to write (JSON), relative to the run's output folder").required();
/// `memory`: the memory M of the kernels.
const MEMORY: Int = Int::new("memory", 1, 128, 20, "samples", "memory M of the kernels (20 ms at 1 kHz)");
/// `highpass_order`: the order of the high-pass the force went through.
const HIGHPASS_ORDER: Int = Int::new(
    "highpass_order",
    0,
    crate::filters::butterworth::design::MAX_ORDER as i64,
    4,
    "1",
    "order of the Butterworth high-pass the force went through (0 = none)",
);
/// `highpass_hz`: its cut-off.
const HIGHPASS_HZ: Float =
    Float::new("highpass_hz", 0.001, 1e6, 10.0, "Hz", "its cut-off (as `butterworth`'s `cutoff`)");
/// `validation`: the fraction held out.
const VALIDATION: Float =
    Float::new("validation", 0.0, 0.89, 0.15, "1", "fraction of the kept samples, at their end, held out");
/// `ridge`: the ridge δ.
const RIDGE: Float = Float::new("ridge", 0.0, 1.0, 1e-9, "1", "ridge δ relative to the mean diagonal of ΦᵀΦ");
/// `noise_window`: the window of the local actuation power.
const NOISE_WINDOW: Float =
    Float::new("noise_window", 0.001, 10.0, 0.25, "s", "window of the local actuation power in the noise model");
/// `reweight`: whether the fit is redone with weights.
const REWEIGHT: Flag =
    Flag::new("reweight", true, "refit weighted by the inverse residual variance at each actuation power");
/// `mass_g`: the condition's stylus mass.
const MASS_G: Float = Float::new("mass_g", 0.0, 1e6, 0.0, "g", "condition: stylus mass (0 = not recorded)");
/// `speed_cm_s`: the condition's scanning speed.
const SPEED_CM_S: Float =
    Float::new("speed_cm_s", 0.0, 1e6, 0.0, "cm/s", "condition: scanning speed (0 = not recorded)");
/// `record_time`: whether the identification time is written.
const RECORD_TIME: Flag = Flag::new(
    "record_time",
    true,
    "write the identification time into the model and the summary (off: byte-identical reruns)",
);

struct Train {
    path: PathBuf,
    shown: String,
    cfg: FitConfig,
    rate: f64,
    condition: Condition,
    record_time: bool,
    gates: Gates,
    u: Vec<f64>,
    y: Vec<f64>,
    keep: Vec<bool>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let path = PATH.get(p);
    if path.is_empty() {
        return Err(NodeError::param(PATH.name(), "name the model file to write"));
    }
    let filter = OutputFilter::highpass(HIGHPASS_ORDER.count(p), HIGHPASS_HZ.get(p), ctx.rate)
        .map_err(|e| NodeError::param(HIGHPASS_HZ.name(), e.to_string()))?;
    let window = (NOISE_WINDOW.get(p) * ctx.rate).round().max(1.0) as usize;
    let set = |v: f64| (v != 0.0).then_some(v);
    Ok(Box::new(Train {
        path: ctx.output_path(PATH.name(), path)?,
        shown: path.to_string(),
        cfg: FitConfig {
            memory: MEMORY.count(p),
            filter,
            validation: VALIDATION.get(p),
            ridge: RIDGE.get(p),
            noise_window: window,
            rate: ctx.rate,
            reweight: REWEIGHT.get(p),
        },
        rate: ctx.rate,
        condition: Condition { mass_g: set(MASS_G.get(p)), speed_cm_s: set(SPEED_CM_S.get(p)) },
        record_time: RECORD_TIME.get(p),
        gates: Gates::from_params(p, GATE)?,
        u: Vec::new(),
        y: Vec::new(),
        keep: Vec::new(),
    }))
}

impl Node for Train {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        let n = ctx.max_block.max(1 << 16);
        self.u.reserve(n);
        self.y.reserve(n);
        self.keep.reserve(n);
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        // Offline only: the buffers grow with the recording. Every sample is
        // kept (the filter and the memory need the whole series); the gates
        // mark the rows.
        let (u, y) = (io.input(U), io.input(FORCE));
        let start = self.keep.len();
        self.u.extend_from_slice(u);
        self.y.extend_from_slice(y);
        self.keep.resize(start + io.len(), false);
        let keep = &mut self.keep;
        self.gates.open_runs(io, |a, b| keep[start + a..start + b].iter_mut().for_each(|k| *k = true));
        Ok(())
    }

    fn reset(&mut self) {
        self.u.clear();
        self.y.clear();
        self.keep.clear();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let t0 = Instant::now();
        let fitted = fit(&self.u, &self.y, &self.keep, &self.cfg)?;
        let (model, noise, scores) = (fitted.model, fitted.noise, fitted.scores);
        let seconds = t0.elapsed().as_secs_f64();
        let kept: Vec<f64> = self.u.iter().zip(&self.keep).filter(|(_, k)| **k).map(|(u, _)| *u).collect();
        let training = Training {
            scores,
            actuation_rms: (kept.iter().map(|v| v * v).sum::<f64>() / kept.len().max(1) as f64).sqrt(),
            actuation_peak: kept.iter().fold(0.0, |m, v| m.max(v.abs())),
            data_hash: data_hash(&[&self.u, &self.y]),
            seconds: if self.record_time { seconds } else { 0.0 },
        };
        let file =
            ForwardModel::new(&model, self.rate, &self.cfg.filter, self.condition, noise, fitted.spectrum, training);
        file.save(&self.path)?;
        let mut s = Summary::default().value("train_rel_rms", scores.train_rel_rms, "1");
        if let Some(v) = scores.validation_rel_rms {
            s = s.value("validation_rel_rms", v, "1");
        }
        let mut s = s
            .value("carrier_gain", file.carrier_gain_n, "N")
            .value("noise_floor", noise.floor_n2, "N²")
            .value("noise_per_u2", noise.per_u2_n2, "N²")
            .value("samples", scores.samples as f64, "1");
        if self.record_time {
            s = s.value("seconds", seconds, "s");
        }
        let validation = match scores.validation_rel_rms {
            Some(v) => format!("validation error {v:.3}"),
            None => "no validation error: none held out".to_string(),
        };
        Ok(s.line(format!(
            "wrote {} (memory {}, {} kept samples, {validation}, carrier gain {:.4} N)",
            self.shown,
            model.memory(),
            scores.samples,
            file.carrier_gain_n
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::super::model_file::ForwardModel;
    use super::SPEC;
    use crate::rng::Rng;
    use evflow_engine::harness::Single;
    use evflow_engine::Summary;
    use std::path::Path;

    fn train(dir: &Path, u: Vec<f64>, force: Vec<f64>, params: &str) -> Summary {
        let n = u.len() as u64;
        let params = format!("path = \"f.json\"\nmemory = 2\nhighpass_order = 0\nrecord_time = false\n{params}");
        Single::new(&SPEC, &params)
            .input("u", u, 1000.0)
            .input("force", force, 1000.0)
            .ticks(n)
            .block(128)
            .base_dir(dir)
            .summary()
            .unwrap()
    }

    fn actuation(n: usize) -> Vec<f64> {
        let mut r = Rng::new(5);
        (0..n).map(|_| [-1.0, -0.5, 0.0, 0.5, 1.0][(r.uniform() * 5.0) as usize % 5]).collect()
    }

    #[test]
    fn nothing_held_out_reports_no_validation_error() {
        // validation = 0: the held-out error was NaN (and `null` in the file).
        let dir = tempfile::tempdir().unwrap();
        let u = actuation(400);
        let force: Vec<f64> = (0..u.len()).map(|n| u[n] * u[n] + if n > 0 { 0.3 * u[n - 1] } else { 0.0 }).collect();
        let s = train(dir.path(), u, force, "validation = 0.0");
        assert!(s.values.iter().all(|(_, v, _)| v.is_finite()), "{s:?}");
        assert_eq!(s.get("validation_rel_rms"), None);
        assert!(s.get("train_rel_rms").unwrap() < 1e-6, "{s:?}");
        assert!(s.lines[0].contains("none held out"), "{:?}", s.lines);
        let m = ForwardModel::load(&dir.path().join("f.json")).unwrap();
        assert_eq!((m.training.scores.validation_rows, m.training.scores.validation_rel_rms), (0, None));
    }

    #[test]
    fn a_subnormal_force_has_finite_relative_errors() {
        // Its squares underflow to 0: both relative errors were 0/0 = NaN.
        let dir = tempfile::tempdir().unwrap();
        let tiny = [5e-324, -5e-324, f64::MIN_POSITIVE / 3.0, -f64::MIN_POSITIVE / 7.0, f64::MIN_POSITIVE];
        let force: Vec<f64> = (0..400).map(|n| tiny[n % 5]).collect();
        let s = train(dir.path(), actuation(400), force, "");
        assert!(s.values.iter().all(|(_, v, _)| v.is_finite()), "{s:?}");
        assert!(s.get("validation_rel_rms").is_some() && s.get("train_rel_rms").is_some(), "{s:?}");
    }
}
