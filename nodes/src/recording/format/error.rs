//! What can be wrong with a recording, each case naming the file.

use evflow_engine::NodeError;
use std::path::{Path, PathBuf};

/// An error reading or writing a recording. Every message starts with the
/// file it concerns (`force.wav: …`).
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// The operating system refused a read, write, rename or removal.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// Neither file of the recording exists.
    #[error("{}: no such recording (neither it nor {} exists)", path.display(), json.display())]
    NotFound {
        /// The WAV that was looked for.
        path: PathBuf,
        /// The sidecar that was looked for.
        json: PathBuf,
    },
    /// The WAV exists but its sidecar does not.
    #[error(
        "{}: sidecar missing: an evflow recording is NAME.wav with NAME.json beside it (rate, channel names and units, condition)",
        path.display()
    )]
    MissingSidecar {
        /// The sidecar that was looked for.
        path: PathBuf,
    },
    /// The sidecar exists but its WAV does not.
    #[error("{}: missing, although its sidecar {} exists", path.display(), json.display())]
    MissingWav {
        /// The WAV that was looked for.
        path: PathBuf,
        /// The sidecar.
        json: PathBuf,
    },
    /// A recording's file is not a regular file (a folder, a device such as
    /// `/dev/zero`, a FIFO), which is refused before it is read.
    #[error("{}: is {what}, not a regular file; a recording is a NAME.wav and NAME.json pair of files", path.display())]
    NotAFile {
        /// The file named.
        path: PathBuf,
        /// What it is.
        what: String,
    },
    /// The sidecar is not JSON.
    #[error("{}: sidecar is not valid JSON: {message}", path.display())]
    SidecarNotJson {
        /// The sidecar.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// The sidecar's `format` is not `evflow-recording`.
    #[error("{}: `format` is {found}, not \"evflow-recording\"; this is not an evflow recording sidecar", path.display())]
    WrongFormat {
        /// The sidecar.
        path: PathBuf,
        /// What was found (quoted value, or `missing`).
        found: String,
    },
    /// The sidecar's `version` is newer than this evflow reads.
    #[error(
        "{}: recording format version {version} is newer than this evflow reads (version {}); update evflow to read it",
        path.display(),
        super::FORMAT_VERSION
    )]
    NewerVersion {
        /// The sidecar.
        path: PathBuf,
        /// The version found.
        version: u64,
    },
    /// The sidecar is JSON of the right format but a field is wrong.
    #[error("{}: {message}", path.display())]
    BadSidecar {
        /// The sidecar.
        path: PathBuf,
        /// Which field, and what is wrong.
        message: String,
    },
    /// The WAV's RIFF structure is broken.
    #[error("{}: not a readable WAV file: {message}", path.display())]
    NotWav {
        /// The WAV.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The WAV holds samples of another type.
    #[error(
        "{}: samples are {found}; evflow recordings hold 64-bit IEEE float samples (WAV format 3)",
        path.display()
    )]
    NotFloat64 {
        /// The WAV.
        path: PathBuf,
        /// What the header declares, in words.
        found: String,
    },
    /// WAV and sidecar disagree on the number of channels.
    #[error(
        "{}: holds {wav_channels} channel(s) but its sidecar {} lists {json_channels}",
        path.display(),
        json.display()
    )]
    ChannelMismatch {
        /// The WAV.
        path: PathBuf,
        /// Channels in the WAV header.
        wav_channels: usize,
        /// The sidecar.
        json: PathBuf,
        /// Channels in the sidecar.
        json_channels: usize,
    },
    /// WAV header and sidecar disagree on the rate.
    #[error(
        "{}: header rate {header} Hz disagrees with its sidecar's rate {rate} Hz (which rounds to {})",
        path.display(),
        rate.round()
    )]
    RateMismatch {
        /// The WAV.
        path: PathBuf,
        /// Rate in the WAV header.
        header: u32,
        /// Exact rate in the sidecar.
        rate: f64,
    },
    /// The WAV holds fewer frames than its header or sidecar claim (a writer
    /// stopped early). [`super::Recording::open`] still reads the frames
    /// present; this error comes from
    /// [`super::Recording::require_complete`].
    #[error(
        "{}: truncated: {claimed} frames expected but the file holds {present} ({} missing)",
        path.display(),
        claimed - present
    )]
    Truncated {
        /// The WAV.
        path: PathBuf,
        /// Frames claimed by the header or the sidecar.
        claimed: u64,
        /// Whole frames present.
        present: u64,
    },
    /// A sample is NaN or infinite (frames count from 0).
    #[error("{}: channel `{channel}` frame {frame} is {what}", path.display())]
    NonFinite {
        /// The WAV.
        path: PathBuf,
        /// The channel's name.
        channel: String,
        /// The frame index, from 0.
        frame: u64,
        /// `NaN`, `+Inf` or `-Inf`.
        what: &'static str,
    },
    /// A requested channel is not in the recording.
    #[error("{}: no channel `{name}` ({help})", path.display())]
    UnknownChannel {
        /// The sidecar.
        path: PathBuf,
        /// The channel asked for.
        name: String,
        /// The closest name, or the list of channels.
        help: String,
    },
    /// The metadata given to a writer is unusable.
    #[error("{}: {message}", path.display())]
    InvalidMeta {
        /// The recording being written.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Samples handed to a writer do not make whole frames.
    #[error("{}: {samples} samples do not make whole frames of {channels} channels", path.display())]
    FrameShape {
        /// The recording being written.
        path: PathBuf,
        /// Samples given.
        samples: usize,
        /// Channels per frame.
        channels: usize,
    },
    /// The WAV would pass the 4 GiB a RIFF size field can describe.
    #[error("{}: a WAV file holds at most {max_frames} frames of this width (4 GiB); split the recording", path.display())]
    TooLong {
        /// The recording being written.
        path: PathBuf,
        /// The largest frame count possible.
        max_frames: u64,
    },
    /// A live writer found a recording already there.
    #[error("{}: already exists; a live recording never overwrites one", path.display())]
    Exists {
        /// The existing file.
        path: PathBuf,
    },
}

impl RecordingError {
    /// The file the error concerns.
    pub fn path(&self) -> &Path {
        use RecordingError::*;
        match self {
            Io { path, .. }
            | NotFound { path, .. }
            | MissingSidecar { path }
            | MissingWav { path, .. }
            | SidecarNotJson { path, .. }
            | WrongFormat { path, .. }
            | NewerVersion { path, .. }
            | BadSidecar { path, .. }
            | NotAFile { path, .. }
            | NotWav { path, .. }
            | NotFloat64 { path, .. }
            | ChannelMismatch { path, .. }
            | RateMismatch { path, .. }
            | Truncated { path, .. }
            | NonFinite { path, .. }
            | UnknownChannel { path, .. }
            | InvalidMeta { path, .. }
            | FrameShape { path, .. }
            | TooLong { path, .. }
            | Exists { path } => path,
        }
    }

    /// The message without the leading file name.
    pub fn detail(&self) -> String {
        let full = self.to_string();
        let prefix = format!("{}: ", self.path().display());
        match full.strip_prefix(&prefix) {
            Some(rest) => rest.to_string(),
            None => full,
        }
    }

    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        RecordingError::Io { path: path.to_path_buf(), source }
    }
}

/// Bad samples become [`NodeError::Data`]; everything else a
/// [`NodeError::File`] naming the file.
impl From<RecordingError> for NodeError {
    fn from(e: RecordingError) -> Self {
        match e {
            RecordingError::NonFinite { .. } => NodeError::Data(e.to_string()),
            e => NodeError::file(e.path(), e.detail()),
        }
    }
}
