//! `recording.out`: writes its inputs to a recording.

use super::format::{Channel, Condition, RecordingMeta, RecordingPaths, RecordingWriter};
use evflow_engine::ports::InPort;
use evflow_engine::typed_params::{Float, Text, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, Summary};
use std::path::Path;

/// Declaration of `recording.out`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "recording.out",
    "recording",
    Role::Sink,
    "Writes its inputs to a recording (NAME.wav + NAME.json), committed when the run ends.",
    build,
)
.doc(
    "Writes one input port per `channels` entry to a recording in the evflow format \
     (`docs/recording-format.md`: 64-bit float WAV, channels interleaved in `channels` order, with \
     a JSON sidecar holding the exact rate, channel names and units, the condition and `source`). \
     All inputs run at the node's rate, which is the rate of its producers; that rate is the \
     recording's rate.\n\n\
     Frames are written as they arrive, through a buffer sized when the run is prepared, into \
     `NAME.wav.tmp` and `NAME.json.tmp`; when the run ends normally the two are renamed to \
     `NAME.wav` and `NAME.json` and the summary says `wrote NAME.wav (N frames, C channels, R Hz)`. \
     A run that fails or is interrupted removes the temporary files: it never leaves a \
     half-written recording and never replaces an existing one. A NaN or infinite input sample \
     stops the run with an error naming the channel and frame. `reset` empties the recording.\n\n\
     The condition parameters describe the experiment (dissertation §5.1: normal load 60/85/110 g, \
     scanning velocity 3–5 cm/s, texture material; §5.3.1: display gain). A number left at 0 and a \
     text left empty mean \"not recorded\" and are left out of the sidecar (no recording is made \
     at zero load or zero velocity, and a gain of 0 means the display was off, which is what an \
     absent gain says).\n\n\
     Checked by reading back what it wrote bit for bit, with byte-identical files at block sizes 1 \
     and large, and files read back by scipy.io.wavfile (see the format document).",
)
.ports(PORTS)
.params(&[
    PATH.spec(),
    CHANNELS.spec(),
    UNITS.spec(),
    LOAD_G.spec(),
    VELOCITY_CM_S.spec(),
    MATERIAL.spec(),
    GAIN.spec(),
    SOURCE.spec(),
])
.offline_only(
    "it writes its file from the processing thread; a live session records its inputs and outputs itself (docs/live.md)",
)
.example(
    "path = \"out.wav\"\nchannels = [\"force\"]\nunits = [\"N\"]\nload_g = 85.0\nvelocity_cm_s = 4.0\nmaterial = \"felt\"",
);

/// The ports: one input per channel recorded.
const PORTS: &[PortSpec] =
    &[PortSpec::input("channel", "as recorded", "one port per `channels` entry, named after it").per(CHANNELS.name())];
/// The first channel recorded (the k-th is `CHANNEL.nth(k)`).
const CHANNEL: InPort = InPort::named(PORTS, "channel");

/// `path`: where to write.
const PATH: Text =
    Text::new("path", "", "where to write: NAME.wav, NAME.json or NAME (relative to the graph file's folder)")
        .required();
/// `channels`: the channel names, in file order.
const CHANNELS: Words = Words::new("channels", "channel names, in file order; each is an input port").required();
/// `units`: the unit of each channel.
const UNITS: Words = Words::new("units", "unit of each channel (e.g. N), same length as `channels`, or empty");
/// `load_g`: the condition's normal load.
const LOAD_G: Float = Float::new("load_g", 0.0, 1e6, 0.0, "g", "condition: normal load (0 = not recorded)");
/// `velocity_cm_s`: the condition's scanning velocity.
const VELOCITY_CM_S: Float =
    Float::new("velocity_cm_s", 0.0, 1e6, 0.0, "cm/s", "condition: scanning velocity (0 = not recorded)");
/// `material`: the condition's texture material.
const MATERIAL: Text = Text::new("material", "", "condition: texture material (empty = not recorded)");
/// `gain`: the condition's display gain.
const GAIN: Float = Float::new("gain", 0.0, 1e6, 0.0, "1", "condition: display gain, 1 = 100 Vpp (0 = not recorded)");
/// `source`: what wrote the recording.
const SOURCE: Text = Text::new("source", "", "what wrote it, kept in the sidecar (empty: the node's type and name)");

/// Frames the writer buffers at least, whatever the block size.
const MIN_BUFFER_FRAMES: usize = 8192;

struct RecordingOut {
    writer: Option<RecordingWriter>,
    /// The WAV's path as the graph wrote it, for the summary.
    shown: String,
    channels: usize,
    /// One block of frames, interleaved; sized in `prepare`.
    interleave: Vec<f64>,
    /// An error from `reset`, reported by the next call that can.
    pending: Option<NodeError>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let names = CHANNELS.get(p);
    if names.is_empty() {
        return Err(NodeError::param(CHANNELS.name(), "list at least one channel to record"));
    }
    let units = UNITS.get(p);
    if !units.is_empty() && units.len() != names.len() {
        return Err(NodeError::param(
            UNITS.name(),
            format!("{} units for {} channels; give one per channel, or none", units.len(), names.len()),
        ));
    }
    let set = |x: f64| (x != 0.0).then_some(x);
    let material = MATERIAL.get(p);
    let condition = Condition {
        load_g: set(LOAD_G.get(p)),
        velocity_cm_s: set(VELOCITY_CM_S.get(p)),
        material: (!material.is_empty()).then(|| material.to_string()),
        gain: set(GAIN.get(p)),
        extra: Default::default(),
    };
    let source = match SOURCE.get(p) {
        "" => format!("evflow {} node `{}`", SPEC.name, ctx.node),
        s => s.to_string(),
    };
    let channels = names
        .iter()
        .enumerate()
        .map(|(i, n)| Channel::new(n.clone(), units.get(i).cloned().unwrap_or_default()))
        .collect();
    let meta = RecordingMeta { rate: ctx.rate, channels, condition, source };
    let path = PATH.get(p);
    let target = ctx.output_path(PATH.name(), path)?;
    // `evflow check` builds to validate and writes nothing: no folder, no file.
    let writer = if ctx.check_only { None } else { Some(RecordingWriter::create(&target, meta)?) };
    let shown = RecordingPaths::new(Path::new(path)).wav.display().to_string();
    Ok(Box::new(RecordingOut { writer, shown, channels: names.len(), interleave: Vec::new(), pending: None }))
}

impl Node for RecordingOut {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.interleave = vec![0.0; ctx.max_block * self.channels];
        if let Some(w) = self.writer.as_mut() {
            w.reserve_frames(ctx.max_block.max(MIN_BUFFER_FRAMES));
        }
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        if let Some(e) = self.pending.take() {
            return Err(e);
        }
        let Some(w) = self.writer.as_mut() else {
            return Err(NodeError::Other("the recording was already finished".into()));
        };
        let ch = self.channels;
        let n = io.len();
        let Some(frames) = self.interleave.get_mut(..n * ch) else {
            return Err(NodeError::Other("a block larger than prepared for".into()));
        };
        for c in 0..ch {
            for (i, x) in io.input(CHANNEL.nth(c)).iter().take(n).enumerate() {
                frames[i * ch + c] = *x;
            }
        }
        w.write_interleaved(frames)?;
        Ok(())
    }

    fn reset(&mut self) {
        if let Some(w) = self.writer.as_mut() {
            if let Err(e) = w.restart() {
                self.pending = Some(e.into());
            }
        }
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        if let Some(e) = self.pending.take() {
            return Err(e);
        }
        let Some(w) = self.writer.take() else {
            return Ok(Summary::default());
        };
        let done = w.finish()?;
        Ok(Summary::default().value("frames", done.frames as f64, "1").line(format!(
            "wrote {} ({} frames, {} channel{}, {} Hz)",
            self.shown,
            done.frames,
            done.channels,
            if done.channels == 1 { "" } else { "s" },
            done.rate
        )))
    }
}

#[cfg(test)]
mod tests;
