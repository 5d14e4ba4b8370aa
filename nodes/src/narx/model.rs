//! The model file: a self-describing, versioned JSON document holding
//! everything needed to run a trained NARX inverse model and to know where
//! it came from.
//!
//! ```json
//! {
//!   "format": "evflow-narx-model",
//!   "version": 1,
//!   "rate_hz": 1000,
//!   "architecture": { "inputs": 24, "hidden": [15, 10, 5],
//!                     "hidden_activation": "tanh", "output_activation": "linear" },
//!   "delays": { "feedback": 2, "input": 20, "lookahead": 2 },
//!   "normalization": { "x": { "min": -0.2, "max": 0.3 }, "y": { "min": -1, "max": 1 } },
//!   "condition": { "mass_g": 85, "speed_cm_s": 4 },
//!   "training": { "algorithm": "lm", "data_hash": "fnv1a64:…", … },
//!   "weights": [ … ]
//! }
//! ```
//!
//! `normalization` holds MATLAB `mapminmax` settings ([`MapMinMax`]) of the
//! force `x` and the actuation `y`; `weights` is the flat vector of
//! [`Mlp::weights`]. Files are written to `NAME.tmp` and renamed, so a
//! crash never leaves a half-written model. Reading checks the format name
//! and version first — a newer version is refused with a message saying so
//! — then every field; each error names the file and the field.

use super::closed_loop::ClosedLoop;
use super::error::NarxError;
use super::mapminmax::MapMinMax;
use super::net::Mlp;
use super::packed::Tanh;
use super::taps::Taps;
use super::train::StopReason;
use crate::model_file_error::ModelFileErrors;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The value of the `format` field.
pub const FORMAT: &str = "evflow-narx-model";
/// The format version this code writes and reads.
pub const VERSION: u64 = 1;

/// Network shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Architecture {
    /// Network inputs (k_y + k_x + d + 1).
    pub inputs: usize,
    /// Hidden layer sizes.
    pub hidden: Vec<usize>,
    /// Hidden activation; only `tanh`.
    pub hidden_activation: String,
    /// Output activation; only `linear`.
    pub output_activation: String,
}

/// Normalization of input and output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Normalization {
    /// Force (network input).
    pub x: MapMinMax,
    /// Actuation (network output).
    pub y: MapMinMax,
}

/// The experimental condition the model was trained for (§5.2.2: one
/// network per load and scanning speed).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Condition {
    /// Stylus mass, g (None: not recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_g: Option<f64>,
    /// Scanning speed, cm/s (None: not recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_cm_s: Option<f64>,
}

/// Closed-loop accuracy on the validation block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClosedLoopScore {
    /// Fraction of samples where the estimate and the reference have the same sign.
    pub sign_agreement: f64,
    /// Fraction of sample pairs (n−1, n) where the estimate changes sign
    /// exactly when the reference does: the part of a binary actuation an
    /// even (square-law) display makes visible whatever the global sign.
    pub transition_agreement: f64,
    /// RMS of estimate − reference, actuation units (at most f64::MAX).
    pub rms: f64,
    /// Samples compared.
    pub samples: usize,
}

/// How the model was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Training {
    /// `lm` or `adam`.
    pub algorithm: String,
    /// FNV-1a 64-bit hash of the training data (force and actuation, as f64 bits).
    pub data_hash: String,
    /// Samples of the recording.
    pub samples: usize,
    /// Regressor rows in the training block.
    pub train_rows: usize,
    /// Regressor rows in the validation block (the last ones).
    pub validation_rows: usize,
    /// Epochs run.
    pub epochs: usize,
    /// The epoch whose weights were kept.
    pub best_epoch: usize,
    /// Why training stopped.
    pub stop: StopReason,
    /// Open-loop MSE on the training block (normalized units).
    pub train_mse: f64,
    /// Open-loop MSE on the validation block (normalized units; null without one).
    pub validation_mse: Option<f64>,
    /// Closed-loop accuracy on the validation block, the loop started from
    /// the true states before the block (null without a validation block).
    pub closed_loop: Option<ClosedLoopScore>,
    /// The same with the force replaced by Gaussian noise of the same RMS:
    /// near chance (0.5) when the network reads the force; as high as
    /// `closed_loop` when it predicts u from its own past instead.
    pub closed_loop_noise_force: Option<ClosedLoopScore>,
    /// Wall-clock training time, s.
    pub seconds: f64,
    /// Seed of the initial weights.
    pub seed: u64,
}

/// A trained model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] when written by this code.
    pub version: u64,
    /// Sample rate of the training data, Hz: the taps count samples at this rate.
    pub rate_hz: f64,
    /// Network shape.
    pub architecture: Architecture,
    /// Taps and look-ahead.
    pub delays: Taps,
    /// Normalization.
    pub normalization: Normalization,
    /// Experimental condition.
    #[serde(default)]
    pub condition: Condition,
    /// Training record.
    pub training: Training,
    /// Weights and biases, flat ([`Mlp::weights`]).
    pub weights: Vec<f64>,
}

/// FNV-1a, 64 bits, over the bit patterns of the samples: a fingerprint of
/// the training data (not a cryptographic hash).
pub fn data_hash(series: &[&[f64]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for s in series {
        for v in s.iter() {
            for b in v.to_bits().to_le_bytes() {
                h ^= b as u64;
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    format!("fnv1a64:{h:016x}")
}

impl Model {
    /// The network.
    pub fn network(&self) -> Result<Mlp, NarxError> {
        Mlp::with_weights(self.architecture.inputs, &self.architecture.hidden, self.weights.clone())
    }

    /// A closed loop running this model (exact tanh).
    pub fn closed_loop(&self) -> Result<ClosedLoop, NarxError> {
        self.closed_loop_with(Tanh::Exact)
    }

    /// A closed loop running this model with the given tanh.
    pub fn closed_loop_with(&self, tanh: Tanh) -> Result<ClosedLoop, NarxError> {
        Ok(ClosedLoop::with_tanh(self.network()?, self.delays, self.normalization.x, self.normalization.y, tanh))
    }

    /// Checks every field; errors name `path` and the field.
    pub fn validate(&self, path: &Path) -> Result<(), NarxError> {
        let f = |field: &str, m: String| Err(NarxError::field(path, field, m));
        if self.format != FORMAT {
            return f("format", format!("`{}` is not `{FORMAT}`", self.format));
        }
        if self.version != VERSION {
            return Err(NarxError::version(path, self.version, VERSION));
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return f("rate_hz", format!("{} is not a sample rate", self.rate_hz));
        }
        let a = &self.architecture;
        if a.hidden_activation != "tanh" {
            return f("architecture.hidden_activation", format!("`{}` is not supported (tanh)", a.hidden_activation));
        }
        if a.output_activation != "linear" {
            return f("architecture.output_activation", format!("`{}` is not supported (linear)", a.output_activation));
        }
        if let Some(i) = a.hidden.iter().position(|&s| s == 0 || s > 10_000) {
            return f(&format!("architecture.hidden[{i}]"), format!("{} neurons is not a usable layer", a.hidden[i]));
        }
        if let Err(m) = self.delays.validate() {
            return f("delays.lookahead", m);
        }
        if self.delays.feedback > 100_000 || self.delays.input > 100_000 || self.delays.lookahead > 100_000 {
            return f("delays", "more than 100000 taps".into());
        }
        if a.inputs != self.delays.n_inputs() {
            return f(
                "architecture.inputs",
                format!(
                    "{} inputs, but the delays give {} (feedback {} + input {} + look-ahead {} + 1)",
                    a.inputs,
                    self.delays.n_inputs(),
                    self.delays.feedback,
                    self.delays.input,
                    self.delays.lookahead
                ),
            );
        }
        for (name, m) in [("x", self.normalization.x), ("y", self.normalization.y)] {
            if !(m.min.is_finite() && m.max.is_finite()) || m.max < m.min {
                return f(
                    &format!("normalization.{name}"),
                    format!("min {} and max {} are not a finite range", m.min, m.max),
                );
            }
        }
        let want = Mlp::new(a.inputs, &a.hidden)?.n_params();
        if self.weights.len() != want {
            return f("weights", format!("{} values, the architecture needs {want}", self.weights.len()));
        }
        if let Some(i) = self.weights.iter().position(|w| !w.is_finite()) {
            return f(&format!("weights[{i}]"), "not a finite number".into());
        }
        Ok(())
    }

    /// Reads and checks a model file.
    pub fn load(path: &Path) -> Result<Self, NarxError> {
        let text = evflow_engine::files::read_regular_to_string(path)
            .map_err(|e| NarxError::io(path, format!("cannot read the model: {e}")))?;
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| NarxError::parse(path, e.to_string()))?;
        // Format and version first, so a newer file is refused for what it is.
        match value.get("format").and_then(|v| v.as_str()) {
            Some(FORMAT) => {}
            Some(other) => return Err(NarxError::field(path, "format", format!("`{other}` is not `{FORMAT}`"))),
            None => return Err(NarxError::field(path, "format", format!("missing (expected `{FORMAT}`)"))),
        }
        match value.get("version").and_then(|v| v.as_u64()) {
            Some(VERSION) => {}
            Some(found) => return Err(NarxError::version(path, found, VERSION)),
            None => return Err(NarxError::field(path, "version", "missing or not a whole number")),
        }
        let model: Model = serde_path_to_error(value, path)?;
        model.validate(path)?;
        Ok(model)
    }

    /// Writes the model to `path` (through `path.tmp` and a rename).
    pub fn save(&self, path: &Path) -> Result<(), NarxError> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| NarxError::io(path, format!("cannot encode the model: {e}")))?;
        crate::recording::atomic::write_atomically(path, &text)
            .map_err(|e| NarxError::io(path, format!("cannot write the model: {e}")))
    }
}

/// Deserializes the model, naming the field that failed.
fn serde_path_to_error(value: serde_json::Value, path: &Path) -> Result<Model, NarxError> {
    // serde_json names the missing or mistyped field in its message; the
    // top-level key it failed in is found by trying each known section.
    match serde_json::from_value::<Model>(value.clone()) {
        Ok(m) => Ok(m),
        Err(e) => {
            let sections = ["rate_hz", "architecture", "delays", "normalization", "condition", "training", "weights"];
            let field = sections
                .iter()
                .find(|s| match value.get(**s) {
                    None => e.to_string().contains(&format!("`{s}`")),
                    Some(v) => !section_ok(s, v),
                })
                .copied()
                .unwrap_or("(model)");
            Err(NarxError::field(path, field, e.to_string()))
        }
    }
}

fn section_ok(section: &str, v: &serde_json::Value) -> bool {
    let v = v.clone();
    match section {
        "rate_hz" => serde_json::from_value::<f64>(v).is_ok(),
        "architecture" => serde_json::from_value::<Architecture>(v).is_ok(),
        "delays" => serde_json::from_value::<Taps>(v).is_ok(),
        "normalization" => serde_json::from_value::<Normalization>(v).is_ok(),
        "condition" => serde_json::from_value::<Condition>(v).is_ok(),
        "training" => serde_json::from_value::<Training>(v).is_ok(),
        "weights" => serde_json::from_value::<Vec<f64>>(v).is_ok(),
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small, valid model (2 feedback, 2 input taps, look-ahead 1, one hidden layer of 3).
    pub(crate) fn small() -> Model {
        let delays = Taps { feedback: 2, input: 2, lookahead: 1 };
        let inputs = delays.n_inputs();
        let n = Mlp::new(inputs, &[3]).unwrap().n_params();
        Model {
            format: FORMAT.into(),
            version: VERSION,
            rate_hz: 1000.0,
            architecture: Architecture {
                inputs,
                hidden: vec![3],
                hidden_activation: "tanh".into(),
                output_activation: "linear".into(),
            },
            delays,
            normalization: Normalization { x: MapMinMax { min: -0.3, max: 0.7 }, y: MapMinMax { min: -1.0, max: 1.0 } },
            condition: Condition { mass_g: Some(85.0), speed_cm_s: Some(4.0) },
            training: Training {
                algorithm: "lm".into(),
                data_hash: data_hash(&[&[1.0, 2.0]]),
                samples: 1000,
                train_rows: 800,
                validation_rows: 150,
                epochs: 12,
                best_epoch: 6,
                stop: StopReason::ValidationStop,
                train_mse: 0.1,
                validation_mse: Some(0.2),
                closed_loop: Some(ClosedLoopScore {
                    sign_agreement: 0.5,
                    transition_agreement: 0.9,
                    rms: 1.3,
                    samples: 150,
                }),
                closed_loop_noise_force: None,
                seconds: 0.5,
                seed: 3,
            },
            weights: (0..n).map(|i| (i as f64 * 0.731).sin() / 3.0).collect(),
        }
    }

    fn edit(text: &str, f: impl FnOnce(&mut serde_json::Value)) -> String {
        let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
        f(&mut v);
        serde_json::to_string_pretty(&v).unwrap()
    }

    #[test]
    fn saves_and_loads_bit_for_bit_through_a_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/model.json");
        let m = small();
        m.save(&path).unwrap();
        assert!(!dir.path().join("sub/model.json.tmp").exists());
        let back = Model::load(&path).unwrap();
        assert_eq!(back, m);
        assert!(back.weights.iter().zip(&m.weights).all(|(a, b)| a.to_bits() == b.to_bits()));
        // Overwriting replaces the file whole.
        let mut m2 = small();
        m2.weights[0] = 0.125;
        m2.save(&path).unwrap();
        assert_eq!(Model::load(&path).unwrap().weights[0], 0.125);
        // The file is self-describing JSON.
        let text = std::fs::read_to_string(&path).unwrap();
        for key in [
            "\"format\": \"evflow-narx-model\"",
            "\"version\": 1",
            "\"hidden\"",
            "\"lookahead\": 1",
            "\"mass_g\": 85.0",
        ] {
            assert!(text.contains(key), "{key} missing in\n{text}");
        }
    }

    #[test]
    fn a_write_that_fails_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        // The target is a folder: the rename fails, the temporary file is removed.
        let path = dir.path().join("taken");
        std::fs::create_dir(&path).unwrap();
        let e = small().save(&path).unwrap_err();
        assert!(matches!(e, NarxError::File(crate::model_file_error::ModelFileError::Io { .. })), "{e}");
        assert!(e.to_string().contains("taken"), "{e}");
        assert!(!dir.path().join("taken.tmp").exists());
    }

    #[test]
    fn bad_files_are_refused_naming_the_file_and_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        let good = serde_json::to_string_pretty(&small()).unwrap();
        let cases: Vec<(String, &str)> = vec![
            ("{ \"format\": ".into(), "not a NARX model file"),
            ("[1, 2]".into(), "field `format`: missing"),
            (edit(&good, |v| v["format"] = "other".into()), "field `format`: `other`"),
            (edit(&good, |v| v["version"] = 2.into()), "version 2 is not supported (this evflow reads version 1)"),
            (edit(&good, |v| v["version"] = 0.into()), "version 0 is not supported"),
            (edit(&good, |v| v["version"] = "one".into()), "field `version`"),
            (edit(&good, |v| v.as_object_mut().unwrap().remove("delays").map(drop).unwrap()), "field `delays`"),
            (edit(&good, |v| v["delays"]["input"] = (-3).into()), "field `delays`"),
            (edit(&good, |v| v["training"]["stop"] = "bored".into()), "field `training`"),
            (edit(&good, |v| v["weights"][2] = serde_json::Value::Null), "field `weights`"),
            (
                edit(&good, |v| v["weights"].as_array_mut().unwrap().pop().map(drop).unwrap()),
                "field `weights`: 24 values, the architecture needs 25",
            ),
            (edit(&good, |v| v["architecture"]["inputs"] = 7.into()), "field `architecture.inputs`: 7 inputs"),
            (edit(&good, |v| v["architecture"]["hidden"][0] = 0.into()), "field `architecture.hidden[0]`"),
            (edit(&good, |v| v["architecture"]["hidden_activation"] = "relu".into()), "hidden_activation"),
            (edit(&good, |v| v["normalization"]["x"]["min"] = 5.into()), "field `normalization.x`"),
            (edit(&good, |v| v["delays"]["lookahead"] = (-5).into()), "field `delays.lookahead`"),
            (edit(&good, |v| v["rate_hz"] = 0.into()), "field `rate_hz`: 0 is not a sample rate"),
            (edit(&good, |v| v.as_object_mut().unwrap().remove("rate_hz").map(drop).unwrap()), "field `rate_hz`"),
        ];
        for (text, want) in cases {
            std::fs::write(&path, &text).unwrap();
            let e = Model::load(&path).unwrap_err().to_string();
            assert!(e.contains("m.json"), "{e}");
            assert!(e.contains(want), "want `{want}` in: {e}");
        }
        let e = Model::load(&dir.path().join("missing.json")).unwrap_err().to_string();
        assert!(e.contains("missing.json") && e.contains("cannot read"), "{e}");
    }

    #[test]
    fn the_data_hash_sees_every_bit() {
        let a = data_hash(&[&[1.0, 2.0], &[3.0]]);
        assert!(a.starts_with("fnv1a64:") && a.len() == 8 + 16);
        assert_ne!(a, data_hash(&[&[1.0, 2.0], &[3.0 + f64::EPSILON * 2.0]]));
        assert_ne!(data_hash(&[&[0.0]]), data_hash(&[&[-0.0]]));
        assert_eq!(a, data_hash(&[&[1.0, 2.0], &[3.0]]));
    }
}
