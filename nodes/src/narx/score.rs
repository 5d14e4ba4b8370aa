//! `narx.score`: an inverse NARX model judged on a recording it was not
//! trained on, with the closed-loop scores `narx.train` gives its own
//! validation block.

use super::fit::closed_loop_score;
use super::model::Model;
use super::node::MODEL;
use super::pairs::GatedPairs;
use crate::filters::segment::{Gates, GATES};
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::Int;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, Summary};
use std::path::PathBuf;

/// Declaration of `narx.score`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "narx.score",
    "narx",
    Role::Sink,
    "Scores an inverse NARX model on a recording of force and actuation it was not trained on (closed loop).",
    build,
)
.doc(
    "Dissertation §5.2.1, Fig. 5.4: the closed-loop estimate of the actuation against the actuation \
     that produced the force. The node buffers the force `x` and the actuation `y` (kept where every \
     gate is above 0.5, as `narx.train` keeps them, e.g. the constant-speed stretches from `segment`), \
     and when the stream ends runs the model `model` closed loop over them — started from the true \
     actuation over a warm-up of k_x + k_y + 50 samples, then on its own estimates — and scores the \
     estimate with `narx.train`'s validation scores: `sign_agreement` (the level of a binary \
     excitation, 0.5 is chance), `transition_agreement` (the changes of level a square-law display \
     makes felt whatever the sign) and `rms` (its squares scaled where they would overflow, so a \
     finite recording, even near ±f64::MAX, gives a finite RMS; cut at f64::MAX if it lies beyond); \
     then once more with the force replaced by Gaussian noise \
     of its RMS (`noise_force_transition_agreement`, which stays near chance for a model that reads the \
     force). `samples` counts the scored samples. The model's rate must be the node's rate.\n\n\
     Use: a second excitation recording per condition, kept in a folder of its own \
     (graphs/model-validate-recordings.toml, docs/rig.md).\n\n\
     Checked against: a model trained on one simulated recording scores a second recording of the same \
     condition well above chance and the noise-force run near it (nodes/src/narx/score.rs tests; \
     tests/rig_recordings.rs end to end).",
)
.ports(PORTS)
.params(&[MODEL.spec(), GATES.spec(), SEED.spec()])
.example("model = \"models/narx.json\"");

/// The ports: force, actuation and the gates.
const PORTS: &[PortSpec] = &[
    PortSpec::input("x", "N", "force, the network's input (preprocessed as for training)"),
    PortSpec::input("y", "1", "actuation that produced the force, the reference"),
    PortSpec::input("gate", "1", "one per `gate` entry: the sample is scored only where every gate is above 0.5")
        .per(GATES.name()),
];
/// The force.
const X: InPort = InPort::named(PORTS, "x");
/// The actuation, the reference.
const Y: InPort = InPort::named(PORTS, "y");
/// The first gate.
const GATE: InPort = InPort::named(PORTS, "gate");

/// `seed`: the seed of the noise force.
const SEED: Int = Int::new("seed", 0, i64::MAX, 1, "1", "seed of the noise force");

struct Score {
    model: Model,
    shown: String,
    seed: u64,
    pairs: GatedPairs,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let shown = MODEL.get(p).to_string();
    let path: PathBuf = ctx.path(&shown);
    let model = Model::load(&path).map_err(|e| NodeError::param(MODEL.name(), e.to_string()))?;
    let rate = model.rate_hz;
    if (rate - ctx.rate).abs() > 1e-9 * ctx.rate {
        return Err(NodeError::param(
            MODEL.name(),
            format!(
                "{shown} was trained at {rate} Hz; this node runs at {} Hz (resample to the model's rate)",
                ctx.rate
            ),
        ));
    }
    let pairs = GatedPairs::new(X, Y, Gates::from_params(p, GATE)?);
    Ok(Box::new(Score { model, shown, seed: SEED.get(p) as u64, pairs }))
}

impl Node for Score {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.pairs.reserve(ctx.max_block);
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        self.pairs.push(io, 0, usize::MAX);
        Ok(())
    }

    fn reset(&mut self) {
        self.pairs.clear();
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let (x, y) = (&self.pairs.x, &self.pairs.y);
        if let Some(k) = x.iter().chain(y).position(|v| !v.is_finite()) {
            let (what, i) = if k < x.len() { ("force", k) } else { ("actuation", k - x.len()) };
            return Err(NodeError::Data(format!("the {what} sample {i} is not finite")));
        }
        let warm = self.model.delays.input + self.model.delays.feedback + 50;
        let too_short = || {
            NodeError::Data(format!(
                "{} samples to score: at least {} are needed (a warm-up of {warm}, then one)",
                x.len(),
                warm + 1
            ))
        };
        if x.len() <= warm {
            return Err(too_short());
        }
        let with = closed_loop_score(&self.model, x, y, warm, None)
            .map_err(|e| NodeError::Data(e.to_string()))?
            .ok_or_else(too_short)?;
        let noise = closed_loop_score(&self.model, x, y, warm, Some(self.seed))
            .map_err(|e| NodeError::Data(e.to_string()))?
            .ok_or_else(too_short)?;
        Ok(Summary::default()
            .value("sign_agreement", with.sign_agreement, "1")
            .value("transition_agreement", with.transition_agreement, "1")
            .value("rms", with.rms, "1")
            .value("noise_force_transition_agreement", noise.transition_agreement, "1")
            .value("samples", with.samples as f64, "1")
            .line(format!("scored {} on {} samples, closed loop", self.shown, with.samples)))
    }
}

#[cfg(all(test, feature = "lab"))]
mod tests {
    use super::super::fit::{fit, FitConfig};
    use super::super::labdata::rbs;
    use super::super::train::Options;
    use super::SPEC;
    use evflow_engine::harness::Single;
    use evflow_engine::Summary;
    use std::path::Path;

    /// A force a square-law display would give for the actuation `u`: its
    /// squared increments, plus a little of u.
    fn force(u: &[f64]) -> Vec<f64> {
        (0..u.len()).map(|i| if i == 0 { 0.0 } else { (u[i] - u[i - 1]).powi(2) + 0.1 * u[i] }).collect()
    }

    fn score(dir: &Path, x: Vec<f64>, y: Vec<f64>, rate: f64) -> Result<Summary, String> {
        let n = x.len() as u64;
        Single::new(&SPEC, "model = \"m.json\"")
            .input("x", x, rate)
            .input("y", y, rate)
            .base_rate(rate)
            .ticks(n)
            .block(256)
            .base_dir(dir)
            .summary()
    }

    #[test]
    fn a_model_scores_a_sequence_it_never_saw_and_noise_does_not() {
        let dir = tempfile::tempdir().unwrap();
        let u = rbs(3000, 4);
        let cfg = FitConfig {
            hidden: vec![6],
            feedback: 1,
            input: 3,
            options: Options { max_epochs: 30, ..Options::default() },
            ..FitConfig::default()
        };
        let model = fit(&force(&u), &u, &cfg, &mut |_| {}).unwrap();
        model.save(&dir.path().join("m.json")).unwrap();
        // Another random binary sequence, never trained on.
        let v = rbs(2000, 99);
        let s = score(dir.path(), force(&v), v.clone(), 1000.0).unwrap();
        let (t, noise) = (s.get("transition_agreement").unwrap(), s.get("noise_force_transition_agreement").unwrap());
        assert!(t > 0.9 && noise < 0.7, "held out {t}, noise force {noise}");
        assert_eq!(s.get("samples"), Some(2000.0 - (3 + 1 + 50) as f64));
        // The model's rate is the node's, and the warm-up needs samples.
        let e = score(dir.path(), force(&v), v.clone(), 2000.0).unwrap_err();
        assert!(e.contains("trained at 1000 Hz") && e.contains("2000 Hz"), "{e}");
        let e = score(dir.path(), force(&v[..40]), v[..40].to_vec(), 1000.0).unwrap_err();
        assert!(e.contains("40 samples to score"), "{e}");
    }

    #[test]
    fn a_recording_near_max_scores_finite() {
        // Force and actuation step 0 → +big → −big → 0: the squares of the
        // error (and of the force, for the noise run) overflowed (rms inf).
        let dir = tempfile::tempdir().unwrap();
        let u = rbs(1500, 4);
        let cfg = FitConfig {
            hidden: vec![4],
            feedback: 1,
            input: 2,
            options: Options { max_epochs: 5, ..Options::default() },
            ..FitConfig::default()
        };
        fit(&force(&u), &u, &cfg, &mut |_| {}).unwrap().save(&dir.path().join("m.json")).unwrap();
        for big in [1e300, f64::MAX] {
            let steps: Vec<f64> = (0..600)
                .map(|i| match i / 150 {
                    1 => big,
                    2 => -big,
                    _ => 0.0,
                })
                .collect();
            let s = score(dir.path(), steps.clone(), steps, 1000.0).unwrap();
            assert!(s.values.iter().all(|(_, v, _)| v.is_finite()), "{s:?}");
            // The estimate stays within the model's actuation range: the
            // error is the reference's ±big over its 300 scored samples.
            let rms = s.get("rms").unwrap();
            assert!((rms - big).abs() <= 1e-12 * big, "{rms:e}");
        }
    }
}
