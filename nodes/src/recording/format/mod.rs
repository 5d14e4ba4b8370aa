//! The on-disk recording format: `NAME.wav` + `NAME.json`.
//!
//! A recording is two files side by side:
//!
//! * `NAME.wav` — RIFF/WAVE, format tag 3 (`WAVE_FORMAT_IEEE_FLOAT`), 64-bit
//!   little-endian float samples, channels interleaved. The header's sample
//!   rate is the recording's rate rounded to an integer.
//! * `NAME.json` — the sidecar: format name and version, the exact rate, the
//!   frame count, channel names and units, the experimental condition (load,
//!   velocity, material, gain and free keys) and a free-text `source`.
//!
//! The format is specified for people, with numpy and MATLAB snippets, in
//! `docs/recording-format.md`. This module is independent of the engine's
//! `Node` trait: the `recording.in` / `recording.out` nodes, session
//! recording and the tools all read and write through it.
//!
//! * [`RecordingWriter`] writes (atomically committed, or live with
//!   incremental flushes that leave a readable file after a crash).
//! * [`Recording`] reads and validates a whole recording into memory.

mod error;
mod reader;
#[cfg(test)]
mod stream_tests;
#[cfg(test)]
mod tests;
mod wav;
mod writer;

pub use error::RecordingError;
pub use reader::{Recording, Shortfall};
pub use writer::{RecordingWriter, Written};

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The sidecar's `format` value.
pub const FORMAT_NAME: &str = "evflow-recording";

/// The rates a recording may have for `recording.in` to play it, in Hz:
/// 0.001 Hz … 10 MHz. `evflow import` refuses a rate outside them (given
/// or read from a time column), so what it writes is what a graph reads.
pub const MIN_RATE_HZ: f64 = 1e-3;

/// The highest rate of [`MIN_RATE_HZ`]'s range, in Hz.
pub const MAX_RATE_HZ: f64 = 1e7;

/// The newest sidecar version this evflow reads and the one it writes.
pub const FORMAT_VERSION: u64 = 1;

/// One channel of a recording.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Channel {
    /// Name, unique within the recording (e.g. `force`). To be exposed by
    /// `recording.in` it must also be a valid port name (letters, digits,
    /// `_`, `-`).
    pub name: String,
    /// Unit of the samples (e.g. `N`); empty when unknown.
    #[serde(default)]
    pub unit: String,
}

impl Channel {
    /// A channel with a name and a unit.
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Self {
        Self { name: name.into(), unit: unit.into() }
    }
}

/// The experimental condition a recording was made under (dissertation
/// §5.1: normal load and scanning velocity of the tribometer, the texture
/// material, and the display gain of §5.3.1). Every key is optional; other
/// keys are kept in [`Condition::extra`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Condition {
    /// Normal load in grams (e.g. 60, 85, 110).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_g: Option<f64>,
    /// Scanning velocity in cm/s (e.g. 3, 4, 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_cm_s: Option<f64>,
    /// Texture material (e.g. `felt`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Display gain (1.0 = 100 Vpp through the amplifier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain: Option<f64>,
    /// Any other keys, kept as written.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl Condition {
    fn check(&self) -> Result<(), String> {
        for (name, v) in [("load_g", self.load_g), ("velocity_cm_s", self.velocity_cm_s), ("gain", self.gain)] {
            if let Some(x) = v {
                if !x.is_finite() {
                    return Err(format!("condition `{name}` is {x}, not a finite number"));
                }
            }
        }
        Ok(())
    }
}

/// What a recording holds besides its samples: the sidecar without the
/// format name, version and frame count.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingMeta {
    /// Sample rate in Hz (exact; the WAV header holds it rounded).
    pub rate: f64,
    /// The channels, in the WAV's interleaving order.
    pub channels: Vec<Channel>,
    /// The experimental condition.
    pub condition: Condition,
    /// Free text: the graph or tool that wrote it.
    pub source: String,
}

impl RecordingMeta {
    /// Metadata with a rate and channels, no condition and no source.
    pub fn new(rate: f64, channels: Vec<Channel>) -> Self {
        Self { rate, channels, condition: Condition::default(), source: String::new() }
    }

    /// Index of the channel of that name.
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c.name == name)
    }

    /// Checks what every recording must satisfy; the message names the field.
    fn check(&self) -> Result<(), String> {
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(format!("`rate` is {}, not a positive number of Hz", self.rate));
        }
        if self.channels.is_empty() {
            return Err("`channels` is empty; a recording has at least one channel".into());
        }
        if self.channels.len() > usize::from(u16::MAX) {
            return Err(format!("{} channels; a WAV holds at most {}", self.channels.len(), u16::MAX));
        }
        for (i, c) in self.channels.iter().enumerate() {
            if c.name.trim().is_empty() {
                return Err(format!("channel {i} has an empty name"));
            }
            if self.channels[..i].iter().any(|d| d.name == c.name) {
                return Err(format!("channel `{}` is listed twice", c.name));
            }
        }
        self.condition.check()
    }
}

/// The sidecar as written (field order is the order on disk).
#[derive(Serialize)]
struct SidecarOut<'a> {
    format: &'static str,
    version: u64,
    rate: f64,
    frames: u64,
    channels: &'a [Channel],
    condition: &'a Condition,
    source: &'a str,
}

/// The sidecar as read, after `format` and `version` were checked.
#[derive(Deserialize)]
struct SidecarIn {
    rate: f64,
    frames: u64,
    channels: Vec<Channel>,
    #[serde(default)]
    condition: Condition,
    #[serde(default)]
    source: String,
}

/// The sidecar's text for `meta` with `frames` frames.
fn sidecar_json(meta: &RecordingMeta, frames: u64) -> String {
    let s = SidecarOut {
        format: FORMAT_NAME,
        version: FORMAT_VERSION,
        rate: meta.rate,
        frames,
        channels: &meta.channels,
        condition: &meta.condition,
        source: &meta.source,
    };
    // Serializing plain structs of strings and finite numbers cannot fail.
    let mut text = serde_json::to_string_pretty(&s).unwrap_or_default();
    text.push('\n');
    text
}

/// The two files of a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordingPaths {
    /// `NAME.wav`: the samples.
    pub wav: PathBuf,
    /// `NAME.json`: the sidecar.
    pub json: PathBuf,
}

impl RecordingPaths {
    /// The files of the recording named by `path`: `NAME.wav` or `NAME.json`
    /// (either names the pair), or `NAME` alone (`.wav` and `.json` are
    /// appended to the whole name, so `run.v2` gives `run.v2.wav`).
    pub fn new(path: &Path) -> Self {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let base = match ext.as_deref() {
            Some("wav") | Some("json") => path.with_extension(""),
            _ => path.to_path_buf(),
        };
        let with = |ext: &str| {
            let mut s = base.clone().into_os_string();
            s.push(ext);
            PathBuf::from(s)
        };
        Self { wav: with(".wav"), json: with(".json") }
    }

    /// The temporary files an atomically committed writer fills:
    /// `NAME.wav.tmp` and `NAME.json.tmp`, in the same folder.
    pub fn temporary(&self) -> Self {
        use evflow_engine::atomic_file::temporary_name;
        Self { wav: temporary_name(&self.wav), json: temporary_name(&self.json) }
    }
}
