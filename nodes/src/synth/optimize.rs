//! `synth.optimize`: the optimized synthesis as a source — reads a real
//! texture force, synthesizes the actuation through a forward model, and
//! plays it.

use super::lbfgsb::Options;
use super::model_file::ForwardModel;
use super::start::carrier;
use super::synthesize::{synthesize, NoiseWeight, ObjectiveKind, SynthConfig};
use crate::filters::segment::SpeedRule;
use crate::metric::spectral_error::{Band, BandError};
use crate::metric::spectrum::{SpectrumConfig, Window};
use crate::narx::model::Model;
use crate::recording::format::Recording;
use evflow_engine::ports::OutPort;
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Choice, Flag, Float, Int, Text};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `synth.optimize`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "synth.optimize",
    "synth",
    Role::Source,
    "Synthesizes the actuation for a recorded texture force by bounded optimization through a forward model, and plays it.",
    build,
)
.doc(
    "Optimized synthesis, beyond dissertation §5.2.2 (docs/synthesis.md): instead of asking an \
     inverse model which actuation made a force, it searches the actuation u whose force — predicted \
     by a forward model of the display (`forward.train`) and high-passed as the recordings were — is \
     closest to the real texture force, with u bounded to [−`bound`, `bound`]. Projected L-BFGS, \
     gradients by backpropagation through the model and the filter.\n\n\
     **Target.** Channel `channel` of the recording `target` (a texture force, e.g. repetition 1 of \
     `graphs/record-textures.toml`). With `speed` > 0, only its constant-speed samples count (the \
     recording's `velocity` channel under `segment`'s rule with `tolerance` and `settle`); 0 counts \
     every sample. The actuation has one sample per recorded one; the node is a finite source that \
     ends with the recording (zeros after it).\n\n\
     **Objective.** `time`: Σ(ŷ − f)²/Σf² over the counted samples (the waveform); `spectral`: E_s² \
     with the `metric` node's spectra (`nfft` 0 = the rate, `window`, `overlap`, band `fmin`–`fmax`); \
     both plus the noise an actuation brings, λ·mean(u²), λ = β/mean(f²) from the model's noise model \
     (`noise = \"learned\"`) or `lambda` (`noise = \"fixed\"`). `expected`: E_s² of the spectra the \
     display is expected to deliver — the model's force plus its learned residual noise spectrum, \
     which grows with the actuation — over Hann-windowed half-overlapping segments of the model's \
     noise-spectrum length (`window`, `overlap` and `noise` do not apply). Where fewer samples count than \
     one segment (one pass at 7 cm/s keeps less than a second), both spectral objectives give way to `time`, \
     and the summary says so.\n\n\
     **Start.** `carrier`: the square-law envelope on a Nyquist-rate carrier, \
     u[n] = (−1)ⁿ·√(max(0, (f[n] + c)/κ)), κ the model's carrier gain, c = −min f; `narx`: the inverse \
     NARX model `narx_model` run closed loop on the force (§5.2.2); `zero`. When the forward model's carrier gain \
     κ is not positive (its fit explains almost nothing of the force), `carrier` starts from `narx_model` \
     instead if one is given, and says so. `best` (default): the optimization runs from every start there \
     is — the carrier (when κ > 0) and the inverse model (when `narx_model` is given; else zero) — each with \
     the whole iteration budget, and the carrier's is played unless another's objective ends lower by more \
     than `start_margin` (5 %): where the display is one the carrier start does not suit, the objective says \
     so; where both end within a few per cent, the objective does not tell which plays better, and the \
     carrier's was measured to (docs/synthesis.md §1).\n\n\
     **Timing.** The synthesis runs on the first block (offline only) and counts in the node's run \
     time. **Summary.** `objective_start`, `objective_end` (never above the start), `iterations`, \
     `evaluations`, `lambda`, `seconds` (with `record_time`), and why the optimizer stopped.",
)
.ports(PORTS)
.params(&[
    TARGET.spec(),
    CHANNEL.spec(),
    MODEL.spec(),
    SPEED.spec(),
    TOLERANCE.spec(),
    SETTLE.spec(),
    START.spec(),
    START_MARGIN.spec(),
    NARX_MODEL.spec(),
    OBJECTIVE.spec(),
    NFFT.spec(),
    WINDOW.spec(),
    OVERLAP.spec(),
    FMIN.spec(),
    FMAX.spec(),
    NOISE.spec(),
    LAMBDA.spec(),
    ITERATIONS.spec(),
    BOUND.spec(),
    RECORD_TIME.spec(),
])
.offline_only("it synthesizes the whole actuation from a recording before playing it")
.bound(output_bound)
.example("target = \"recordings/felt\"\nmodel = \"models/forward.json\"\niterations = 5");

struct Optimize {
    force: Vec<f64>,
    keep: Vec<bool>,
    /// The starts to optimize from, each with its name (for the summary).
    starts: Vec<(String, Vec<f64>)>,
    /// How much lower another start's objective must end to be kept over the first's.
    margin: f64,
    /// Which objective was used (for the summary).
    objective_used: &'static str,
    model: ForwardModel,
    cfg: SynthConfig,
    u: Option<Vec<f64>>,
    summary: Summary,
    pos: usize,
    /// Report `seconds`.
    record_time: bool,
}

/// The port: the synthesized actuation.
const PORTS: &[PortSpec] = &[PortSpec::output("u", "1", "the synthesized actuation (1 = 50 V)")];
/// The synthesized actuation.
const U: OutPort = OutPort::named(PORTS, "u");

/// Where the optimization starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    /// From every start there is; the lowest objective (within `start_margin`) is kept.
    Best,
    /// The square-law envelope on a Nyquist-rate carrier.
    Carrier,
    /// The inverse NARX model's actuation.
    Narx,
    /// u = 0.
    Zero,
}

/// What the optimization matches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Objective {
    /// The waveform.
    Time,
    /// The spectra E_s compares.
    Spectral,
    /// The spectra the display is expected to deliver, with its learned noise.
    Expected,
}

/// Where the noise weight λ comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Noise {
    /// The model's noise model.
    Learned,
    /// `lambda`.
    Fixed,
}

/// `target`: the recording of the real texture force.
const TARGET: Text =
    Text::new("target", "", "the recording of the real texture force (NAME, relative to the graph file)").required();
/// `channel`: its force channel.
const CHANNEL: Text = Text::new("channel", "force", "its force channel");
/// `model`: the forward model file.
const MODEL: Text = Text::new("model", "", "forward model file (forward.train)").required();
/// `speed`: count only the constant-speed samples at this speed.
const SPEED: Float =
    Float::new("speed", 0.0, 1e4, 0.0, "cm/s", "count only the constant-speed samples at this speed (0 = all)");
/// `tolerance`: the largest relative deviation from `speed`.
const TOLERANCE: Float = Float::new("tolerance", 1e-6, 0.5, 0.02, "1", "largest relative deviation from `speed`");
/// `settle`: how long the speed must have held.
const SETTLE: Float = Float::new("settle", 0.0, 60.0, 0.1, "s", "time the speed must have held");
/// `start`: the starting actuation.
const START: Choice<Start> = Choice::new(
    "start",
    &["best", "carrier", "narx", "zero"],
    &[Start::Best, Start::Carrier, Start::Narx, Start::Zero],
    "best",
    "starting actuation (best: every start, the lowest objective kept)",
);
/// `start_margin`: how much lower another start must end to be kept over the carrier's.
const START_MARGIN: Float = Float::new(
    "start_margin",
    0.0,
    1.0,
    0.05,
    "1",
    "start = best: another start is kept over the carrier's only when its objective ends lower by this fraction",
);
/// `narx_model`: the inverse NARX model file.
const NARX_MODEL: Text = Text::new("narx_model", "", "inverse NARX model for start = \"narx\"");
/// `objective`: what to match.
const OBJECTIVE: Choice<Objective> = Choice::new(
    "objective",
    &["time", "spectral", "expected"],
    &[Objective::Time, Objective::Spectral, Objective::Expected],
    "expected",
    "what to match (`expected`: chosen by measurement, docs/synthesis.md)",
);
/// `nfft`: the spectral objective's segment length.
const NFFT: Int = Int::new("nfft", 0, 1 << 20, 0, "samples", "spectral objective: segment length (0 = the rate)");
/// `window`: the spectral objective's window, arriving as a [`Window`].
const WINDOW: Choice<Window> =
    Choice::new("window", &["rect", "hann"], &[Window::Rect, Window::Hann], "rect", "spectral objective: window");
/// `overlap`: the spectral objective's overlap of segments.
const OVERLAP: Float = Float::new("overlap", 0.0, 0.9, 0.0, "1", "spectral objective: overlap of segments");
/// `fmin`: the spectral objective's lowest frequency.
const FMIN: Float = Float::new("fmin", 0.0, 1e7, 2.0, "Hz", "spectral objective: lowest frequency");
/// `fmax`: the spectral objective's highest frequency.
const FMAX: Float = Float::new("fmax", 0.0, 1e7, 200.0, "Hz", "spectral objective: highest frequency (0 = Nyquist)");
/// `noise`: where the noise weight comes from.
const NOISE: Choice<Noise> = Choice::new(
    "noise",
    &["learned", "fixed"],
    &[Noise::Learned, Noise::Fixed],
    "learned",
    "noise weight from the model, or `lambda`",
);
/// `lambda`: the fixed noise weight λ.
const LAMBDA: Float = Float::new("lambda", 0.0, 1e6, 0.0, "1", "noise weight λ when noise = \"fixed\"");
/// `iterations`: the largest number of optimizer iterations.
const ITERATIONS: Int = Int::new("iterations", 0, 100_000, 100, "1", "largest number of optimizer iterations");
/// `bound`: the actuation's bound.
const BOUND: Float = Float::new("bound", 1e-6, 2.0, 1.0, "1", "|u| ≤ bound");
/// `record_time`: whether the synthesis time is reported.
const RECORD_TIME: Flag =
    Flag::new("record_time", true, "report the synthesis time as the `seconds` value (off: identical reruns)");

/// A band error, naming this node's parameter.
fn band_error(e: BandError) -> NodeError {
    e.naming([FMIN.name(), FMAX.name(), NFFT.name()])
}

/// The output bound the stability suite checks: |u| ≤ `bound`.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    Some(("u", b.num(&BOUND.spec()), "|u| ≤ bound".into()))
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let (force, keep) = target(p, ctx)?;
    let model = ForwardModel::load(&ctx.path(MODEL.get(p)))?;
    if (model.rate_hz - ctx.rate).abs() > 1e-9 * ctx.rate {
        return Err(NodeError::param(
            MODEL.name(),
            format!("the model was identified at {} Hz, the node runs at {} Hz", model.rate_hz, ctx.rate),
        ));
    }
    let bound = BOUND.get(p);
    let starts = starts(p, ctx, &force, &keep, &model, bound)?;
    let (objective, objective_used) = objective(p, ctx, &keep)?;
    let noise = match NOISE.get(p) {
        Noise::Fixed => NoiseWeight::Fixed(LAMBDA.get(p)),
        Noise::Learned => NoiseWeight::Learned,
    };
    let cfg = SynthConfig {
        objective,
        noise,
        bound,
        options: Options { max_iter: ITERATIONS.count(p), ..Options::default() },
    };
    Ok(Box::new(Optimize {
        force,
        keep,
        starts,
        margin: START_MARGIN.get(p),
        objective_used,
        model,
        cfg,
        u: None,
        summary: Summary::default(),
        pos: 0,
        record_time: RECORD_TIME.get(p),
    }))
}

/// The target force (the `channel` of the `target` recording) and the
/// samples that count (where the recording's velocity holds `speed`, or
/// all).
fn target(p: &Params, ctx: &BuildContext) -> Result<(Vec<f64>, Vec<bool>), NodeError> {
    let shown = TARGET.get(p);
    let channel = CHANNEL.get(p);
    let speed = SPEED.get(p);
    let mut wanted = vec![channel.to_string()];
    if speed > 0.0 {
        wanted.push("velocity".into());
    }
    let rec = Recording::open_channels(&ctx.path(shown), &wanted)?;
    if (rec.rate() - ctx.rate).abs() > 1e-9 * ctx.rate {
        return Err(NodeError::param(
            TARGET.name(),
            format!("{shown} was recorded at {} Hz, the node runs at {} Hz", rec.rate(), ctx.rate),
        ));
    }
    let force = rec.channel(channel).unwrap_or_default().to_vec();
    let keep = if speed > 0.0 {
        let v = rec.channel("velocity").unwrap_or_default();
        SpeedRule::new(speed, TOLERANCE.get(p), SETTLE.get(p), ctx.rate, 0.0).gate(v)
    } else {
        vec![true; force.len()]
    };
    if !keep.iter().any(|k| *k) {
        return Err(NodeError::param(
            SPEED.name(),
            format!("{shown}: its velocity never holds {speed} cm/s within the tolerance; is the speed right?"),
        ));
    }
    Ok((force, keep))
}

/// The starting actuations `start` asks for, each named.
fn starts(
    p: &Params,
    ctx: &BuildContext,
    force: &[f64],
    keep: &[bool],
    model: &ForwardModel,
    bound: f64,
) -> Result<Vec<(String, Vec<f64>)>, NodeError> {
    let narx_start = |why: &str| -> Result<Vec<f64>, NodeError> {
        let path = NARX_MODEL.get(p);
        if path.is_empty() {
            return Err(NodeError::param(NARX_MODEL.name(), format!("{why} needs the inverse model's file")));
        }
        let m = Model::load(&ctx.path(path))?;
        Ok(m.closed_loop()?.run(force).into_iter().map(|u| u.clamp(-bound, bound)).collect())
    };
    let kappa = model.carrier_gain_n;
    let kappa_positive = kappa.is_finite() && kappa > 0.0;
    let has_narx = !NARX_MODEL.get(p).is_empty();
    Ok(match START.get(p) {
        Start::Narx => vec![("narx".into(), narx_start("start = \"narx\"")?)],
        Start::Zero => vec![("zero".into(), vec![0.0; force.len()])],
        // Every start there is; the objective picks.
        Start::Best => {
            let mut v = Vec::new();
            if kappa_positive {
                v.push(("carrier".into(), carrier(force, keep, kappa, bound)?));
            }
            if has_narx {
                v.push(("narx".into(), narx_start("start = \"narx\"")?));
            }
            if v.is_empty() {
                v.push(("zero (no carrier gain, no inverse model)".into(), vec![0.0; force.len()]));
            }
            v
        }
        // A model whose carrier gain is not positive (a display whose force the
        // model hardly explains) gives the square-law start no meaning: start
        // from the inverse model when one is given.
        Start::Carrier if has_narx && !kappa_positive => {
            vec![("narx (the model's carrier gain is not positive)".into(), narx_start("the fallback start")?)]
        }
        Start::Carrier => vec![("carrier".into(), carrier(force, keep, kappa, bound)?)],
    })
}

/// The objective `objective` asks for over the counted samples `keep`,
/// and its name for the summary. A counted stretch shorter than one
/// spectral segment (one pass at 7 cm/s keeps less than a second) has no
/// spectrum: the spectral objectives give way to the waveform, and the
/// summary says so.
fn objective(p: &Params, ctx: &BuildContext, keep: &[bool]) -> Result<(ObjectiveKind, &'static str), NodeError> {
    let nfft = match NFFT.count(p) {
        0 => ctx.rate.round() as usize,
        n => n,
    };
    let short = keep.iter().filter(|k| **k).count() < nfft;
    Ok(match OBJECTIVE.get(p) {
        Objective::Expected | Objective::Spectral if short => {
            (ObjectiveKind::Time, "time (fewer counted samples than one spectral segment)")
        }
        Objective::Expected => {
            let band = Band::new(ctx.rate, nfft, FMIN.get(p), FMAX.get(p), false).map_err(band_error)?;
            let cfg = SpectrumConfig { rate: ctx.rate, nfft, window: Window::Hann, overlap: 0.5 };
            (ObjectiveKind::Expected { cfg, band }, "expected")
        }
        Objective::Spectral => {
            let window = WINDOW.get(p);
            let band = Band::new(ctx.rate, nfft, FMIN.get(p), FMAX.get(p), false).map_err(band_error)?;
            let cfg = SpectrumConfig { rate: ctx.rate, nfft, window, overlap: OVERLAP.get(p) };
            (ObjectiveKind::Spectral { cfg, band }, "spectral")
        }
        Objective::Time => (ObjectiveKind::Time, "time"),
    })
}

impl Optimize {
    fn run(&mut self) -> Result<(), NodeError> {
        let mut results = Vec::with_capacity(self.starts.len());
        for (name, start) in &self.starts {
            results.push((name.as_str(), synthesize(&self.model, &self.force, &self.keep, start, &self.cfg)?));
        }
        // The first start (the carrier, when it is tried) is kept unless another
        // ends lower by more than `start_margin`: objectives within a few per
        // cent of each other do not tell which start plays better
        // (docs/synthesis.md §1).
        let mut kept = 0;
        for k in 1..results.len() {
            if results[k].1.objective_end < (1.0 - self.margin) * results[kept].1.objective_end {
                kept = k;
            }
        }
        let evaluations: usize = results.iter().map(|(_, r)| r.evaluations).sum();
        let seconds: f64 = results.iter().map(|(_, r)| r.seconds).sum();
        let mut summary = Summary::default();
        for (name, r) in &results {
            summary = summary.line(format!(
                "from the {name} start, objective {}: {:.4} → {:.4} in {} iterations ({})",
                self.objective_used,
                r.objective_start,
                r.objective_end,
                r.history.len() - 1,
                r.stop.describe()
            ));
        }
        let (name, s) = results.swap_remove(kept);
        summary = summary
            .value("objective_start", s.objective_start, "1")
            .value("objective_end", s.objective_end, "1")
            .value("iterations", (s.history.len() - 1) as f64, "1")
            .value("evaluations", evaluations as f64, "1")
            .value("lambda", s.lambda, "1")
            .value("starts", self.starts.len() as f64, "1")
            .line(format!(
                "synthesized {} samples: kept the {name} start's ({} of {} tried), {seconds:.3} s in all",
                s.u.len(),
                kept + 1,
                self.starts.len()
            ));
        if self.record_time {
            summary = summary.value("seconds", seconds, "s");
        }
        self.summary = summary;
        self.u = Some(s.u);
        Ok(())
    }
}

impl Node for Optimize {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        if self.u.is_none() {
            // Offline only: the whole synthesis runs once, on the first block.
            self.run()?;
        }
        let u = self.u.as_deref().unwrap_or_default();
        let out = io.output(U);
        let start = self.pos.min(u.len());
        let k = out.len().min(u.len() - start);
        out[..k].copy_from_slice(&u[start..start + k]);
        out[k..].fill(0.0);
        self.pos = self.pos.saturating_add(out.len());
        Ok(())
    }

    fn reset(&mut self) {
        self.pos = 0;
    }

    fn remaining(&self) -> Option<u64> {
        Some(self.force.len().saturating_sub(self.pos) as u64)
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(std::mem::take(&mut self.summary))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One default per parameter (issue 37, point 7): the node's objective
    /// is the one the shipped graph and docs/synthesis.md call the default.
    #[test]
    fn the_default_objective_is_the_measured_one_the_shipped_graph_sets() {
        use evflow_engine::spec::ParamDefault;
        assert!(matches!(OBJECTIVE.spec().default, ParamDefault::Text("expected")));
        let graph = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/synthesize-optimized.toml");
        let text = std::fs::read_to_string(graph).unwrap();
        assert!(text.lines().any(|l| l.starts_with("objective = \"expected\"")), "{text}");
    }
    use crate::recording::format::{Channel, RecordingMeta, RecordingWriter};
    use crate::synth::model_file::Training;
    use crate::synth::volterra_fit::{fit, FitConfig};
    use evflow_engine::harness::Single;

    /// A forward model of a square law behind a two-tap filter, and a
    /// texture force of `n` samples, written into `dir`.
    fn fixtures(dir: &std::path::Path, n: usize) {
        let u: Vec<f64> = (0..3000).map(|k| ((k * 7919) % 1000) as f64 / 500.0 - 1.0).collect();
        let y: Vec<f64> =
            (0..u.len()).map(|k| (0.8 * u[k] - 0.3 * if k > 0 { u[k - 1] } else { 0.0 }).powi(2)).collect();
        let cfg = FitConfig { memory: 4, ..FitConfig::default() };
        let fitted = fit(&u, &y, &vec![true; u.len()], &cfg).unwrap();
        let training = Training {
            scores: fitted.scores,
            actuation_rms: 0.5,
            actuation_peak: 1.0,
            data_hash: String::new(),
            seconds: 0.0,
        };
        ForwardModel::new(
            &fitted.model,
            1000.0,
            &cfg.filter,
            Default::default(),
            fitted.noise,
            fitted.spectrum,
            training,
        )
        .save(&dir.join("f.json"))
        .unwrap();
        let meta = RecordingMeta::new(1000.0, vec![Channel::new("force", "N")]);
        let mut w = RecordingWriter::create(&dir.join("short.wav"), meta).unwrap();
        for k in 0..n {
            w.write_frame(&[0.05 * (k as f64 * 0.2).sin()]).unwrap();
        }
        w.finish().unwrap();
    }

    #[test]
    fn a_target_shorter_than_one_spectral_segment_is_matched_by_its_waveform_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        fixtures(dir.path(), 600);
        for (objective, used) in [("expected", "objective time (fewer counted samples"), ("time", "objective time:")] {
            let params = format!("target = \"short\"\nmodel = \"f.json\"\nobjective = \"{objective}\"\niterations = 5");
            let single = Single::new(&SPEC, &params).output("u").ticks(600).block(128).base_dir(dir.path());
            let u = single.run().unwrap_or_else(|e| panic!("{objective}: {e}")).remove(0);
            assert_eq!(u.len(), 600);
            assert!(u.iter().all(|v| v.is_finite() && v.abs() <= 1.0));
            let lines = single.summary().unwrap().lines.join("\n");
            assert!(lines.contains(used), "{objective}: {lines}");
        }
    }
}
