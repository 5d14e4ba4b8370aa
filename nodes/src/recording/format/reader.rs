//! Reading a recording: validate the sidecar and the WAV, load the samples.

use super::wav::{self, WavProblem, SAMPLE_BYTES};
use super::{RecordingError, RecordingMeta, RecordingPaths, SidecarIn, FORMAT_NAME, FORMAT_VERSION};
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// Bytes read from a WAV at a time.
const READ_CHUNK: usize = 1 << 16;

/// The largest sidecar read (a sidecar is a few hundred bytes; its condition
/// may hold notes, not megabytes).
pub(crate) const MAX_SIDECAR_BYTES: u64 = 1 << 20;

/// Opens `path` for reading if it is a regular file (a link is followed),
/// with its length: a device, a FIFO or a folder is refused before it is
/// opened (opening a FIFO would wait for a writer; `/dev/zero` never ends).
fn open_regular(path: &Path) -> Result<(std::fs::File, u64), RecordingError> {
    evflow_engine::files::open_regular(path).map_err(|e| match e {
        evflow_engine::files::OpenError::Io(e) => RecordingError::io(path, e),
        evflow_engine::files::OpenError::NotAFile { what } => {
            RecordingError::NotAFile { path: path.to_path_buf(), what: what.to_string() }
        }
    })
}

/// Frames missing from a truncated recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shortfall {
    /// Frames the WAV header or the sidecar claim (the larger).
    pub claimed: u64,
    /// Whole frames present in the file (what was loaded).
    pub present: u64,
}

/// A recording loaded into memory, validated: every sample finite, WAV and
/// sidecar consistent.
#[derive(Debug, Clone)]
pub struct Recording {
    paths: RecordingPaths,
    meta: RecordingMeta,
    /// The loaded channels: (index in the file, samples).
    data: Vec<(usize, Vec<f64>)>,
    frames: usize,
    shortfall: Option<Shortfall>,
    sidecar_frames: u64,
}

impl Recording {
    /// Opens the recording named by `path` (`NAME.wav`, `NAME.json` or
    /// `NAME`) and loads every channel.
    ///
    /// A truncated WAV (a writer killed mid-write) is not an error: the
    /// whole frames present are loaded and [`Recording::shortfall`] says how
    /// many are missing.
    pub fn open(path: &Path) -> Result<Self, RecordingError> {
        Self::open_impl(path, None)
    }

    /// Like [`Recording::open`], loading only the named channels (in the
    /// order given); the others are neither decoded nor checked. Errors
    /// with [`RecordingError::UnknownChannel`] (naming the closest channel)
    /// if one is not in the recording.
    pub fn open_channels(path: &Path, names: &[impl AsRef<str>]) -> Result<Self, RecordingError> {
        let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
        Self::open_impl(path, Some(&names))
    }

    /// Validates the recording as [`Recording::open_channels`] does — the
    /// sidecar, the header, every sample of the named channels finite — by
    /// streaming through the file, keeping none of the samples: what `evflow
    /// check` does, in memory that does not grow with the file.
    /// [`Recording::frames`] and [`Recording::shortfall`] are those of the
    /// file; no channel is loaded ([`Recording::loaded`] is empty).
    pub fn scan_channels(path: &Path, names: &[impl AsRef<str>]) -> Result<Self, RecordingError> {
        let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
        Self::read(path, Some(&names), false)
    }

    fn open_impl(path: &Path, names: Option<&[&str]>) -> Result<Self, RecordingError> {
        Self::read(path, names, true)
    }

    /// Reads the recording, decoding the `names` channels (all if `None`) in
    /// chunks of [`READ_CHUNK`] bytes; `keep` keeps their samples.
    fn read(path: &Path, names: Option<&[&str]>, keep: bool) -> Result<Self, RecordingError> {
        let paths = RecordingPaths::new(path);
        match (paths.wav.exists(), paths.json.exists()) {
            (false, false) => {
                return Err(RecordingError::NotFound { path: paths.wav.clone(), json: paths.json.clone() })
            }
            (true, false) => return Err(RecordingError::MissingSidecar { path: paths.json.clone() }),
            (false, true) => {
                return Err(RecordingError::MissingWav { path: paths.wav.clone(), json: paths.json.clone() })
            }
            (true, true) => {}
        }
        let (meta, sidecar_frames) = read_sidecar(&paths.json)?;

        let wanted: Vec<usize> = match names {
            None => (0..meta.channels.len()).collect(),
            Some(names) => names
                .iter()
                .map(|n| {
                    meta.channel_index(n).ok_or_else(|| RecordingError::UnknownChannel {
                        path: paths.json.clone(),
                        name: n.to_string(),
                        help: evflow_engine::suggest::help(n, meta.channels.iter().map(|c| c.name.as_str())),
                    })
                })
                .collect::<Result<_, _>>()?,
        };

        let (file, len) = open_regular(&paths.wav)?;
        let mut file = std::io::BufReader::with_capacity(READ_CHUNK, file);
        let info = wav::parse(&mut file, len).map_err(|p| match p {
            WavProblem::Broken(message) => RecordingError::NotWav { path: paths.wav.clone(), message },
            WavProblem::NotFloat64(found) => RecordingError::NotFloat64 { path: paths.wav.clone(), found },
            WavProblem::Io(e) => RecordingError::io(&paths.wav, e),
        })?;
        if info.channels != meta.channels.len() {
            return Err(RecordingError::ChannelMismatch {
                path: paths.wav.clone(),
                wav_channels: info.channels,
                json: paths.json.clone(),
                json_channels: meta.channels.len(),
            });
        }
        if info.rate != wav::header_rate(meta.rate) {
            return Err(RecordingError::RateMismatch { path: paths.wav.clone(), header: info.rate, rate: meta.rate });
        }

        // Whole frames in the file as its size says when opened: what is
        // read never passes it, whatever the header claims.
        let block = info.channels * SAMPLE_BYTES;
        let in_file = len.saturating_sub(info.data_offset) / block as u64;
        let present = info.claimed_frames.min(in_file);
        let claimed = info.claimed_frames.max(sidecar_frames);
        let shortfall = (present < claimed).then_some(Shortfall { claimed, present });
        let frames = usize::try_from(present).map_err(|_| RecordingError::NotWav {
            path: paths.wav.clone(),
            message: format!("{present} frames do not fit in memory on this machine"),
        })?;

        let mut data: Vec<(usize, Vec<f64>)> =
            wanted.iter().map(|&c| (c, Vec::with_capacity(if keep { frames } else { 0 }))).collect();
        if !wanted.is_empty() {
            file.seek(SeekFrom::Start(info.data_offset)).map_err(|e| RecordingError::io(&paths.wav, e))?;
            let per_read = (READ_CHUNK / block).max(1);
            let mut buf = vec![0u8; per_read * block];
            let mut done = 0usize;
            while done < frames {
                let n = per_read.min(frames - done);
                let bytes = &mut buf[..n * block];
                file.read_exact(bytes).map_err(|e| RecordingError::io(&paths.wav, e))?;
                for (c, v) in &mut data {
                    let at = *c * SAMPLE_BYTES;
                    for (k, frame) in bytes.chunks_exact(block).enumerate() {
                        let mut le = [0u8; SAMPLE_BYTES];
                        le.copy_from_slice(&frame[at..at + SAMPLE_BYTES]);
                        let x = f64::from_le_bytes(le);
                        if !x.is_finite() {
                            return Err(RecordingError::NonFinite {
                                path: paths.wav.clone(),
                                channel: meta.channels[*c].name.clone(),
                                frame: (done + k) as u64,
                                what: non_finite_word(x),
                            });
                        }
                        if keep {
                            v.push(x);
                        }
                    }
                }
                done += n;
            }
        }
        if !keep {
            data.clear();
        }
        Ok(Recording { paths, meta, data, frames, shortfall, sidecar_frames })
    }

    /// The files it was read from.
    pub fn paths(&self) -> &RecordingPaths {
        &self.paths
    }
    /// Rate, channels (all of the file's, loaded or not), condition, source.
    pub fn meta(&self) -> &RecordingMeta {
        &self.meta
    }
    /// Sample rate in Hz.
    pub fn rate(&self) -> f64 {
        self.meta.rate
    }
    /// Frames loaded (per channel).
    pub fn frames(&self) -> usize {
        self.frames
    }
    /// Names of the loaded channels, in load order.
    pub fn loaded(&self) -> impl Iterator<Item = &str> + '_ {
        self.data.iter().map(|(c, _)| self.meta.channels[*c].name.as_str())
    }
    /// The samples of a loaded channel, by name.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        let c = self.meta.channel_index(name)?;
        self.data.iter().find(|(i, _)| *i == c).map(|(_, v)| v.as_slice())
    }
    /// The loaded channels' samples, in load order, taken out of the recording.
    pub fn into_channels(self) -> Vec<Vec<f64>> {
        self.data.into_iter().map(|(_, v)| v).collect()
    }
    /// The frames the sidecar says the recording holds: the writer's count
    /// when it last wrote the sidecar. Equal to [`Recording::frames`] in a
    /// finished recording; a live one killed between writing frames and
    /// rewriting its sidecar says fewer (more is a [`Recording::shortfall`]).
    pub fn sidecar_frames(&self) -> u64 {
        self.sidecar_frames
    }
    /// Frames missing if the file was cut short, else `None`.
    pub fn shortfall(&self) -> Option<Shortfall> {
        self.shortfall
    }
    /// An error if the file was cut short ([`RecordingError::Truncated`]).
    pub fn require_complete(&self) -> Result<(), RecordingError> {
        match self.shortfall {
            None => Ok(()),
            Some(Shortfall { claimed, present }) => {
                Err(RecordingError::Truncated { path: self.paths.wav.clone(), claimed, present })
            }
        }
    }
}

/// `NaN`, `+Inf` or `-Inf`, for messages about a non-finite sample.
pub(crate) fn non_finite_word(x: f64) -> &'static str {
    if x.is_nan() {
        "NaN"
    } else if x > 0.0 {
        "+Inf"
    } else {
        "-Inf"
    }
}

/// Reads and checks the sidecar: format name, then version, then fields.
fn read_sidecar(path: &Path) -> Result<(RecordingMeta, u64), RecordingError> {
    let (file, len) = open_regular(path)?;
    if len > MAX_SIDECAR_BYTES {
        return Err(RecordingError::BadSidecar {
            path: path.to_path_buf(),
            message: format!("{len} bytes; a sidecar holds at most {MAX_SIDECAR_BYTES} bytes"),
        });
    }
    let mut text = String::new();
    file.take(MAX_SIDECAR_BYTES).read_to_string(&mut text).map_err(|e| RecordingError::io(path, e))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| RecordingError::SidecarNotJson { path: path.to_path_buf(), message: e.to_string() })?;
    let bad = |message: String| RecordingError::BadSidecar { path: path.to_path_buf(), message };
    let Some(obj) = value.as_object() else {
        return Err(bad("the sidecar is not a JSON object".into()));
    };
    match obj.get("format") {
        Some(serde_json::Value::String(s)) if s == FORMAT_NAME => {}
        other => {
            let found = other.map_or_else(|| "missing".to_string(), |v| format!("`{v}`"));
            return Err(RecordingError::WrongFormat { path: path.to_path_buf(), found });
        }
    }
    match obj.get("version").and_then(serde_json::Value::as_u64) {
        Some(v) if v > FORMAT_VERSION => {
            return Err(RecordingError::NewerVersion { path: path.to_path_buf(), version: v })
        }
        Some(v) if v >= 1 => {}
        _ => {
            let found = obj.get("version").map_or_else(|| "missing".to_string(), |v| format!("`{v}`"));
            return Err(bad(format!("`version` is {found}; expected a whole number from 1 to {FORMAT_VERSION}")));
        }
    }
    let s: SidecarIn = serde_json::from_value(value).map_err(|e| bad(format!("invalid sidecar: {e}")))?;
    let meta = RecordingMeta { rate: s.rate, channels: s.channels, condition: s.condition, source: s.source };
    meta.check().map_err(bad)?;
    Ok((meta, s.frames))
}
