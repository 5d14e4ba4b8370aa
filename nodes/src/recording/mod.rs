//! Recordings: the on-disk format ([`format`](mod@format): 64-bit float WAV + JSON
//! sidecar, described in `docs/recording-format.md`) and the nodes that read
//! and write it, `recording.in` ([`input`]) and `recording.out` ([`output`]);
//! [`import`](mod@import) turns a lab's `.npy` and CSV files into recordings.

pub mod atomic;
pub mod format;
pub mod import;
pub mod input;
pub mod output;
pub mod sweep_fields;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&input::SPEC, &output::SPEC];

#[cfg(test)]
mod tests {
    use super::{input, output};
    use evflow_engine::harness::TAP;
    use evflow_engine::{check, graph::parse_graph, run_offline, Plan, PlanOptions, Registry, RunOptions};

    /// A graph file copying a recording through `recording.in` →
    /// `recording.out` reproduces it: same samples, same bytes.
    #[test]
    fn recording_in_to_recording_out_copies_the_recording() {
        use super::format::{Channel, RecordingMeta, RecordingWriter};
        let dir = tempfile::tempdir().unwrap();
        let mut meta = RecordingMeta::new(
            10_000.0,
            vec![Channel::new("force", "N"), Channel::new("pos", "m"), Channel::new("skip", "")],
        );
        meta.source = "copy".into();
        let mut w = RecordingWriter::create(&dir.path().join("in.wav"), meta).unwrap();
        for i in 0..4321 {
            let t = i as f64 / 10_000.0;
            w.write_frame(&[(t * 377.0).sin(), t * 0.04, 1.0]).unwrap();
        }
        w.finish().unwrap();

        let doc = r#"
[graph]
format = 1
name = "copy"
rate = 1000.0
connections = ["src.force -> dst.force", "src.pos -> dst.pos", "src.force -> tap.in"]

[nodes.src]
type = "recording.in"
path = "in.wav"
channels = ["force", "pos"]
rate = 10000.0

[nodes.dst]
type = "recording.out"
path = "out"
channels = ["force", "pos"]
units = ["N", "m"]
source = "copy"

[nodes.tap]
type = "harness.tap"
"#;
        let mut reg = Registry::new();
        reg.add(&input::SPEC).add(&output::SPEC).add(&TAP);
        let g = parse_graph(&dir.path().join("copy.toml"), doc).unwrap();
        let checked = check(&g, &reg, &[]).unwrap();
        let mut plan = Plan::build(
            &checked,
            &PlanOptions { timing: false, out_dir: Some(dir.path().to_path_buf()), ..PlanOptions::default() },
        )
        .unwrap();
        let report = run_offline(&mut plan, RunOptions::default()).unwrap();
        // 4321 samples at 10 kHz are 432.1 base ticks: the run covers the
        // 432 whole ticks (4320 frames).
        assert_eq!(report.ticks, 432);
        let line = &report.summaries.iter().find(|(n, _)| n == "dst").unwrap().1.lines[0];
        assert_eq!(line, "wrote out.wav (4320 frames, 2 channels, 10000 Hz)");

        let a = super::format::Recording::open(&dir.path().join("in")).unwrap();
        let b = super::format::Recording::open(&dir.path().join("out")).unwrap();
        for c in ["force", "pos"] {
            assert_eq!(&a.channel(c).unwrap()[..4320], b.channel(c).unwrap(), "{c}");
        }
        assert_eq!(b.meta().channels, vec![Channel::new("force", "N"), Channel::new("pos", "m")]);
    }
}
