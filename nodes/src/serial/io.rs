//! The I/O thread of a link: opens the port (and reopens it after a
//! disconnect), reads with a 1 ms timeout, hands the bytes to the
//! [`HostSession`], pushes touch and force into the rings `serial.in`
//! reads, drains the actuation ring `serial.out` fills, and writes. It is an
//! ordinary thread: it may block, allocate and print; the real-time thread
//! only sees the rings and the atomics of [`LinkState`].

use super::host::{HostConfig, HostSession, Inbound, Notice, Phase};
use super::link_state::{LinkConfig, LinkReport, LinkState, ACTUATION_RING};
use super::message::{fault_names, Touch};
use serialport::{ClearBuffer, SerialPort};
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Read timeout: the longest the thread waits for bytes before it looks at
/// the actuation ring again.
const READ_TIMEOUT: Duration = Duration::from_millis(1);
/// More queued actuation samples than this (after a stall of this thread):
/// only the newest [`STALE_KEEP`] are sent.
const STALE_AFTER: usize = 16;
const STALE_KEEP: usize = 4;
/// Unwritten bytes beyond this are dropped (the port does not take them).
const BACKLOG_MAX: usize = 1 << 16;

struct Io {
    config: LinkConfig,
    state: Arc<LinkState>,
    touch: rtrb::Producer<Touch>,
    force: rtrb::Producer<f32>,
    actuation: rtrb::Consumer<f32>,
    session: HostSession,
    report: LinkReport,
}

/// The thread's body; returns when [`LinkState::stop`] is set.
pub fn run(
    config: LinkConfig,
    state: Arc<LinkState>,
    touch: rtrb::Producer<Touch>,
    force: rtrb::Producer<f32>,
    actuation: rtrb::Consumer<f32>,
) {
    let now = Instant::now();
    let host = HostConfig { timeout: config.timeout, actuation_hz: 0, touch_hz: 40, actuation: false };
    let mut io = Io {
        config,
        state,
        touch,
        force,
        actuation,
        session: HostSession::new(host, now),
        report: LinkReport::default(),
    };
    io.run();
}

impl Io {
    fn run(&mut self) {
        let mut port: Option<Box<dyn SerialPort>> = None;
        let mut next_open = Instant::now();
        let mut rbuf = vec![0u8; 4096];
        let mut samples: Vec<f32> = Vec::with_capacity(ACTUATION_RING);
        let mut backlog: Vec<u8> = Vec::with_capacity(BACKLOG_MAX);
        let mut was_up = false;
        while !self.state.stop.load(Ordering::Acquire) {
            let now = Instant::now();
            let hz = self.state.actuation_hz.load(Ordering::Relaxed);
            self.session.set_actuation(hz);
            let Some(p) = port.as_mut() else {
                self.drain_actuation(&mut samples);
                self.session.transmit(now, &samples, &mut backlog);
                backlog.clear();
                if now >= next_open {
                    match self.open() {
                        Ok(p) => {
                            port = Some(p);
                            self.session.opened(now);
                        }
                        Err(()) => next_open = now + self.config.retry,
                    }
                }
                self.publish(&mut was_up);
                std::thread::sleep(Duration::from_millis(2));
                continue;
            };
            let mut lost: Option<String> = None;
            match p.read(&mut rbuf) {
                Ok(0) => lost = Some("end of file (the device is gone)".into()),
                Ok(n) => {
                    let now = Instant::now();
                    let (touch, force, state) = (&mut self.touch, &mut self.force, &self.state);
                    let report = &mut self.report;
                    let mut notices = Vec::new();
                    self.session.receive(now, &rbuf[..n], &mut |x| deliver(x, touch, force, state, report), &mut |n| {
                        notices.push(n)
                    });
                    for n in notices {
                        self.notice(n);
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
                Err(e) => lost = Some(format!("read error: {e}")),
            }
            if lost.is_none() {
                let now = Instant::now();
                self.drain_actuation(&mut samples);
                self.session.transmit(now, &samples, &mut backlog);
                if let Err(e) = self.write(p.as_mut(), &mut backlog) {
                    lost = Some(format!("write error: {e}"));
                }
                let mut notices = Vec::new();
                self.session.tick(now, &mut |n| notices.push(n));
                for n in notices {
                    self.notice(n);
                }
            }
            if let Some(why) = lost {
                self.session.closed();
                port = None;
                backlog.clear();
                next_open = Instant::now() + self.config.retry;
                let msg = format!(
                    "link lost at sample {}: {why}; reopening every {} s",
                    self.state.sample(),
                    self.config.retry.as_secs_f64()
                );
                self.say(&msg);
                self.report.last_error = Some(why);
                self.report.event(msg);
            }
            self.publish(&mut was_up);
        }
        if let Some(mut p) = port {
            // The last samples the graph queued, then a zero sample.
            let mut bye = std::mem::take(&mut backlog);
            self.drain_actuation(&mut samples);
            self.session.transmit(Instant::now(), &samples, &mut bye);
            self.session.goodbye(&mut bye);
            let _ = p.write_all(&bye);
            let _ = p.flush();
        }
        self.session.closed();
        self.publish(&mut was_up);
    }

    /// Opens the port and clears what it held.
    fn open(&mut self) -> Result<Box<dyn SerialPort>, ()> {
        let r = serialport::new(&self.config.port, self.config.baud).timeout(READ_TIMEOUT).open();
        match r {
            Ok(p) => {
                let _ = p.clear(ClearBuffer::Input);
                Ok(p)
            }
            Err(e) => {
                let why = format!("cannot open {}: {e}", self.config.port);
                if self.report.last_error.as_deref() != Some(why.as_str()) {
                    // Said once per new reason: a session started without
                    // its device (`wait = 0`) shows why it is unconnected.
                    let msg = format!("{why}; trying again every {} s", self.config.retry.as_secs_f64());
                    self.say(&msg);
                    self.report.event(msg);
                    self.report.last_error = Some(why);
                }
                Err(())
            }
        }
    }

    /// The samples `serial.out` queued; after a stall, only the newest.
    fn drain_actuation(&mut self, samples: &mut Vec<f32>) {
        samples.clear();
        let n = self.actuation.slots();
        if n == 0 {
            return;
        }
        if let Ok(chunk) = self.actuation.read_chunk(n) {
            let skip = if n > STALE_AFTER { n - STALE_KEEP } else { 0 };
            self.report.stale_dropped += skip as u64;
            let (a, b) = chunk.as_slices();
            samples.extend(a.iter().chain(b).skip(skip));
            chunk.commit_all();
        }
    }

    /// Writes what the port takes now; the rest waits for the next turn.
    fn write(&mut self, p: &mut dyn SerialPort, backlog: &mut Vec<u8>) -> std::io::Result<()> {
        if backlog.is_empty() {
            return Ok(());
        }
        match p.write(backlog) {
            Ok(n) => {
                backlog.drain(..n);
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
            Err(e) => return Err(e),
        }
        if backlog.len() > BACKLOG_MAX {
            self.report.write_overflows += 1;
            backlog.clear();
        }
        Ok(())
    }

    fn notice(&mut self, n: Notice) {
        let sample = self.state.sample();
        let msg = match n {
            Notice::Up(h) => {
                self.report.connects += 1;
                self.report.last_error = None;
                format!(
                    "connected at sample {sample}: device protocol {}, touch {} Hz, actuation {} Hz{}",
                    h.version,
                    h.touch_hz,
                    h.actuation_hz,
                    if h.caps & super::message::caps::FORCE != 0 { ", force" } else { "" }
                )
            }
            Notice::VersionMismatch(v) => {
                let m = format!(
                    "device speaks protocol version {v}, evflow speaks {}: the link stays down",
                    super::message::VERSION
                );
                self.report.last_error = Some(m.clone());
                m
            }
            Notice::Silent(t) => {
                let m = format!("no valid frame from the device for {} s", t.as_secs_f64());
                self.report.last_error = Some(m.clone());
                format!("link lost at sample {sample}: {m}; saying HELLO again")
            }
            Notice::Faults(0) => format!("device faults cleared at sample {sample}"),
            Notice::Faults(b) => format!("device fault at sample {sample}: {}", fault_names(b)),
        };
        self.say(&msg);
        self.report.event(msg);
    }

    /// Tells the user at once (link changes are rare), unless notices are
    /// off ([`set_notices`]); the end-of-run summary lists them anyway.
    fn say(&self, msg: &str) {
        if NOTICES.load(std::sync::atomic::Ordering::Relaxed) {
            eprintln!("serial {}: {msg}", self.config.port);
        }
    }

    /// Publishes the link state to the nodes.
    fn publish(&mut self, was_up: &mut bool) {
        let up = self.session.phase() == Phase::Up;
        if *was_up && !up {
            self.report.disconnects += 1;
        }
        *was_up = up;
        self.state.faults.store(self.session.faults(), Ordering::Relaxed);
        self.state.connected.store(up, Ordering::Release);
        self.report.counters = self.session.counters();
        if let Ok(mut r) = self.state.report.lock() {
            r.clone_from(&self.report);
        }
    }
}

fn deliver(
    x: Inbound,
    touch: &mut rtrb::Producer<Touch>,
    force: &mut rtrb::Producer<f32>,
    state: &LinkState,
    report: &mut LinkReport,
) {
    let reading = state.has_reader.load(Ordering::Relaxed);
    match x {
        Inbound::Touch(t) => {
            if touch.push(t).is_err() && reading {
                report.touch_overruns += 1;
            }
        }
        Inbound::Force(f) => {
            if force.push(f).is_err() && reading {
                report.force_overruns += 1;
            }
        }
    }
}

/// Whether I/O threads print link changes on stderr as they happen.
static NOTICES: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);

/// Turns the I/O threads' immediate stderr notices (link lost, reconnected,
/// device faults) on or off for the whole process — off for `evflow live
/// -q`. The notices still reach each node's end-of-run summary.
pub fn set_notices(on: bool) {
    NOTICES.store(on, std::sync::atomic::Ordering::Relaxed);
}
