//! `recording.in`: plays channels of a recording.

use super::format::{Recording, RecordingError, Shortfall};
use evflow_engine::ports::OutPort;
use evflow_engine::typed_params::{Float, Text, Words};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role, Summary};

/// Declaration of `recording.in`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "recording.in",
    "recording",
    Role::Source,
    "Plays chosen channels of a recording (NAME.wav + NAME.json), once.",
    build,
)
.doc(
    "Reads a recording in the evflow format (`docs/recording-format.md`: 64-bit float WAV with a \
     JSON sidecar) and plays the channels listed in `channels`, each on an output port named after \
     the channel, from its first frame to its last. It is a finite source: an offline run ends when \
     the recording does; after the end the ports carry zeros. `reset` rewinds to the first frame.\n\n\
     The node's rate is `rate`, which must equal the recording's rate (the validator resolves rates \
     before any file is opened, so the rate is written in the graph and checked against the file at \
     construction). Only the listed channels are decoded and kept in memory.\n\n\
     The whole recording is validated when the node is built (`evflow check` streams through the \
     file to do so, keeping no sample, so checking a large recording takes no memory): a missing or foreign sidecar, a newer \
     format version, a WAV that is not 64-bit float, a channel-count mismatch or a NaN/Inf sample \
     is an error naming the file (and the channel and frame); so is a WAV or sidecar that is not a \
     regular file (a link to `/dev/zero`, a FIFO). A WAV cut short by a crash is played \
     up to its last whole frame and the run's summary says how many frames were missing.\n\n\
     Used to replay tribometer force recordings (dissertation §5.1: lateral force at 1 kHz under \
     load × velocity conditions; §3.1: 10 kHz) and recorded sessions through any graph. Checked \
     against the writer (`recording.out`) bit for bit, and for equal output at block sizes 1 and \
     large.",
)
.ports(PORTS)
.params(&[PATH.spec(), CHANNELS.spec(), RATE.spec()])
.rate_param(RATE.name())
.example("path = \"recordings/felt.wav\"\nchannels = [\"force\"]\nrate = 1000.0");

/// The ports: one output per channel played.
const PORTS: &[PortSpec] =
    &[PortSpec::output("channel", "as recorded", "one port per `channels` entry, named after it").per(CHANNELS.name())];
/// The first channel played (the k-th is `CHANNEL.nth(k)`).
const CHANNEL: OutPort = OutPort::named(PORTS, "channel");

/// `path`: the recording.
const PATH: Text =
    Text::new("path", "", "the recording: NAME.wav, NAME.json or NAME (relative to the graph file's folder)")
        .required();
/// `channels`: the channels to play.
const CHANNELS: Words = Words::new("channels", "channels to play, each on an output port of its name").required();
/// `rate`: the recording's rate (the node's rate).
const RATE: Float = Float::new(
    "rate",
    super::format::MIN_RATE_HZ,
    super::format::MAX_RATE_HZ,
    1000.0,
    "Hz",
    "the recording's sample rate (must match the file)",
);

struct RecordingIn {
    /// Samples of each output port, in port order.
    channels: Vec<Vec<f64>>,
    frames: usize,
    pos: usize,
    /// The path as written and the frames missing, for the summary.
    shown: String,
    shortfall: Option<Shortfall>,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let shown = PATH.get(p).to_string();
    let names = CHANNELS.get(p);
    if names.is_empty() {
        return Err(NodeError::param(CHANNELS.name(), "list at least one channel to play"));
    }
    // `evflow check` streams through the samples to validate them, keeping none.
    let read = if ctx.check_only { Recording::scan_channels } else { Recording::open_channels };
    let rec = read(&ctx.path(&shown), names).map_err(|e| match e {
        RecordingError::UnknownChannel { .. } => NodeError::param(CHANNELS.name(), e.to_string()),
        e => e.into(),
    })?;
    let rate = RATE.get(p);
    if (rate - rec.rate()).abs() > 1e-9 * rec.rate() {
        return Err(NodeError::param(
            RATE.name(),
            format!(
                "the node runs at {rate} Hz but {} was recorded at {} Hz; set rate = {} (and add a rate node if the graph needs another rate)",
                rec.paths().wav.display(),
                rec.rate(),
                rec.rate()
            ),
        ));
    }
    let frames = rec.frames();
    let shortfall = rec.shortfall();
    let mut channels = rec.into_channels();
    // A checked plan never runs; its ports still get their (empty) channels.
    channels.resize(names.len(), Vec::new());
    Ok(Box::new(RecordingIn { channels, frames, pos: 0, shown, shortfall }))
}

impl Node for RecordingIn {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let start = self.pos.min(self.frames);
        let mut n = 0;
        for (o, data) in self.channels.iter().enumerate() {
            let out = io.output(CHANNEL.nth(o));
            n = out.len();
            let avail = data.get(start..).unwrap_or(&[]);
            let k = n.min(avail.len());
            out[..k].copy_from_slice(&avail[..k]);
            out[k..].fill(0.0);
        }
        self.pos = self.pos.saturating_add(n);
        Ok(())
    }

    fn reset(&mut self) {
        self.pos = 0;
    }

    fn remaining(&self) -> Option<u64> {
        Some(self.frames.saturating_sub(self.pos) as u64)
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(match self.shortfall {
            Some(s) => Summary::default().line(format!(
                "{} was cut short: {} frames claimed, {} present; played the {} present",
                self.shown, s.claimed, s.present, s.present
            )),
            None => Summary::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::format::{Channel, RecordingMeta, RecordingWriter};
    use evflow_engine::harness::Single;
    use std::path::Path;

    fn write(dir: &Path, name: &str, rate: f64, chans: &[(&str, Vec<f64>)]) {
        let meta = RecordingMeta::new(rate, chans.iter().map(|(n, _)| Channel::new(*n, "N")).collect());
        let mut w = RecordingWriter::create(&dir.join(name), meta).unwrap();
        for i in 0..chans[0].1.len() {
            let frame: Vec<f64> = chans.iter().map(|(_, v)| v[i]).collect();
            w.write_frame(&frame).unwrap();
        }
        w.finish().unwrap();
    }

    fn signals(n: usize) -> (Vec<f64>, Vec<f64>) {
        let a = (0..n).map(|i| (i as f64 * 0.37).sin() * 1e-3).collect();
        let b = (0..n).map(|i| (i as f64).sqrt() - 7.25).collect();
        (a, b)
    }

    fn run(dir: &Path, params: &str, outputs: Vec<&str>, base: f64, ticks: u64, block: usize) -> Vec<Vec<f64>> {
        Single::new(&SPEC, params)
            .outputs(outputs)
            .base_rate(base)
            .ticks(ticks)
            .block(block)
            .base_dir(dir)
            .run()
            .unwrap()
    }

    #[test]
    fn plays_channels_in_requested_order_then_zeros() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = signals(300);
        write(dir.path(), "rec.wav", 1000.0, &[("force", a.clone()), ("pos", b.clone())]);
        // Channels requested in the other order than in the file.
        let out = run(
            dir.path(),
            "path = \"rec.wav\"\nchannels = [\"pos\", \"force\"]",
            vec!["pos", "force"],
            1000.0,
            320,
            64,
        );
        assert_eq!(&out[0][..300], &b[..]);
        assert_eq!(&out[1][..300], &a[..]);
        assert!(out[0][300..].iter().chain(&out[1][300..]).all(|x| *x == 0.0));
    }

    #[test]
    fn block_one_equals_large_block() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = signals(517);
        write(dir.path(), "rec", 1000.0, &[("force", a), ("pos", b)]);
        let p = "path = \"rec\"\nchannels = [\"force\", \"pos\"]";
        let one = run(dir.path(), p, vec!["force", "pos"], 1000.0, 530, 1);
        let big = run(dir.path(), p, vec!["force", "pos"], 1000.0, 530, 256);
        assert_eq!(one, big);
        // Also at a rate that divides the base rate (500 Hz under 1 kHz).
        write(dir.path(), "half", 500.0, &[("force", (0..77).map(f64::from).collect())]);
        let p = "path = \"half.json\"\nchannels = [\"force\"]\nrate = 500.0";
        let one = run(dir.path(), p, vec!["force"], 1000.0, 160, 1);
        let big = run(dir.path(), p, vec!["force"], 1000.0, 160, 64);
        assert_eq!(one, big);
        assert_eq!(&one[0][..77], &(0..77).map(f64::from).collect::<Vec<_>>()[..]);
    }

    #[test]
    fn reset_rewinds_and_remaining_counts_down() {
        let dir = tempfile::tempdir().unwrap();
        let (a, _) = signals(100);
        write(dir.path(), "rec.wav", 1000.0, &[("force", a.clone())]);
        let single = Single::new(&SPEC, "path = \"rec.wav\"\nchannels = [\"force\"]")
            .output("force")
            .block(40)
            .base_dir(dir.path());
        let (mut plan, idx) = single.plan().unwrap();
        assert_eq!(plan.remaining_ticks(), Some(100));
        plan.step(40).unwrap();
        let first: Vec<f64> = plan.output("dut", idx[0]).unwrap().to_vec();
        assert_eq!(first, a[..40]);
        plan.step(40).unwrap();
        assert_eq!(plan.remaining_ticks(), Some(20));
        plan.reset();
        assert_eq!(plan.remaining_ticks(), Some(100));
        plan.step(40).unwrap();
        assert_eq!(plan.output("dut", idx[0]).unwrap(), &first[..]);
    }

    #[test]
    fn refuses_wrong_rate_and_unknown_channel() {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), "rec.wav", 10_000.0, &[("force", vec![1.0; 10])]);
        let err = Single::new(&SPEC, "path = \"rec.wav\"\nchannels = [\"force\"]")
            .output("force")
            .ticks(5)
            .block(4)
            .base_dir(dir.path())
            .run()
            .unwrap_err();
        assert!(err.contains("parameter `rate`") && err.contains("1000 Hz") && err.contains("10000 Hz"), "{err}");

        write(dir.path(), "one.wav", 1000.0, &[("force", vec![1.0; 10])]);
        let err = Single::new(&SPEC, "path = \"one.wav\"\nchannels = [\"forse\"]")
            .output("forse")
            .ticks(5)
            .block(4)
            .base_dir(dir.path())
            .run()
            .unwrap_err();
        assert!(err.contains("parameter `channels`") && err.contains("did you mean `force`?"), "{err}");
    }

    #[test]
    fn truncated_recording_plays_what_is_there_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let (a, _) = signals(1000);
        write(dir.path(), "cut.wav", 1000.0, &[("force", a.clone())]);
        let wav = dir.path().join("cut.wav");
        let bytes = std::fs::read(&wav).unwrap();
        std::fs::write(&wav, &bytes[..58 + 400 * 8 + 3]).unwrap();
        let single = Single::new(&SPEC, "path = \"cut.wav\"\nchannels = [\"force\"]")
            .output("force")
            .block(500)
            .base_dir(dir.path());
        let (mut plan, idx) = single.plan().unwrap();
        assert_eq!(plan.remaining_ticks(), Some(400));
        plan.step(400).unwrap();
        assert_eq!(plan.output("dut", idx[0]).unwrap(), &a[..400]);
        let summaries = plan.finish().unwrap();
        assert_eq!(
            summaries[0].1.lines,
            ["cut.wav was cut short: 1000 frames claimed, 400 present; played the 400 present"]
        );
    }

    #[test]
    fn missing_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let err = Single::new(&SPEC, "path = \"nothere.wav\"\nchannels = [\"force\"]")
            .output("force")
            .ticks(5)
            .block(4)
            .base_dir(dir.path())
            .run()
            .unwrap_err();
        assert!(err.contains("nothere.wav") && err.contains("no such recording"), "{err}");
    }
}
