//! The session's disk thread: it owns the recordings and the event log and
//! writes what the recorder hands it through a queue, so a slow disk (an
//! fsync that takes seconds on a loaded machine) never keeps the recorder
//! from draining the real-time thread's rings. The queue is bounded in
//! bytes: past its budget the recorder stops draining, the rings fill and
//! the real-time thread counts the lost ticks as a gap — the same outcome
//! as before, only seconds later and with memory still bounded.

use super::error::SessionError;
use super::session::FileSpec;
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::fs::File;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Seconds of the session's samples the queue to the disk thread may hold
/// before the recorder stops draining the rings.
pub(super) const QUEUE_SECONDS: f64 = 60.0;

/// One thing to write.
pub(super) enum Op {
    /// Interleaved frames for recording `file` (in the order of the specs
    /// given to [`Files::create`]).
    Frames {
        /// Index of the recording.
        file: usize,
        /// Interleaved samples.
        data: Vec<f64>,
    },
    /// One line of the event log (without its newline).
    Event(String),
}

impl Op {
    /// Bytes the op holds (what it counts against the queue's budget).
    fn bytes(&self) -> usize {
        match self {
            Op::Frames { data, .. } => data.len() * std::mem::size_of::<f64>(),
            Op::Event(line) => line.len(),
        }
    }
}

/// What the disk thread reports at the end.
#[derive(Debug, Clone, Default)]
pub(super) struct DiskReport {
    /// The first error of each recording (`None`: written whole).
    pub files: Vec<Option<String>>,
    /// The first error writing the event log.
    pub event_error: Option<String>,
}

/// Where the disk thread writes: the session's files, or a stand-in in tests.
pub(super) trait Disk: Send + 'static {
    /// Writes one op (errors are kept for the report).
    fn write(&mut self, op: Op);
    /// Makes everything written so far durable and readable.
    fn flush(&mut self);
    /// Finishes every file and reports.
    fn finish(self: Box<Self>) -> DiskReport;
}

/// The session's recordings and event log.
pub struct Files {
    specs: Vec<FileSpec>,
    writers: Vec<(Option<RecordingWriter>, Option<String>)>,
    log: Option<std::io::BufWriter<File>>,
    event_error: Option<String>,
}

impl Files {
    /// Creates every recording of `specs` (inputs then outputs; live
    /// writers, which never replace an existing recording) and the event
    /// log in the session folder `dir`. Each file is synced to disk once
    /// here, which can take seconds on a loaded machine: call it before the
    /// real-time thread starts filling its rings.
    pub fn create(dir: &Path, specs: &[FileSpec], source: &str) -> Result<Self, SessionError> {
        let mut writers = Vec::new();
        for spec in specs {
            let path = dir.join(&spec.file);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(SessionError::file(parent, "cannot create"))?;
            }
            let channels = spec.ports.iter().map(|p| Channel::new(p.clone(), "")).collect();
            let mut meta = RecordingMeta::new(spec.rate, channels);
            meta.source = format!("{source}: `{}` ({})", spec.node, spec.ports.join(", "));
            let mut writer = RecordingWriter::create_live(&path, meta)
                .map_err(|e| SessionError::Run(format!("cannot start the session recording: {e}")))?;
            writer.reserve_frames(8192);
            writer.flush().map_err(|e| SessionError::Run(e.to_string()))?;
            writers.push((Some(writer), None));
        }
        let events = dir.join("events.jsonl");
        let log = File::create(&events).map_err(SessionError::file(&events, "cannot create"))?;
        Ok(Self { specs: specs.to_vec(), writers, log: Some(std::io::BufWriter::new(log)), event_error: None })
    }

    /// Writes the event log out and syncs it.
    fn flush_log(&mut self) {
        if let Some(log) = self.log.as_mut() {
            if let Err(e) = log.flush().and_then(|_| log.get_ref().sync_data()) {
                self.event_error.get_or_insert_with(|| format!("events.jsonl: {e}"));
            }
        }
    }

    /// What each recording holds, in the order [`Op::Frames`] names them.
    pub(super) fn specs(&self) -> &[FileSpec] {
        &self.specs
    }
}

impl Disk for Files {
    /// After an error a recording stops growing (the error is reported);
    /// the others go on.
    fn write(&mut self, op: Op) {
        match op {
            Op::Frames { file, data } => {
                if let Some((Some(w), err @ None)) = self.writers.get_mut(file) {
                    if let Err(e) = w.write_interleaved(&data) {
                        *err = Some(e.to_string());
                    }
                }
            }
            Op::Event(line) => {
                if let Some(log) = self.log.as_mut() {
                    if let Err(e) = writeln!(log, "{line}") {
                        self.event_error.get_or_insert_with(|| format!("events.jsonl: {e}"));
                    }
                }
            }
        }
    }

    fn flush(&mut self) {
        self.flush_log();
        for (w, err) in &mut self.writers {
            if let Some(w) = w.as_mut() {
                if let Err(e) = w.flush() {
                    err.get_or_insert_with(|| e.to_string());
                }
            }
        }
    }

    /// The event log is flushed and synced; each recording is finished
    /// (written out, synced, its sidecar written), which is its flush.
    fn finish(mut self: Box<Self>) -> DiskReport {
        self.flush_log();
        let files = self
            .writers
            .drain(..)
            .map(|(w, mut err)| {
                if let Some(Err(e)) = w.map(RecordingWriter::finish) {
                    err.get_or_insert_with(|| e.to_string());
                }
                err
            })
            .collect();
        self.log = None;
        DiskReport { files, event_error: self.event_error.take() }
    }
}

/// The recorder's end of the queue to the disk thread.
pub(super) struct DiskQueue {
    tx: Option<mpsc::Sender<Op>>,
    queued: Arc<AtomicUsize>,
    budget: usize,
    files: usize,
    thread: Option<JoinHandle<DiskReport>>,
}

impl DiskQueue {
    /// Starts the disk thread writing to `disk` (`files` recordings),
    /// flushing every `flush_every`; the recorder is told to hold back once
    /// more than `budget` bytes wait.
    pub(super) fn start(
        disk: Box<dyn Disk>,
        files: usize,
        budget: usize,
        flush_every: Duration,
    ) -> std::io::Result<Self> {
        let (tx, rx) = mpsc::channel::<Op>();
        let queued = Arc::new(AtomicUsize::new(0));
        let q = queued.clone();
        let thread = std::thread::Builder::new()
            .name("evflow-disk".into())
            .spawn(move || write_until_closed(disk, &rx, &q, flush_every))?;
        Ok(Self { tx: Some(tx), queued, budget, files, thread: Some(thread) })
    }

    /// Queues an op (never blocks; the budget is the caller's to check).
    pub(super) fn send(&self, op: Op) {
        let n = op.bytes();
        self.queued.fetch_add(n, Ordering::AcqRel);
        if let Some(tx) = &self.tx {
            if tx.send(op).is_err() {
                // The disk thread has ended (it panicked): nothing waits for these bytes.
                self.queued.fetch_sub(n, Ordering::AcqRel);
            }
        }
    }

    /// True while more than the budget waits to be written.
    pub(super) fn over_budget(&self) -> bool {
        self.queued.load(Ordering::Acquire) > self.budget
    }

    /// Bytes waiting to be written.
    #[cfg(test)]
    pub(super) fn queued(&self) -> usize {
        self.queued.load(Ordering::Acquire)
    }

    /// Closes the queue, waits for the disk thread to write and finish
    /// everything, and reports. Should that take longer than `patience`
    /// (a slow disk), `notice` is called once with the bytes still queued,
    /// so the user knows why the session has not ended yet.
    pub(super) fn finish(mut self, patience: Duration, mut notice: impl FnMut(usize)) -> DiskReport {
        self.tx = None;
        let asked = Instant::now();
        let mut told = false;
        while self.thread.as_ref().is_some_and(|t| !t.is_finished()) {
            if !told && asked.elapsed() >= patience {
                notice(self.queued.load(Ordering::Acquire));
                told = true;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(report)) => report,
            _ => {
                let failed = "the session's disk thread failed".to_string();
                DiskReport { files: vec![Some(failed.clone()); self.files], event_error: Some(failed) }
            }
        }
    }
}

/// The disk thread's loop: writes ops in order, flushes every
/// `flush_every`, and finishes the files once the queue closes.
fn write_until_closed(
    mut disk: Box<dyn Disk>,
    rx: &mpsc::Receiver<Op>,
    queued: &AtomicUsize,
    flush_every: Duration,
) -> DiskReport {
    let mut flushed = Instant::now();
    loop {
        match rx.recv_timeout(flush_every.saturating_sub(flushed.elapsed())) {
            Ok(op) => {
                let n = op.bytes();
                disk.write(op);
                queued.fetch_sub(n, Ordering::AcqRel);
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => break,
        }
        if flushed.elapsed() >= flush_every {
            disk.flush();
            flushed = Instant::now();
        }
    }
    disk.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    /// A disk that holds every write until the test opens its gate.
    struct Gated {
        gate: Arc<Mutex<()>>,
        written: Arc<AtomicUsize>,
        flushes: Arc<AtomicUsize>,
    }

    impl Disk for Gated {
        fn write(&mut self, op: Op) {
            drop(self.gate.lock().unwrap());
            self.written.fetch_add(op.bytes(), Ordering::SeqCst);
        }
        fn flush(&mut self) {
            self.flushes.fetch_add(1, Ordering::SeqCst);
        }
        fn finish(self: Box<Self>) -> DiskReport {
            DiskReport { files: vec![None, Some("full".into())], event_error: None }
        }
    }

    #[test]
    fn the_queue_counts_its_bytes_against_the_budget_and_drains_in_full() {
        let gate = Arc::new(Mutex::new(()));
        let (written, flushes) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let disk = Gated { gate: gate.clone(), written: written.clone(), flushes: flushes.clone() };
        let held = gate.lock().unwrap();
        let q = DiskQueue::start(Box::new(disk), 2, 1000, Duration::from_millis(5)).unwrap();
        for _ in 0..10 {
            q.send(Op::Frames { file: 0, data: vec![0.0; 20] });
        }
        assert!(q.queued() >= 9 * 160, "{} bytes queued", q.queued());
        assert!(q.over_budget(), "1600 bytes against a budget of 1000");
        q.send(Op::Event("{}".into()));
        // The first write outlasts the flush period: a flush follows it.
        std::thread::sleep(Duration::from_millis(20));
        drop(held);
        let report = q.finish(Duration::from_secs(60), |_| panic!("no notice"));
        assert_eq!(written.load(Ordering::SeqCst), 10 * 160 + 2, "every op written");
        assert!(flushes.load(Ordering::SeqCst) >= 1, "flushed once the period passed");
        assert_eq!(report.files, vec![None, Some("full".to_string())]);
    }

    #[test]
    fn a_slow_finish_is_noticed_once_with_what_is_still_queued() {
        /// A disk that takes 200 ms per write.
        struct Slow;
        impl Disk for Slow {
            fn write(&mut self, _: Op) {
                std::thread::sleep(Duration::from_millis(200));
            }
            fn flush(&mut self) {}
            fn finish(self: Box<Self>) -> DiskReport {
                DiskReport { files: vec![None], event_error: None }
            }
        }
        let q = DiskQueue::start(Box::new(Slow), 1, 1 << 20, Duration::from_secs(60)).unwrap();
        for _ in 0..3 {
            q.send(Op::Frames { file: 0, data: vec![0.0; 100] });
        }
        let mut notices = Vec::new();
        let report = q.finish(Duration::from_millis(10), |bytes| notices.push(bytes));
        assert_eq!(notices.len(), 1, "told once: {notices:?}");
        assert!(notices[0] >= 800, "the bytes still queued: {notices:?}");
        assert_eq!(report.files, vec![None]);
    }

    #[test]
    fn a_disk_thread_that_dies_fails_every_file_by_name_of_the_cause() {
        struct Panics;
        impl Disk for Panics {
            fn write(&mut self, _: Op) {
                panic!("disk on fire");
            }
            fn flush(&mut self) {}
            fn finish(self: Box<Self>) -> DiskReport {
                DiskReport::default()
            }
        }
        let q = DiskQueue::start(Box::new(Panics), 3, 1 << 20, Duration::from_secs(1)).unwrap();
        q.send(Op::Event("x".into()));
        let report = q.finish(Duration::from_secs(60), |_| panic!("no notice"));
        assert_eq!(report.files.len(), 3);
        assert!(report.files.iter().all(|e| e.as_deref() == Some("the session's disk thread failed")));
        assert!(report.event_error.is_some());
    }

    #[test]
    fn files_write_frames_and_events_and_finish_them() {
        use evflow_nodes::recording::format::Recording;
        let dir = tempfile::tempdir().unwrap();
        let spec = FileSpec { ports: vec!["a".into(), "b".into()], ..r_spec() };
        let files = Files::create(dir.path(), &[spec], "test").unwrap();
        assert!(dir.path().join("outputs/r.json").exists(), "created before any frame");
        let q = DiskQueue::start(Box::new(files), 1, 1 << 20, Duration::from_millis(1)).unwrap();
        q.send(Op::Frames { file: 0, data: vec![1.0, 2.0, 3.0, 4.0] });
        q.send(Op::Event("{\"tick\":1}".into()));
        q.send(Op::Frames { file: 0, data: vec![5.0, 6.0] });
        let report = q.finish(Duration::from_secs(60), |_| panic!("no notice"));
        assert_eq!(report.files, vec![None]);
        assert_eq!(report.event_error, None);
        let r = Recording::open(&dir.path().join("outputs/r")).unwrap();
        assert_eq!(r.frames(), 3);
        assert_eq!(r.channel("b"), Some(&[2.0, 4.0, 6.0][..]));
        assert_eq!(std::fs::read_to_string(dir.path().join("events.jsonl")).unwrap(), "{\"tick\":1}\n");
        // A second session into the same folder is refused, naming the file.
        let again = Files::create(dir.path(), &[r_spec()], "test");
        let e = again.err().expect("never overwrites a recording").to_string();
        assert!(e.contains("outputs/r"), "{e}");
    }

    fn r_spec() -> FileSpec {
        FileSpec {
            file: "outputs/r".into(),
            node: "r".into(),
            ports: vec!["a".into()],
            ratio: evflow_engine::rate::Ratio::ONE,
            rate: 1000.0,
        }
    }
}
