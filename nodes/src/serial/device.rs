//! The device's side of the protocol as a state machine (no port, no clock
//! of its own), following the checklist of `docs/serial-protocol.md`: answer
//! HELLO, play actuation from a small FIFO at the device's own clock, the
//! 100 ms watchdog, fault reports, heartbeats, numbered frames. The device
//! emulator (`evflow devsim`) and the nodes' tests drive it; it is also a
//! reference for firmware.

use super::frame::MAX_FRAME;
use super::message::{self, caps, faults, Hello, Message, Role, VERSION};
use super::stream::{StreamDecoder, StreamStats};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// No valid host frame for this long: the watchdog ramps the output to zero.
pub const WATCHDOG: Duration = Duration::from_millis(100);
/// Steps (calls of [`DeviceSession::play`]) of the watchdog's ramp to zero.
pub const WATCHDOG_RAMP: u32 = 10;
/// A device not engaged that hears host frames says HELLO at most this often.
pub const PROMPT_EVERY: Duration = Duration::from_millis(250);
/// The FIFO holds at most this many samples; older ones are dropped.
pub const FIFO_MAX: usize = 8;

/// Fixed settings of a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceConfig {
    /// Protocol version it speaks (1; tests use others).
    pub version: u8,
    /// [`caps`] bits it announces.
    pub caps: u16,
    /// Actuation (and force) rate, Hz.
    pub actuation_hz: u16,
    /// Touch rate, Hz.
    pub touch_hz: u16,
}

impl Default for DeviceConfig {
    fn default() -> Self {
        Self { version: VERSION, caps: caps::TOUCH | caps::FORCE, actuation_hz: 1000, touch_hz: 40 }
    }
}

/// Counters of a device.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DeviceCounters {
    /// Receiver counters.
    pub stream: StreamStats,
    /// Host HELLOs answered.
    pub hellos: u64,
    /// Actuation frames received.
    pub actuation: u64,
    /// Host frames missing by sequence number.
    pub lost: u64,
    /// Samples dropped because the FIFO was full.
    pub fifo_overflows: u64,
    /// Plays with an empty FIFO (the last sample held).
    pub fifo_underruns: u64,
    /// Times the watchdog fired.
    pub watchdog: u64,
}

/// The device's protocol state.
pub struct DeviceSession {
    config: DeviceConfig,
    decoder: StreamDecoder,
    seq_out: u16,
    seq_in: Option<u16>,
    engaged: bool,
    last_rx: Instant,
    started: Instant,
    faults: u16,
    fifo: VecDeque<i16>,
    /// The sample being played.
    u: i16,
    ramp_left: u32,
    ramp_from: i16,
    /// When it last said HELLO to a host it was not engaged with.
    prompted: Option<Instant>,
    counters: DeviceCounters,
    scratch: Vec<super::frame::Frame>,
}

impl DeviceSession {
    /// A device that has just powered up (output zero, not engaged).
    pub fn new(config: DeviceConfig, now: Instant) -> Self {
        Self {
            config,
            decoder: StreamDecoder::new(),
            seq_out: 0,
            seq_in: None,
            engaged: false,
            last_rx: now,
            started: now,
            faults: 0,
            fifo: VecDeque::with_capacity(FIFO_MAX + 1),
            u: 0,
            ramp_left: 0,
            ramp_from: 0,
            prompted: None,
            counters: DeviceCounters::default(),
            scratch: Vec::with_capacity(256),
        }
    }

    /// True after a host HELLO of the same version: the device streams and plays.
    pub fn engaged(&self) -> bool {
        self.engaged
    }

    /// The fault bits set.
    pub fn faults(&self) -> u16 {
        self.faults
    }

    /// Counters so far.
    pub fn counters(&self) -> DeviceCounters {
        let mut c = self.counters;
        c.stream = self.decoder.stats();
        c
    }

    /// Appends `m` as the next numbered frame to `out`.
    pub fn send(&mut self, m: Message, out: &mut Vec<u8>) {
        let mut b = [0u8; MAX_FRAME];
        if let Ok(n) = m.encode(self.seq_out, &mut b) {
            out.extend_from_slice(&b[..n]);
            self.seq_out = self.seq_out.wrapping_add(1);
        }
    }

    /// The HELLO this device sends.
    pub fn hello(&self) -> Message {
        Message::Hello(Hello {
            version: self.config.version,
            role: Role::Device,
            caps: self.config.caps,
            actuation_hz: self.config.actuation_hz,
            touch_hz: self.config.touch_hz,
        })
    }

    /// Bytes from the host: HELLO is answered (into `out`), actuation
    /// samples go to the FIFO, and each received sample is also passed to
    /// `on_actuation` (for logs).
    pub fn receive(&mut self, now: Instant, bytes: &[u8], out: &mut Vec<u8>, on_actuation: &mut impl FnMut(i16)) {
        let mut frames = std::mem::take(&mut self.scratch);
        frames.clear();
        self.decoder.feed(bytes, |f| frames.push(f));
        for f in &frames {
            let Ok(m) = Message::from_frame(f) else { continue };
            if let Some(e) = self.seq_in {
                let d = f.seq.wrapping_sub(e);
                if d < 0x8000 {
                    self.counters.lost += d as u64;
                }
            }
            self.seq_in = Some(f.seq.wrapping_add(1));
            match m {
                Message::Hello(h) if h.role == Role::Host => {
                    self.counters.hellos += 1;
                    self.seq_in = Some(f.seq.wrapping_add(1));
                    let hello = self.hello();
                    self.send(hello, out);
                    if h.version == self.config.version {
                        self.engaged = true;
                        self.last_rx = now;
                        if self.faults & faults::HOST_TIMEOUT != 0 {
                            self.set_faults(self.faults & !faults::HOST_TIMEOUT, out);
                        }
                    } else {
                        self.engaged = false;
                    }
                }
                // A host streaming to a device it never said HELLO to (its
                // HELLO lost, or it took our power-up HELLO for an answer):
                // a HELLO, at most every 250 ms, asks it for its own.
                _ if !self.engaged => {
                    if self.prompted.is_none_or(|t| now.saturating_duration_since(t) >= PROMPT_EVERY) {
                        self.prompted = Some(now);
                        let hello = self.hello();
                        self.send(hello, out);
                    }
                }
                Message::Actuation(v) => {
                    self.last_rx = now;
                    self.counters.actuation += 1;
                    on_actuation(v);
                    if self.faults & faults::HOST_TIMEOUT == 0 {
                        if self.fifo.len() >= FIFO_MAX {
                            self.fifo.pop_front();
                            self.counters.fifo_overflows += 1;
                        }
                        self.fifo.push_back(v);
                    }
                }
                _ => self.last_rx = now,
            }
        }
        self.scratch = frames;
    }

    /// The host went away (the port closed): disengage, ramp to zero.
    pub fn host_gone(&mut self) {
        self.engaged = false;
        self.fifo.clear();
        self.decoder.end_of_stream(|_| {});
        self.seq_in = None;
        self.start_ramp();
    }

    fn start_ramp(&mut self) {
        if self.ramp_left == 0 && self.u != 0 {
            self.ramp_left = WATCHDOG_RAMP;
            self.ramp_from = self.u;
        }
    }

    /// Sets the fault bits, sending a FAULT frame when they change.
    pub fn set_faults(&mut self, bits: u16, out: &mut Vec<u8>) {
        if bits != self.faults {
            self.faults = bits;
            if self.engaged || bits & faults::HOST_TIMEOUT != 0 {
                self.send(Message::Fault { faults: bits }, out);
            }
        }
    }

    /// One tick of the device's actuation clock: the sample to apply, as
    /// a value (1.0 = 50 V). Pops the FIFO (holding the last sample when it
    /// is empty); the watchdog ramps to zero when the host went quiet.
    pub fn play(&mut self, now: Instant, out: &mut Vec<u8>) -> f64 {
        let quiet = now.saturating_duration_since(self.last_rx) > WATCHDOG;
        if self.engaged && quiet && self.faults & faults::HOST_TIMEOUT == 0 {
            self.counters.watchdog += 1;
            self.set_faults(self.faults | faults::HOST_TIMEOUT, out);
            self.fifo.clear();
            self.start_ramp();
        }
        if self.ramp_left > 0 {
            self.ramp_left -= 1;
            self.u = (self.ramp_from as i32 * self.ramp_left as i32 / WATCHDOG_RAMP as i32) as i16;
        } else if !self.engaged || self.faults & faults::HOST_TIMEOUT != 0 {
            // Idle: nothing plays.
        } else if let Some(v) = self.fifo.pop_front() {
            self.u = v;
        } else {
            self.counters.fifo_underruns += 1;
        }
        message::actuation_from_i16(self.u)
    }

    /// A heartbeat frame (while engaged).
    pub fn heartbeat(&mut self, now: Instant, out: &mut Vec<u8>) {
        if self.engaged {
            let uptime_ms = now.saturating_duration_since(self.started).as_millis() as u32;
            self.send(Message::Heartbeat { faults: self.faults, uptime_ms }, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::serial::host::{HostConfig, HostSession, Inbound};

    const MS: Duration = Duration::from_millis(1);

    /// Host and device wired back to back, stepped one millisecond at a time.
    #[test]
    fn host_and_device_agree_end_to_end() {
        let t0 = Instant::now();
        let hc = HostConfig { timeout: Duration::from_millis(250), actuation_hz: 1000, touch_hz: 40, actuation: true };
        let mut host = HostSession::new(hc, t0);
        let mut dev = DeviceSession::new(DeviceConfig::default(), t0);
        host.opened(t0);
        let (mut h2d, mut d2h) = (Vec::new(), Vec::new());
        let mut received = Vec::new();
        let mut played = Vec::new();
        let mut forces = Vec::new();
        let sent: Vec<f32> = (0..200).map(|k| 0.9 * (k as f32 * 0.05).sin()).collect();
        for (k, u) in sent.iter().enumerate() {
            let now = t0 + k as u32 * MS;
            host.transmit(now, if host.connected() { std::slice::from_ref(u) } else { &[] }, &mut h2d);
            dev.receive(now, &h2d, &mut d2h, &mut |v| received.push(v));
            h2d.clear();
            played.push(dev.play(now, &mut d2h));
            if dev.engaged() {
                dev.send(Message::Force(k as f32), &mut d2h);
            }
            host.receive(
                now,
                &d2h,
                &mut |x| {
                    if let Inbound::Force(f) = x {
                        forces.push(f)
                    }
                },
                &mut |_| {},
            );
            d2h.clear();
        }
        assert!(host.connected() && dev.engaged());
        // Every sample sent after the handshake arrived, in order.
        let n = received.len();
        assert!(n >= 198, "{n}");
        let want: Vec<i16> = sent[200 - n..].iter().map(|u| message::actuation_to_i16(*u as f64).0).collect();
        assert_eq!(received, want);
        // The device plays each sample on the tick it arrives.
        assert_eq!(played.last().copied(), Some(message::actuation_from_i16(*want.last().unwrap())));
        assert_eq!(forces, (0..200).map(|k| k as f32).collect::<Vec<_>>(), "every force frame arrived");
        assert_eq!(dev.counters().lost, 0);
        assert_eq!(host.counters().lost, 0);
    }

    #[test]
    fn watchdog_ramps_to_zero_and_reports_until_the_next_hello() {
        let t0 = Instant::now();
        let mut dev = DeviceSession::new(DeviceConfig::default(), t0);
        let mut out = Vec::new();
        let hello = Message::Hello(Hello { version: 1, role: Role::Host, caps: 1, actuation_hz: 1000, touch_hz: 40 });
        let (b, n) = hello.to_bytes(0);
        dev.receive(t0, &b[..n], &mut out, &mut |_| {});
        assert!(dev.engaged());
        let (b, n) = Message::Actuation(20000).to_bytes(1);
        dev.receive(t0, &b[..n], &mut out, &mut |_| {});
        assert_eq!(dev.play(t0, &mut out), message::actuation_from_i16(20000));
        assert_eq!(dev.play(t0 + 100 * MS, &mut out), message::actuation_from_i16(20000), "held, not yet fired");
        out.clear();
        let ramp: Vec<f64> = (0..12).map(|k| dev.play(t0 + (101 + k) * MS, &mut out)).collect();
        assert_eq!(ramp[9], 0.0, "zero after 10 steps");
        assert!(ramp.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(dev.faults(), faults::HOST_TIMEOUT);
        let mut d = StreamDecoder::new();
        let mut msgs = Vec::new();
        d.feed(&out, |f| msgs.push(Message::from_frame(&f).unwrap()));
        assert_eq!(msgs, [Message::Fault { faults: faults::HOST_TIMEOUT }]);
        // Samples are ignored while the fault is set; the next HELLO clears it.
        let (b, n) = Message::Actuation(5000).to_bytes(2);
        dev.receive(t0 + 120 * MS, &b[..n], &mut out, &mut |_| {});
        assert_eq!(dev.play(t0 + 121 * MS, &mut out), 0.0);
        let (b, n) = hello.to_bytes(3);
        dev.receive(t0 + 130 * MS, &b[..n], &mut out, &mut |_| {});
        assert_eq!(dev.faults(), 0);
        assert_eq!(dev.counters().watchdog, 1);
    }

    #[test]
    fn another_version_is_answered_but_not_engaged() {
        let t0 = Instant::now();
        let mut dev = DeviceSession::new(DeviceConfig::default(), t0);
        let mut out = Vec::new();
        let hello = Message::Hello(Hello { version: 2, role: Role::Host, caps: 1, actuation_hz: 1000, touch_hz: 40 });
        let (b, n) = hello.to_bytes(0);
        dev.receive(t0, &b[..n], &mut out, &mut |_| {});
        assert!(!dev.engaged());
        assert!(!out.is_empty(), "the device still says which version it speaks");
    }
}
