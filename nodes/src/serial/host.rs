//! The host's side of the protocol as a state machine, with no port and no
//! clock of its own: the I/O thread feeds it the bytes it read and the
//! actuation samples the graph produced, with the time, and writes out what
//! it returns. Handshake, liveness, heartbeats, sequence numbers, device
//! faults and the stall fade live here (`docs/serial-protocol.md`), so they
//! are tested without hardware.

use super::frame::MAX_FRAME;
use super::message::{self, caps, kind, Hello, Message, Role, Touch, VERSION};
use super::stream::{StreamDecoder, StreamStats};
use std::time::{Duration, Instant};

/// How often the host repeats HELLO until the device answers.
pub const HELLO_EVERY: Duration = Duration::from_millis(250);
/// How often the host sends a heartbeat while the link is up.
pub const HEARTBEAT_EVERY: Duration = Duration::from_millis(100);
/// Without new actuation samples for this long, the host fades out.
pub const STALL_AFTER: Duration = Duration::from_millis(5);
/// Frames of the stall fade (one per millisecond: 10 ms to zero).
pub const STALL_FADE_FRAMES: u32 = 10;

/// Fixed settings of a link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HostConfig {
    /// No valid frame for this long: the link is down.
    pub timeout: Duration,
    /// Actuation rate announced in HELLO, Hz.
    pub actuation_hz: u16,
    /// Touch rate announced in HELLO, Hz.
    pub touch_hz: u16,
    /// True when a `serial.out` sends actuation on this link.
    pub actuation: bool,
}

/// Whether the link is up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// The port is closed.
    Closed,
    /// The port is open; HELLO sent, no (matching) answer yet.
    Handshake,
    /// The device answered with protocol version 1 and frames keep coming.
    Up,
}

/// What the host receives for the graph.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Inbound {
    /// A touch frame.
    Touch(Touch),
    /// A force sample, N.
    Force(f32),
}

/// A change worth telling the user about.
#[derive(Debug, Clone, PartialEq)]
pub enum Notice {
    /// The device answered the handshake: the link is up.
    Up(Hello),
    /// The device speaks another protocol version: the link stays down.
    VersionMismatch(u8),
    /// No valid frame for the timeout: the link is down (port still open).
    Silent(Duration),
    /// The device's fault bits changed.
    Faults(u16),
}

/// Counters of one direction or the other, for the nodes' summaries.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostCounters {
    /// Frame-level counters of the receiver (summed over connections).
    pub stream: StreamStats,
    /// Frames of unknown types.
    pub unknown_type: u64,
    /// Frames whose payload length did not fit their type.
    pub bad_payload: u64,
    /// Frames missing by their sequence numbers.
    pub lost: u64,
    /// Frames that arrived with an older sequence number than expected.
    pub out_of_order: u64,
    /// Touch frames received.
    pub touch: u64,
    /// Force frames received.
    pub force: u64,
    /// Heartbeats received.
    pub heartbeats: u64,
    /// Actuation frames sent (the graph's samples).
    pub sent: u64,
    /// Actuation samples clipped to ±1 (or NaN sent as 0).
    pub clipped: u64,
    /// Actuation samples dropped because the link was down.
    pub dropped_down: u64,
    /// Stall fades begun (the graph stopped delivering samples).
    pub stall_fades: u64,
}

/// Sequence-number bookkeeping of the frames received.
#[derive(Debug, Clone, Copy, Default)]
struct SeqTracker {
    expected: Option<u16>,
}

impl SeqTracker {
    /// Frames missing before `seq` (0 when in order), or `None` when `seq` is old.
    fn observe(&mut self, seq: u16) -> Option<u64> {
        let gap = match self.expected {
            None => Some(0),
            Some(e) => {
                let d = seq.wrapping_sub(e);
                if d < 0x8000 {
                    Some(d as u64)
                } else {
                    None
                }
            }
        };
        self.expected = Some(seq.wrapping_add(1));
        gap
    }
}

/// The host's protocol state.
pub struct HostSession {
    config: HostConfig,
    phase: Phase,
    decoder: StreamDecoder,
    /// Decoder counters of earlier connections.
    stream_before: StreamStats,
    seq_out: u16,
    seq_in: SeqTracker,
    last_rx: Instant,
    next_hello: Instant,
    next_heartbeat: Instant,
    started: Instant,
    device: Option<Hello>,
    /// When this host last sent HELLO, and whether a device HELLO it did
    /// not ask for (the device reset, or never got ours) awaits an answer.
    hello_sent: Option<Instant>,
    rehello: bool,
    faults: u16,
    /// Last actuation sample sent, when it came and the fade in progress.
    last_u: i16,
    last_sample_at: Instant,
    fade_left: u32,
    fade_from: i16,
    next_fade: Instant,
    counters: HostCounters,
    /// Frames of one read (reused: the I/O thread allocates once).
    scratch: Vec<super::frame::Frame>,
}

impl HostSession {
    /// A session with the port closed.
    pub fn new(config: HostConfig, now: Instant) -> Self {
        Self {
            config,
            phase: Phase::Closed,
            decoder: StreamDecoder::new(),
            stream_before: StreamStats::default(),
            seq_out: 0,
            seq_in: SeqTracker::default(),
            last_rx: now,
            next_hello: now,
            next_heartbeat: now,
            started: now,
            device: None,
            hello_sent: None,
            rehello: false,
            faults: 0,
            last_u: 0,
            last_sample_at: now,
            fade_left: 0,
            fade_from: 0,
            next_fade: now,
            counters: HostCounters::default(),
            scratch: Vec::with_capacity(256),
        }
    }

    /// Announces actuation at `hz` in the next HELLOs and enables the
    /// stall fade (0: no `serial.out` on this link).
    pub fn set_actuation(&mut self, hz: u16) {
        self.config.actuation = hz > 0;
        self.config.actuation_hz = hz;
    }

    /// The link's phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// True while the link is up.
    pub fn connected(&self) -> bool {
        self.phase == Phase::Up
    }

    /// The device's fault bits (0 while unknown).
    pub fn faults(&self) -> u16 {
        self.faults
    }

    /// The device's HELLO, once it answered.
    pub fn device(&self) -> Option<Hello> {
        self.device
    }

    /// Counters so far.
    pub fn counters(&self) -> HostCounters {
        let mut c = self.counters;
        let s = self.decoder.stats();
        let b = self.stream_before;
        c.stream = StreamStats {
            bytes: b.bytes + s.bytes,
            frames: b.frames + s.frames,
            frame_bytes: b.frame_bytes + s.frame_bytes,
            garbage_bytes: b.garbage_bytes + s.garbage_bytes,
            bad_crc: b.bad_crc + s.bad_crc,
            truncated: b.truncated + s.truncated,
            bad_length: b.bad_length + s.bad_length,
        };
        c
    }

    /// The port was (re)opened: start the handshake.
    pub fn opened(&mut self, now: Instant) {
        self.phase = Phase::Handshake;
        self.seq_in = SeqTracker::default();
        self.last_rx = now;
        self.next_hello = now;
        self.next_heartbeat = now + HEARTBEAT_EVERY;
        self.device = None;
        self.faults = 0;
        self.fade_left = 0;
        self.last_u = 0;
    }

    /// The port was closed (read or write error, end of file): what was
    /// buffered is counted, the link is down.
    pub fn closed(&mut self) {
        self.decoder.end_of_stream(|_| {});
        let s = self.decoder.stats();
        self.decoder = StreamDecoder::new();
        self.stream_before = StreamStats {
            bytes: self.stream_before.bytes + s.bytes,
            frames: self.stream_before.frames + s.frames,
            frame_bytes: self.stream_before.frame_bytes + s.frame_bytes,
            garbage_bytes: self.stream_before.garbage_bytes + s.garbage_bytes,
            bad_crc: self.stream_before.bad_crc + s.bad_crc,
            truncated: self.stream_before.truncated + s.truncated,
            bad_length: self.stream_before.bad_length + s.bad_length,
        };
        self.phase = Phase::Closed;
        self.device = None;
        self.faults = 0;
    }

    /// Bytes read from the port: frames are decoded, touch and force go to
    /// `deliver`, changes worth reporting to `notice`.
    pub fn receive(
        &mut self,
        now: Instant,
        bytes: &[u8],
        deliver: &mut impl FnMut(Inbound),
        notice: &mut impl FnMut(Notice),
    ) {
        let mut frames = std::mem::take(&mut self.scratch);
        frames.clear();
        self.decoder.feed(bytes, |f| frames.push(f));
        for f in &frames {
            self.frame(now, f, deliver, notice);
        }
        self.scratch = frames;
    }

    fn frame(
        &mut self,
        now: Instant,
        f: &super::frame::Frame,
        deliver: &mut impl FnMut(Inbound),
        notice: &mut impl FnMut(Notice),
    ) {
        let m = match Message::from_frame(f) {
            Ok(m) => m,
            Err(message::MessageError::UnknownType(_)) => {
                self.counters.unknown_type += 1;
                return;
            }
            Err(_) => {
                self.counters.bad_payload += 1;
                return;
            }
        };
        if let Message::Hello(h) = m {
            self.seq_in = SeqTracker::default();
            self.seq_in.observe(f.seq);
            if h.role != Role::Device {
                return;
            }
            if h.version != VERSION {
                self.phase = Phase::Handshake;
                notice(Notice::VersionMismatch(h.version));
                return;
            }
            self.last_rx = now;
            self.device = Some(h);
            // A device HELLO while up that answers none of ours: the device
            // reset (its power-up HELLO) or never got our HELLO (it says
            // so when it hears frames before one). Say HELLO again, or it
            // stays idle while we stream.
            let asked = self.hello_sent.is_some_and(|t| now.saturating_duration_since(t) <= HELLO_EVERY);
            if self.phase == Phase::Up && !asked {
                self.rehello = true;
            }
            if self.phase != Phase::Up {
                self.phase = Phase::Up;
                self.faults = 0;
                notice(Notice::Up(h));
            }
            return;
        }
        match self.seq_in.observe(f.seq) {
            Some(gap) => self.counters.lost += gap,
            None => self.counters.out_of_order += 1,
        }
        if self.phase != Phase::Up {
            // Frames before the device's HELLO: the device is talking to an
            // earlier session (or another version); ignore until it answers.
            return;
        }
        self.last_rx = now;
        match m {
            Message::Touch(t) => {
                self.counters.touch += 1;
                deliver(Inbound::Touch(t));
            }
            Message::Force(x) => {
                self.counters.force += 1;
                deliver(Inbound::Force(x));
            }
            Message::Heartbeat { faults, .. } | Message::Fault { faults } => {
                if matches!(m, Message::Heartbeat { .. }) {
                    self.counters.heartbeats += 1;
                }
                if faults != self.faults {
                    self.faults = faults;
                    notice(Notice::Faults(faults));
                }
            }
            // A device never sends these; ignore.
            Message::Actuation(_) | Message::Hello(_) => {}
        }
    }

    /// Time passes: a silent device takes the link down.
    pub fn tick(&mut self, now: Instant, notice: &mut impl FnMut(Notice)) {
        if self.phase == Phase::Up && now.saturating_duration_since(self.last_rx) > self.config.timeout {
            self.phase = Phase::Handshake;
            self.next_hello = now;
            self.faults = 0;
            notice(Notice::Silent(self.config.timeout));
        }
    }

    fn push(&mut self, m: Message, out: &mut Vec<u8>) {
        let mut b = [0u8; MAX_FRAME];
        if let Ok(n) = m.encode(self.seq_out, &mut b) {
            out.extend_from_slice(&b[..n]);
            self.seq_out = self.seq_out.wrapping_add(1);
        }
    }

    /// The bytes to write now: HELLO while handshaking, heartbeats, one
    /// ACTUATION frame per sample in `samples` (dropped while the link is
    /// down), and the stall fade when samples stop coming.
    pub fn transmit(&mut self, now: Instant, samples: &[f32], out: &mut Vec<u8>) {
        match self.phase {
            Phase::Closed => {
                self.counters.dropped_down += samples.len() as u64;
                return;
            }
            Phase::Handshake => {
                self.counters.dropped_down += samples.len() as u64;
                if now >= self.next_hello {
                    self.push(Message::Hello(self.hello()), out);
                    self.hello_sent = Some(now);
                    self.next_hello = now + HELLO_EVERY;
                }
                return;
            }
            Phase::Up => {}
        }
        if self.rehello {
            self.rehello = false;
            self.push(Message::Hello(self.hello()), out);
            self.hello_sent = Some(now);
        }
        if !samples.is_empty() {
            for &u in samples {
                let (v, clipped) = message::actuation_to_i16(u as f64);
                self.counters.clipped += clipped as u64;
                self.counters.sent += 1;
                self.push(Message::Actuation(v), out);
                self.last_u = v;
            }
            self.last_sample_at = now;
            self.fade_left = 0;
        } else if self.config.actuation {
            self.stall_fade(now, out);
        }
        if now >= self.next_heartbeat {
            let uptime_ms = now.saturating_duration_since(self.started).as_millis() as u32;
            self.push(Message::Heartbeat { faults: 0, uptime_ms }, out);
            self.next_heartbeat = now + HEARTBEAT_EVERY;
        }
    }

    /// The HELLO this host sends.
    fn hello(&self) -> Hello {
        Hello {
            version: VERSION,
            role: Role::Host,
            caps: if self.config.actuation { caps::ACTUATION } else { 0 },
            actuation_hz: self.config.actuation_hz,
            touch_hz: self.config.touch_hz,
        }
    }

    /// No samples: after [`STALL_AFTER`], ramp the last sample to zero, one
    /// frame per millisecond over [`STALL_FADE_FRAMES`] frames.
    fn stall_fade(&mut self, now: Instant, out: &mut Vec<u8>) {
        if self.fade_left == 0 {
            if self.last_u == 0 || now.saturating_duration_since(self.last_sample_at) < STALL_AFTER {
                return;
            }
            self.fade_left = STALL_FADE_FRAMES;
            self.fade_from = self.last_u;
            self.next_fade = now;
            self.counters.stall_fades += 1;
        }
        if now < self.next_fade {
            return;
        }
        self.fade_left -= 1;
        let v = (self.fade_from as i32 * self.fade_left as i32 / STALL_FADE_FRAMES as i32) as i16;
        self.push(Message::Actuation(v), out);
        self.last_u = v;
        self.next_fade = now + Duration::from_millis(1);
    }

    /// The frames to send when the session ends: a zero actuation sample
    /// (if actuation was sent) so the device does not wait for its watchdog.
    pub fn goodbye(&mut self, out: &mut Vec<u8>) {
        if self.phase == Phase::Up && self.config.actuation {
            self.push(Message::Actuation(0), out);
            self.last_u = 0;
        }
    }
}

/// The frame type name, for reports.
pub fn kind_name(k: u8) -> &'static str {
    match k {
        kind::HELLO => "HELLO",
        kind::ACTUATION => "ACTUATION",
        kind::TOUCH => "TOUCH",
        kind::FORCE => "FORCE",
        kind::HEARTBEAT => "HEARTBEAT",
        kind::FAULT => "FAULT",
        _ => "unknown",
    }
}

#[cfg(test)]
#[path = "host_tests.rs"]
mod tests;
