//! The session recorder: a non-real-time thread that drains the tap and
//! event rings in chunks and hands them to the disk thread
//! ([`super::disk`]), which writes the session's files and flushes them at
//! a steady pace, so a killed process leaves readable files. The recorder
//! itself never waits on the disk.

use super::disk::{Disk, DiskQueue, Files, Op, QUEUE_SECONDS};
use super::error::SessionError;
use super::session::{event_json, FileSpec};
use evflow_engine::live::{rtrb, Event, EventKind, TapInfo};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// One recording being written.
struct Sink {
    spec: FileSpec,
    /// Indices into the tap rings, one per channel.
    rings: Vec<usize>,
    /// Frames accepted (samples of each channel), including zero-filled gaps.
    frames: u64,
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

/// Owns the consumer ends of the rings and the queue to the disk thread.
pub struct Recorder {
    tee: Option<Box<dyn Tee>>,
    sinks: Vec<Sink>,
    rings: Vec<rtrb::Consumer<f64>>,
    events: rtrb::Consumer<Event>,
    disk: DiskQueue,
    names: Vec<String>,
    events_logged: u64,
    /// Echo applied and refused changes on the console: the base rate (for
    /// the time), and whether the stop sequence began (its `enable` changes
    /// are the ending's, not the user's).
    echo: Option<(f64, bool)>,
}

impl Recorder {
    /// A recorder of the session's `files` (created before the real-time
    /// thread started) and its disk thread, which flushes them every
    /// `flush_every`. `taps` are the ring ends in tap order.
    pub fn create(
        files: Files,
        taps: Vec<(TapInfo, rtrb::Consumer<f64>)>,
        events: rtrb::Consumer<Event>,
        names: Vec<String>,
        flush_every: Duration,
    ) -> Result<Self, SessionError> {
        let infos: Vec<TapInfo> = taps.iter().map(|(i, _)| i.clone()).collect();
        let rings = taps.into_iter().map(|(_, r)| r).collect();
        let mut used = vec![false; infos.len()];
        let mut sinks = Vec::new();
        for spec in files.specs() {
            let mut idx = Vec::new();
            for port in &spec.ports {
                let i = (0..infos.len())
                    .find(|&i| !used[i] && infos[i].node == spec.node && infos[i].port == *port)
                    .ok_or_else(|| SessionError::Setup(format!("no tap for {}.{port}", spec.node)))?;
                used[i] = true;
                idx.push(i);
            }
            sinks.push(Sink { spec: spec.clone(), rings: idx, frames: 0, gap_frames: 0 });
        }
        Self::with_disk(Box::new(files), sinks, rings, events, names, flush_every)
    }

    /// A recorder of `sinks` writing to `disk` through its own thread.
    fn with_disk(
        disk: Box<dyn Disk>,
        sinks: Vec<Sink>,
        rings: Vec<rtrb::Consumer<f64>>,
        events: rtrb::Consumer<Event>,
        names: Vec<String>,
        flush_every: Duration,
    ) -> Result<Self, SessionError> {
        // The budget: QUEUE_SECONDS of every recording's samples.
        let per_second: f64 = sinks.iter().map(|s| s.spec.rate * s.spec.ports.len() as f64).sum();
        let budget = (QUEUE_SECONDS * per_second * std::mem::size_of::<f64>() as f64) as usize;
        let disk =
            DiskQueue::start(disk, sinks.len(), budget.max(1 << 16), flush_every).map_err(SessionError::spawn)?;
        Ok(Self { tee: None, sinks, rings, events, disk, names, events_logged: 0, echo: None })
    }

    /// Hands every drained sample and event to `tee` as well.
    #[cfg_attr(not(feature = "studio"), allow(dead_code))]
    pub fn tee(mut self, tee: Box<dyn Tee>) -> Self {
        self.tee = Some(tee);
        self
    }

    /// Prints each parameter change on stderr as it lands (scheduled with
    /// `--change`, typed, or from the studio), timed on the base rate.
    pub fn echo(mut self, base_rate: f64) -> Self {
        self.echo = Some((base_rate, false));
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
        let mut frames = vec![0.0; n * ch];
        for (c, &r) in sink.rings.iter().enumerate() {
            if let Ok(chunk) = self.rings[r].read_chunk(n) {
                let (a, b) = chunk.as_slices();
                if let Some(t) = self.tee.as_mut() {
                    t.samples(r, a);
                    t.samples(r, b);
                }
                for (i, x) in a.iter().chain(b).enumerate() {
                    frames[i * ch + c] = *x;
                }
                chunk.commit_all();
            }
        }
        sink.frames += n as u64;
        self.disk.send(Op::Frames { file: s, data: frames });
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
                for (s, sink) in self.sinks.iter_mut().enumerate() {
                    let missing = Self::due(&sink.spec, e.tick + ticks) - Self::due(&sink.spec, e.tick);
                    let zeros = vec![0.0; (missing as usize) * sink.rings.len()];
                    if let Some(t) = self.tee.as_mut() {
                        for &r in &sink.rings {
                            t.samples(r, &zeros[..missing as usize]);
                        }
                    }
                    sink.frames += missing;
                    sink.gap_frames += missing;
                    if missing > 0 {
                        self.disk.send(Op::Frames { file: s, data: zeros });
                    }
                }
            }
            if let Some(t) = self.tee.as_mut() {
                t.event(&e);
            }
            if let Some((rate, stopped)) = self.echo.as_mut() {
                *stopped |= matches!(e.kind, EventKind::Stop(_));
                if let Some(line) = echo_line(&e, &self.names, *rate).filter(|_| !*stopped) {
                    // Over the once-a-second status line on a terminal.
                    let clear = if std::io::stderr().is_terminal() { "\r\x1b[K" } else { "" };
                    eprintln!("{clear}{line}");
                }
            }
            self.log_event(&e);
        }
        for s in 0..self.sinks.len() {
            self.drain_sink(s, None);
        }
    }

    fn log_event(&mut self, e: &Event) {
        self.disk.send(Op::Event(event_json(e, &self.names).to_string()));
        self.events_logged += 1;
    }

    /// Runs until `done` is set (after the real-time thread ended), pumping
    /// every `pace` — except while the disk thread is more than its budget
    /// behind, when the rings are left to fill — then drains what is left,
    /// waits for the disk thread to finish every file, and reports.
    pub fn run(mut self, done: Arc<AtomicBool>, pace: Duration) -> RecorderReport {
        while !done.load(Ordering::Acquire) {
            std::thread::sleep(pace);
            if !self.disk.over_budget() {
                self.pump();
            }
        }
        self.pump();
        self.finish()
    }

    /// Waits for the disk thread to finish every file; the report.
    fn finish(self) -> RecorderReport {
        let disk = self.disk.finish(Duration::from_secs(2), |bytes| {
            let what = match bytes {
                0 => "syncing".to_string(),
                _ => format!("writing ({:.0} kB queued) and syncing", bytes as f64 / 1e3),
            };
            eprintln!("still {what} the session's files on a slow disk; the session ends once they are synced");
        });
        let files = self
            .sinks
            .iter()
            .zip(disk.files.into_iter().chain(std::iter::repeat(None)))
            .map(|(sink, err)| (sink.spec.file.clone(), sink.frames, sink.gap_frames, err))
            .collect();
        RecorderReport { files, events: self.events_logged, event_error: disk.event_error }
    }
}

/// The studio sees what the recorder drains.
#[cfg(feature = "studio")]
impl Tee for crate::studio::Ingest {
    fn samples(&mut self, tap: usize, samples: &[f64]) {
        crate::studio::Ingest::samples(self, tap, samples);
    }
    fn event(&mut self, e: &Event) {
        crate::studio::Ingest::event(self, e);
    }
}

/// The console's line for a change that landed (none for other events).
fn echo_line(e: &Event, names: &[String], base_rate: f64) -> Option<String> {
    let name = |k: u32| names.get(k as usize).map_or_else(|| format!("#{k}"), String::clone);
    let t = e.tick as f64 / base_rate;
    // As typed: the shortest text that reads back as the same value.
    let v = |x: f64| format!("{x}");
    match e.kind {
        EventKind::Set { node, param, value } => Some(format!("at {t:.3} s: {}.{param} = {}", name(node), v(value))),
        EventKind::Refused { node, param, value } => {
            Some(format!("at {t:.3} s: {}.{param} = {} refused by the node (nothing changed)", name(node), v(value)))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::super::disk::DiskReport;
    use super::*;
    use evflow_engine::rate::Ratio;
    use std::sync::mpsc;
    use std::sync::Mutex;

    #[test]
    fn a_change_that_lands_is_echoed_with_its_time_and_a_refused_one_says_so() {
        let names = vec!["drive".to_string(), "gain".to_string()];
        let set = Event { tick: 5000, kind: EventKind::Set { node: 1, param: "gain", value: 0.5 } };
        assert_eq!(echo_line(&set, &names, 1000.0).unwrap(), "at 5.000 s: gain.gain = 0.5");
        let refused = Event { tick: 250, kind: EventKind::Refused { node: 0, param: "frequency", value: -3.0 } };
        assert_eq!(
            echo_line(&refused, &names, 1000.0).unwrap(),
            "at 0.250 s: drive.frequency = -3 refused by the node (nothing changed)"
        );
        assert_eq!(echo_line(&Event { tick: 1, kind: EventKind::Replaced }, &names, 1000.0), None);
    }

    /// A disk whose first write stalls until the test lets it go (an fsync
    /// that takes seconds), keeping every frame it is given.
    struct Stalled {
        gate: Option<mpsc::Receiver<()>>,
        frames: Arc<Mutex<Vec<f64>>>,
    }

    impl Disk for Stalled {
        fn write(&mut self, op: Op) {
            if let Some(g) = self.gate.take() {
                let _ = g.recv_timeout(Duration::from_secs(30));
            }
            if let Op::Frames { data, .. } = op {
                self.frames.lock().unwrap().extend(data);
            }
        }
        fn flush(&mut self) {}
        fn finish(self: Box<Self>) -> DiskReport {
            DiskReport { files: vec![None], event_error: None }
        }
    }

    #[test]
    fn a_stalled_disk_does_not_stop_the_rings_being_drained() {
        // Two taps of one recording, rings of 100 samples (0.1 s at 1 kHz).
        let (mut producers, consumers): (Vec<_>, Vec<_>) = (0..2).map(|_| rtrb::RingBuffer::new(100)).unzip();
        let (_ev_tx, ev_rx) = rtrb::RingBuffer::new(16);
        let spec = FileSpec {
            file: "outputs/x".into(),
            node: "x".into(),
            ports: vec!["a".into(), "b".into()],
            ratio: Ratio::ONE,
            rate: 1000.0,
        };
        let sink = Sink { spec, rings: vec![0, 1], frames: 0, gap_frames: 0 };
        let (release, gate) = mpsc::channel();
        let frames = Arc::new(Mutex::new(Vec::new()));
        let disk = Box::new(Stalled { gate: Some(gate), frames: frames.clone() });
        let mut rec =
            Recorder::with_disk(disk, vec![sink], consumers, ev_rx, vec![], Duration::from_secs(3600)).unwrap();
        // Ten seconds of samples, 50 at a time, while the disk is stalled:
        // the rings never fill, since the recorder keeps draining them.
        for k in 0..10_000 {
            for (c, p) in producers.iter_mut().enumerate() {
                p.push(k as f64 + 0.5 * c as f64).expect("a ring filled: the recorder stopped draining");
            }
            if k % 50 == 49 {
                rec.pump();
            }
        }
        assert!(!rec.disk.over_budget(), "ten seconds is within the queue's budget");
        assert!(frames.lock().unwrap().len() <= 2 * 50, "the disk was still stalled");
        release.send(()).unwrap();
        let report = rec.finish();
        assert_eq!(report.files, vec![("outputs/x".to_string(), 10_000, 0, None)]);
        let got = frames.lock().unwrap();
        let want: Vec<f64> = (0..10_000).flat_map(|k| [k as f64, k as f64 + 0.5]).collect();
        assert!(*got == want, "every frame, in order, interleaved");
    }
}
