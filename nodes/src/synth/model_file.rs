//! The forward-model file: a self-describing, versioned JSON document with
//! everything needed to run an identified forward model ([`Volterra`]) and
//! to know where it came from.
//!
//! ```json
//! {
//!   "format": "evflow-forward-model",
//!   "version": 1,
//!   "rate_hz": 1000,
//!   "kind": "volterra2",
//!   "memory": 20,
//!   "output_filter": { "highpass_order": 4, "highpass_hz": 10 },
//!   "condition": { "mass_g": 85, "speed_cm_s": 5 },
//!   "noise": { "floor_n2": 1.1e-4, "per_u2_n2": 6.0e-5 },
//!   "carrier_gain_n": 0.18,
//!   "training": { "samples": 7000, "train_rel_rms": 0.45, "validation_rel_rms": 0.47, … },
//!   "kernel": { "quadratic_upper": [ … ], "linear": [ … ], "constant": 0.0 }
//! }
//! ```
//!
//! `kernel.quadratic_upper` is H's upper triangle row by row
//! ([`super::volterra::upper_index`]); `carrier_gain_n` is derived
//! ([`Volterra::carrier_gain`]) and written for people, and checked on
//! reading. Files are written to `NAME.tmp` and renamed. Reading checks the
//! format name and version first, then every field; each error names the
//! file and the field.

use super::error::SynthError;
use super::output_filter::OutputFilter;
use super::spectral::NoiseSpectrum;
use super::volterra::{Volterra, MAX_MEMORY};
use super::volterra_fit::{FitScores, NoiseModel};
use crate::model_file_error::ModelFileErrors;
use crate::narx::model::Condition;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The value of the `format` field.
pub const FORMAT: &str = "evflow-forward-model";
/// The format version this code writes and reads.
pub const VERSION: u64 = 1;

/// The filter the recorded force went through, which the model's output goes through too.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FilterSpec {
    /// Butterworth high-pass order (0 = none).
    pub highpass_order: usize,
    /// Its cut-off, Hz.
    pub highpass_hz: f64,
}

/// The kernels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kernel {
    /// H's upper triangle, row by row, M(M+1)/2 values.
    pub quadratic_upper: Vec<f64>,
    /// l, M values.
    pub linear: Vec<f64>,
    /// c.
    pub constant: f64,
}

/// How the model was identified.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Training {
    /// Fit scores.
    #[serde(flatten)]
    pub scores: FitScores,
    /// RMS of the actuation over the kept samples.
    pub actuation_rms: f64,
    /// Largest |u| over the kept samples.
    pub actuation_peak: f64,
    /// FNV-1a 64-bit hash of the actuation and force samples.
    pub data_hash: String,
    /// Wall-clock identification time, s (0 when not recorded).
    pub seconds: f64,
}

/// An identified forward model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForwardModel {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] when written by this code.
    pub version: u64,
    /// Sample rate, Hz: the memory counts samples at this rate.
    pub rate_hz: f64,
    /// Model class; only `volterra2`.
    pub kind: String,
    /// Memory M, samples.
    pub memory: usize,
    /// The output filter.
    pub output_filter: FilterSpec,
    /// Experimental condition.
    #[serde(default)]
    pub condition: Condition,
    /// Residual noise against actuation power.
    pub noise: NoiseModel,
    /// Residual spectrum against actuation power (absent when the
    /// recording was shorter than three one-second segments).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_spectrum: Option<NoiseSpectrum>,
    /// κ, the force a unit Nyquist-rate carrier adds, N.
    pub carrier_gain_n: f64,
    /// Identification record.
    pub training: Training,
    /// The kernels.
    pub kernel: Kernel,
}

impl ForwardModel {
    /// A model file's contents for an identified model.
    pub fn new(
        model: &Volterra,
        rate_hz: f64,
        filter: &OutputFilter,
        condition: Condition,
        noise: NoiseModel,
        noise_spectrum: Option<NoiseSpectrum>,
        training: Training,
    ) -> Self {
        Self {
            format: FORMAT.into(),
            version: VERSION,
            rate_hz,
            kind: "volterra2".into(),
            memory: model.memory(),
            output_filter: FilterSpec { highpass_order: filter.order(), highpass_hz: filter.cutoff_hz() },
            condition,
            noise,
            noise_spectrum,
            carrier_gain_n: model.carrier_gain(),
            training,
            kernel: Kernel {
                quadratic_upper: model.upper(),
                linear: model.linear().to_vec(),
                constant: model.constant(),
            },
        }
    }

    /// The model.
    pub fn volterra(&self) -> Result<Volterra, SynthError> {
        Volterra::from_upper(&self.kernel.quadratic_upper, self.kernel.linear.clone(), self.kernel.constant)
    }

    /// The output filter.
    pub fn filter(&self) -> Result<OutputFilter, SynthError> {
        OutputFilter::highpass(self.output_filter.highpass_order, self.output_filter.highpass_hz, self.rate_hz)
    }

    /// Checks every field; errors name `path` and the field.
    pub fn validate(&self, path: &Path) -> Result<(), SynthError> {
        let f = |field: &str, m: String| Err(SynthError::field(path, field, m));
        if self.format != FORMAT {
            return f("format", format!("`{}` is not `{FORMAT}`", self.format));
        }
        if self.version != VERSION {
            return Err(SynthError::version(path, self.version, VERSION));
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return f("rate_hz", format!("{} is not a sample rate", self.rate_hz));
        }
        if self.kind != "volterra2" {
            return f("kind", format!("`{}` is not supported (volterra2)", self.kind));
        }
        let m = self.memory;
        if m == 0 || m > MAX_MEMORY {
            return f("memory", format!("{m} samples is not in 1 ..= {MAX_MEMORY}"));
        }
        if self.kernel.linear.len() != m {
            return f("kernel.linear", format!("{} values, memory {m} needs {m}", self.kernel.linear.len()));
        }
        if self.kernel.quadratic_upper.len() != m * (m + 1) / 2 {
            return f(
                "kernel.quadratic_upper",
                format!("{} values, memory {m} needs {}", self.kernel.quadratic_upper.len(), m * (m + 1) / 2),
            );
        }
        let all =
            self.kernel.quadratic_upper.iter().chain(&self.kernel.linear).chain(std::iter::once(&self.kernel.constant));
        if let Some((i, _)) = all.enumerate().find(|(_, v)| !v.is_finite()) {
            return f("kernel", format!("value {i} is not a finite number"));
        }
        if let Err(e) = self.filter() {
            return f("output_filter", e.to_string());
        }
        for (name, v) in [("noise.floor_n2", self.noise.floor_n2), ("noise.per_u2_n2", self.noise.per_u2_n2)] {
            if !(v.is_finite() && v >= 0.0) {
                return f(name, format!("{v} is not a power ≥ 0"));
            }
        }
        if let Some(ns) = &self.noise_spectrum {
            let bins = ns.nfft / 2 + 1;
            if ns.nfft < 2 || ns.p0.len() != bins || ns.p1.len() != bins {
                return f("noise_spectrum", format!("nfft {} needs {bins} values in p0 and p1", ns.nfft));
            }
            if ns.p0.iter().chain(&ns.p1).any(|v| !(v.is_finite() && *v >= 0.0)) {
                return f("noise_spectrum", "powers must be finite and ≥ 0".into());
            }
        }
        let kappa = self.volterra()?.carrier_gain();
        if (kappa - self.carrier_gain_n).abs() > 1e-9 * kappa.abs().max(1e-12) {
            return f("carrier_gain_n", format!("{} does not match the kernel's {kappa}", self.carrier_gain_n));
        }
        Ok(())
    }

    /// Reads and checks a model file.
    pub fn load(path: &Path) -> Result<Self, SynthError> {
        let text = evflow_engine::files::read_regular_to_string(path)
            .map_err(|e| SynthError::io(path, format!("cannot read the model: {e}")))?;
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| SynthError::parse(path, e.to_string()))?;
        match value.get("format").and_then(|v| v.as_str()) {
            Some(FORMAT) => {}
            Some(other) => return Err(SynthError::field(path, "format", format!("`{other}` is not `{FORMAT}`"))),
            None => return Err(SynthError::field(path, "format", format!("missing (expected `{FORMAT}`)"))),
        }
        match value.get("version").and_then(|v| v.as_u64()) {
            Some(VERSION) => {}
            Some(found) => return Err(SynthError::version(path, found, VERSION)),
            None => return Err(SynthError::field(path, "version", "missing or not a whole number")),
        }
        let model: ForwardModel = match serde_json::from_value(value.clone()) {
            Ok(m) => m,
            Err(e) => {
                let sections = [
                    "rate_hz",
                    "kind",
                    "memory",
                    "output_filter",
                    "condition",
                    "noise",
                    "carrier_gain_n",
                    "training",
                    "kernel",
                ];
                let field = sections
                    .iter()
                    .find(|s| value.get(**s).is_none() && e.to_string().contains(&format!("`{s}`")))
                    .copied()
                    .unwrap_or("(model)");
                return Err(SynthError::field(path, field, e.to_string()));
            }
        };
        model.validate(path)?;
        Ok(model)
    }

    /// Writes the model to `path` (through `path.tmp` and a rename).
    pub fn save(&self, path: &Path) -> Result<(), SynthError> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| SynthError::io(path, format!("cannot encode the model: {e}")))?;
        crate::recording::atomic::write_atomically(path, &text)
            .map_err(|e| SynthError::io(path, format!("cannot write the model: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ForwardModel {
        let v = Volterra::from_upper(&[0.2, 0.05, 0.1], vec![0.01, -0.02], 0.0).unwrap();
        let training = Training {
            scores: FitScores {
                samples: 100,
                train_rows: 85,
                validation_rows: 15,
                train_rel_rms: 0.1,
                validation_rel_rms: Some(0.12),
            },
            actuation_rms: 0.3,
            actuation_peak: 0.5,
            data_hash: "fnv1a64:0".into(),
            seconds: 0.0,
        };
        ForwardModel::new(
            &v,
            1000.0,
            &OutputFilter::highpass(4, 10.0, 1000.0).unwrap(),
            Condition { mass_g: Some(85.0), speed_cm_s: Some(5.0) },
            NoiseModel { floor_n2: 1e-5, per_u2_n2: 2e-5 },
            Some(NoiseSpectrum { nfft: 4, p0: vec![1e-6, 2e-6, 3e-6], p1: vec![0.0, 1e-6, 1e-6] }),
            training,
        )
    }

    #[test]
    fn a_model_round_trips_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        let m = sample();
        m.save(&path).unwrap();
        let back = ForwardModel::load(&path).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.volterra().unwrap(), m.volterra().unwrap());
        assert!(!dir.path().join("m.json.tmp").exists());
    }

    #[test]
    fn bad_files_name_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        let good = serde_json::to_value(sample()).unwrap();
        type Change = Box<dyn Fn(&mut serde_json::Value)>;
        let cases: Vec<(&str, Change)> = vec![
            ("version 2", Box::new(|v| v["version"] = 2.into())),
            ("format", Box::new(|v| v["format"] = "evflow-narx-model".into())),
            ("kernel.linear", Box::new(|v| v["kernel"]["linear"] = serde_json::json!([1.0]))),
            ("kernel.quadratic_upper", Box::new(|v| v["kernel"]["quadratic_upper"] = serde_json::json!([1.0]))),
            ("kind", Box::new(|v| v["kind"] = "mlp".into())),
            ("carrier_gain_n", Box::new(|v| v["carrier_gain_n"] = 5.0.into())),
            ("noise.per_u2_n2", Box::new(|v| v["noise"]["per_u2_n2"] = (-1.0).into())),
            ("output_filter", Box::new(|v| v["output_filter"]["highpass_hz"] = 900.0.into())),
            ("rate_hz", Box::new(|v| v["rate_hz"] = 0.0.into())),
            ("noise_spectrum", Box::new(|v| v["noise_spectrum"]["p0"] = serde_json::json!([1.0]))),
            ("kernel", Box::new(|v| v.as_object_mut().unwrap().remove("kernel").map(|_| ()).unwrap_or(()))),
        ];
        for (want, change) in cases {
            let mut v = good.clone();
            change(&mut v);
            std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
            let e = ForwardModel::load(&path).unwrap_err().to_string();
            assert!(e.contains(want) && e.contains("m.json"), "{want}: {e}");
        }
        std::fs::write(&path, "{ not json").unwrap();
        assert!(ForwardModel::load(&path).unwrap_err().to_string().contains("not a forward-model file"));
        assert!(ForwardModel::load(&dir.path().join("missing.json")).is_err());
    }
}
