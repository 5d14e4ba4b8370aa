//! The session recorder: a non-real-time thread that drains the tap and
//! event rings in chunks into the session's files and flushes them at a
//! steady pace, so a killed process leaves readable files.

use super::session::{event_json, FileSpec};
use evflow_engine::live::{rtrb, Event, EventKind, TapInfo};
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::fs::File;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// One recording being written.
struct Sink {
    spec: FileSpec,
    writer: Option<RecordingWriter>,
    /// Indices into the tap rings, one per channel.
    rings: Vec<usize>,
    /// Frames accepted (samples of each channel), including zero-filled gaps.
    frames: u64,
    error: Option<String>,
    gap_frames: u64,
}

/// What the recorder wrote.
#[derive(Debug, Clone, Default)]
pub struct RecorderReport {
    /// (file, frames, zero-filled gap frames, error) per recording.
    pub files: Vec<(String, u64, u64, Option<String>)>,
    /// Events written.
    pub events: u64,
    /// An error writing the event log.
    pub event_error: Option<String>,
}

/// A second, non-real-time reader of what the recorder drains (the
/// studio): it sees each tap's samples, in order, right after they leave
/// their ring, and every event. It runs on the recorder's thread, so it
/// must be quick and never block.
pub trait Tee: Send {
    /// Samples of tap `tap` (index in tap order), oldest first; zeros for
    /// samples lost to a full ring.
    fn samples(&mut self, tap: usize, samples: &[f64]);
    /// An event, in order.
    fn event(&mut self, e: &Event);
}

/// Owns the consumer ends of the rings and the session's files.
pub struct Recorder {
    tee: Option<Box<dyn Tee>>,
    sinks: Vec<Sink>,
    rings: Vec<rtrb::Consumer<f64>>,
    events: rtrb::Consumer<Event>,
    log: Option<std::io::BufWriter<File>>,
    names: Vec<String>,
    report: RecorderReport,
    scratch: Vec<f64>,
}

impl Recorder {
    /// Creates every file of the session (live writers: they never replace
    /// an existing recording). `specs` lists inputs then outputs; `taps`
    /// are the ring ends in the same tap order.
    pub fn create(
        dir: &Path,
        specs: &[FileSpec],
        taps: Vec<(TapInfo, rtrb::Consumer<f64>)>,
        events: rtrb::Consumer<Event>,
        names: Vec<String>,
        source: &str,
    ) -> anyhow::Result<Self> {
        let mut sinks = Vec::new();
        let infos: Vec<TapInfo> = taps.iter().map(|(i, _)| i.clone()).collect();
        let rings = taps.into_iter().map(|(_, r)| r).collect();
        let mut used = vec![false; infos.len()];
        for spec in specs {
            let mut idx = Vec::new();
            for port in &spec.ports {
                let i = (0..infos.len())
                    .find(|&i| !used[i] && infos[i].node == spec.node && infos[i].port == *port)
                    .ok_or_else(|| anyhow::anyhow!("no tap for {}.{port}", spec.node))?;
                used[i] = true;
                idx.push(i);
            }
            let path = dir.join(&spec.file);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
            let channels = spec.ports.iter().map(|p| Channel::new(p.clone(), "")).collect();
            let mut meta = RecordingMeta::new(spec.rate, channels);
            meta.source = format!("{source}: `{}` ({})", spec.node, spec.ports.join(", "));
            let mut writer = RecordingWriter::create_live(&path, meta)
                .map_err(|e| anyhow::anyhow!("cannot start the session recording: {e}"))?;
            writer.reserve_frames(8192);
            writer.flush().map_err(|e| anyhow::anyhow!("{e}"))?;
            sinks.push(Sink {
                spec: spec.clone(),
                writer: Some(writer),
                rings: idx,
                frames: 0,
                error: None,
                gap_frames: 0,
            });
        }
        let log = File::create(dir.join("events.jsonl"))?;
        Ok(Self {
            tee: None,
            sinks,
            rings,
            events,
            log: Some(std::io::BufWriter::new(log)),
            names,
            report: RecorderReport::default(),
            scratch: Vec::new(),
        })
    }

    /// Hands every drained sample and event to `tee` as well.
    #[cfg_attr(not(feature = "studio"), allow(dead_code))]
    pub fn tee(mut self, tee: Box<dyn Tee>) -> Self {
        self.tee = Some(tee);
        self
    }

    /// Moves up to `limit` frames (all available when `None`) of a sink
    /// from its rings to its file.
    fn drain_sink(&mut self, s: usize, limit: Option<u64>) {
        let sink = &mut self.sinks[s];
        let avail = sink.rings.iter().map(|&r| self.rings[r].slots()).min().unwrap_or(0) as u64;
        let n = limit.map_or(avail, |l| l.min(avail)) as usize;
        if n == 0 {
            return;
        }
        let ch = sink.rings.len();
        self.scratch.clear();
        self.scratch.resize(n * ch, 0.0);
        for (c, &r) in sink.rings.iter().enumerate() {
            if let Ok(chunk) = self.rings[r].read_chunk(n) {
                let (a, b) = chunk.as_slices();
                if let Some(t) = self.tee.as_mut() {
                    t.samples(r, a);
                    t.samples(r, b);
                }
                for (i, x) in a.iter().chain(b).enumerate() {
                    self.scratch[i * ch + c] = *x;
                }
                chunk.commit_all();
            }
        }
        sink.frames += n as u64;
        write(sink, &self.scratch);
    }

    /// Frames of a sink due for ticks [0, tick).
    fn due(spec: &FileSpec, tick: u64) -> u64 {
        spec.ratio.count(0, tick)
    }

    /// Drains the event ring, bringing the recordings up to each event's
    /// tick first (so gaps are filled at the right frame), then every ring.
    pub fn pump(&mut self) {
        while let Ok(e) = self.events.pop() {
            for s in 0..self.sinks.len() {
                let due = Self::due(&self.sinks[s].spec, e.tick);
                let have = self.sinks[s].frames;
                if due > have {
                    self.drain_sink(s, Some(due - have));
                }
            }
            if let EventKind::Gap { ticks } = e.kind {
                for sink in &mut self.sinks {
                    let missing = Self::due(&sink.spec, e.tick + ticks) - Self::due(&sink.spec, e.tick);
                    let zeros = vec![0.0; (missing as usize) * sink.rings.len()];
                    if let Some(t) = self.tee.as_mut() {
                        for &r in &sink.rings {
                            t.samples(r, &zeros[..missing as usize]);
                        }
                    }
                    sink.frames += missing;
                    sink.gap_frames += missing;
                    write(sink, &zeros);
                }
            }
            if let Some(t) = self.tee.as_mut() {
                t.event(&e);
            }
            self.log_event(&e);
        }
        for s in 0..self.sinks.len() {
            self.drain_sink(s, None);
        }
    }

    fn log_event(&mut self, e: &Event) {
        let line = event_json(e, &self.names).to_string();
        if let Some(log) = self.log.as_mut() {
            if let Err(err) = writeln!(log, "{line}") {
                self.report.event_error.get_or_insert_with(|| format!("events.jsonl: {err}"));
            }
        }
        self.report.events += 1;
    }

    /// Writes everything out: recordings (WAV header and sidecar updated)
    /// and the event log.
    pub fn flush(&mut self) {
        if let Some(log) = self.log.as_mut() {
            if let Err(err) = log.flush().and_then(|_| log.get_ref().sync_data()) {
                self.report.event_error.get_or_insert_with(|| format!("events.jsonl: {err}"));
            }
        }
        for sink in &mut self.sinks {
            if let Some(w) = sink.writer.as_mut() {
                if let Err(e) = w.flush() {
                    sink.error.get_or_insert_with(|| e.to_string());
                }
            }
        }
    }

    /// Runs until `done` is set (after the real-time thread ended), pumping
    /// every `pace` and flushing every `flush_every`; then drains what is
    /// left, finishes every file and reports.
    pub fn run(mut self, done: Arc<AtomicBool>, pace: Duration, flush_every: Duration) -> RecorderReport {
        let mut flushed = Instant::now();
        while !done.load(Ordering::Acquire) {
            std::thread::sleep(pace);
            self.pump();
            if flushed.elapsed() >= flush_every {
                self.flush();
                flushed = Instant::now();
            }
        }
        self.pump();
        self.flush();
        for sink in &mut self.sinks {
            if let Some(w) = sink.writer.take() {
                if let Err(e) = w.finish() {
                    sink.error.get_or_insert_with(|| e.to_string());
                }
            }
            self.report.files.push((sink.spec.file.clone(), sink.frames, sink.gap_frames, sink.error.clone()));
        }
        self.log = None;
        self.report
    }
}

/// Appends interleaved frames; after an error the file stops growing (the
/// error is reported) but its ring keeps being drained.
fn write(sink: &mut Sink, frames: &[f64]) {
    if sink.error.is_some() || frames.is_empty() {
        return;
    }
    if let Some(w) = sink.writer.as_mut() {
        if let Err(e) = w.write_interleaved(frames) {
            sink.error = Some(e.to_string());
        }
    }
}
