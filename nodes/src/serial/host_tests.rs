//! The host's protocol state machine against a scripted device.

use super::*;
use crate::serial::frame;
use crate::serial::message::faults;

const MS: Duration = Duration::from_millis(1);

fn config() -> HostConfig {
    HostConfig { timeout: Duration::from_millis(250), actuation_hz: 1000, touch_hz: 40, actuation: true }
}

/// Decodes every frame in `bytes` (which must be clean).
fn frames(bytes: &[u8]) -> Vec<(u16, Message)> {
    let mut d = StreamDecoder::new();
    let mut v = Vec::new();
    d.feed(bytes, |f| v.push((f.seq, Message::from_frame(&f).unwrap())));
    assert_eq!(d.stats().garbage_bytes, 0);
    v
}

fn device_hello(version: u8) -> Message {
    Message::Hello(Hello {
        version,
        role: Role::Device,
        caps: caps::TOUCH | caps::FORCE,
        actuation_hz: 1000,
        touch_hz: 40,
    })
}

fn bytes(m: Message, seq: u16) -> Vec<u8> {
    let (b, n) = m.to_bytes(seq);
    b[..n].to_vec()
}

struct Sink {
    inbound: Vec<Inbound>,
    notices: Vec<Notice>,
}

impl Sink {
    fn new() -> Self {
        Self { inbound: Vec::new(), notices: Vec::new() }
    }
    fn receive(&mut self, h: &mut HostSession, now: Instant, b: &[u8]) {
        h.receive(now, b, &mut |x| self.inbound.push(x), &mut |n| self.notices.push(n));
    }
}

/// A session whose device has answered at `t0`.
fn up(t0: Instant, sink: &mut Sink) -> HostSession {
    let mut h = HostSession::new(config(), t0);
    h.opened(t0);
    let mut out = Vec::new();
    h.transmit(t0, &[], &mut out);
    sink.receive(&mut h, t0, &bytes(device_hello(VERSION), 100));
    assert!(h.connected());
    h
}

#[test]
fn handshake_hello_repeats_until_the_device_answers() {
    let t0 = Instant::now();
    let mut h = HostSession::new(config(), t0);
    let mut out = Vec::new();
    h.transmit(t0, &[0.5], &mut out);
    assert!(out.is_empty(), "nothing is sent while the port is closed");
    h.opened(t0);
    h.transmit(t0, &[0.5], &mut out);
    let f = frames(&out);
    assert_eq!(f.len(), 1, "only HELLO before the answer");
    let Message::Hello(hello) = f[0].1 else { panic!("{f:?}") };
    assert_eq!(
        hello,
        Hello { version: VERSION, role: Role::Host, caps: caps::ACTUATION, actuation_hz: 1000, touch_hz: 40 }
    );
    out.clear();
    h.transmit(t0 + 249 * MS, &[], &mut out);
    assert!(out.is_empty(), "not repeated before 250 ms");
    h.transmit(t0 + 250 * MS, &[], &mut out);
    assert_eq!(frames(&out).len(), 1, "repeated after 250 ms");
    assert_eq!(h.counters().dropped_down, 2, "samples while the link is down are dropped and counted");

    let mut s = Sink::new();
    s.receive(&mut h, t0 + 260 * MS, &bytes(device_hello(VERSION), 7));
    assert!(h.connected());
    assert!(matches!(s.notices[..], [Notice::Up(Hello { version: 1, .. })]));
}

#[test]
fn another_protocol_version_keeps_the_link_down() {
    let t0 = Instant::now();
    let mut h = HostSession::new(config(), t0);
    h.opened(t0);
    let mut s = Sink::new();
    s.receive(&mut h, t0, &bytes(device_hello(2), 0));
    assert!(!h.connected());
    assert_eq!(s.notices, [Notice::VersionMismatch(2)]);
    s.receive(&mut h, t0, &bytes(Message::Force(1.0), 1));
    assert!(s.inbound.is_empty(), "nothing is delivered from a device of another version");
}

#[test]
fn actuation_frames_carry_each_sample_in_order_with_heartbeats() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    let mut out = Vec::new();
    let samples: Vec<f32> = (0..300).map(|k| (k as f32 * 0.1).sin() * 1.2).collect();
    for (k, x) in samples.iter().enumerate() {
        h.transmit(t0 + k as u32 * MS, std::slice::from_ref(x), &mut out);
    }
    let f = frames(&out);
    let acts: Vec<i16> =
        f.iter().filter_map(|(_, m)| if let Message::Actuation(v) = m { Some(*v) } else { None }).collect();
    let want: Vec<i16> = samples.iter().map(|x| message::actuation_to_i16(*x as f64).0).collect();
    assert_eq!(acts, want);
    let beats = f.iter().filter(|(_, m)| matches!(m, Message::Heartbeat { .. })).count();
    assert_eq!(beats, 2, "heartbeats at 100 and 200 ms");
    // Sequence numbers: consecutive over every frame sent (HELLO was 0).
    for (i, (seq, _)) in f.iter().enumerate() {
        assert_eq!(*seq, i as u16 + 1);
    }
    let c = h.counters();
    assert_eq!(c.sent, 300);
    assert_eq!(c.clipped, samples.iter().filter(|x| (x.abs() as f64 * 32767.0).round() > 32767.0).count() as u64);
}

#[test]
fn touch_force_faults_and_lost_frames() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    let t = Touch { x: 0.01, y: 0.02, load: 0.7, flags: 1 };
    let mut b = bytes(Message::Touch(t), 101);
    b.extend(bytes(Message::Force(0.3), 102));
    b.extend(bytes(Message::Force(0.4), 105)); // 103, 104 lost
    b.extend(bytes(Message::Heartbeat { faults: faults::AMPLIFIER, uptime_ms: 5 }, 106));
    b.extend(bytes(Message::Fault { faults: 0 }, 107));
    b.extend(
        frame::Frame::new(0x7E, 108, &[1, 2])
            .map(|f| {
                let mut o = [0u8; 16];
                let n = f.encode(&mut o).unwrap();
                o[..n].to_vec()
            })
            .unwrap(),
    );
    s.receive(&mut h, t0, &b);
    assert_eq!(s.inbound, [Inbound::Touch(t), Inbound::Force(0.3), Inbound::Force(0.4)]);
    assert_eq!(s.notices[1..], [Notice::Faults(faults::AMPLIFIER), Notice::Faults(0)]);
    let c = h.counters();
    assert_eq!((c.lost, c.unknown_type, c.touch, c.force, c.heartbeats), (2, 1, 1, 2, 1));
}

#[test]
fn a_silent_device_takes_the_link_down_and_hello_starts_again() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    s.receive(&mut h, t0 + 100 * MS, &bytes(Message::Force(0.1), 101));
    h.tick(t0 + 350 * MS, &mut |n| s.notices.push(n));
    assert!(h.connected(), "250 ms after the last frame is not yet too long");
    h.tick(t0 + 351 * MS, &mut |n| s.notices.push(n));
    assert!(!h.connected());
    assert_eq!(s.notices.last(), Some(&Notice::Silent(Duration::from_millis(250))));
    let mut out = Vec::new();
    h.transmit(t0 + 351 * MS, &[0.2], &mut out);
    assert!(matches!(frames(&out)[..], [(_, Message::Hello(_))]));
}

#[test]
fn the_stall_fade_ramps_the_last_sample_to_exactly_zero() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    let mut out = Vec::new();
    h.transmit(t0, &[0.8], &mut out);
    out.clear();
    for k in 1..5 {
        h.transmit(t0 + k * MS, &[], &mut out);
    }
    assert!(out.is_empty(), "no fade within 5 ms");
    for k in 5..40 {
        h.transmit(t0 + k * MS, &[], &mut out);
    }
    let acts: Vec<i16> =
        frames(&out).iter().filter_map(|(_, m)| if let Message::Actuation(v) = m { Some(*v) } else { None }).collect();
    let top = message::actuation_to_i16(0.8).0 as i32;
    let want: Vec<i16> = (0..10).rev().map(|k| (top * k / 10) as i16).collect();
    assert_eq!(acts, want, "ten frames, one per ms, ending at exactly 0");
    assert_eq!(h.counters().stall_fades, 1);
    // New samples end a fade at once.
    out.clear();
    h.transmit(t0 + 50 * MS, &[0.1], &mut out);
    assert!(frames(&out).iter().any(|(_, m)| *m == Message::Actuation(message::actuation_to_i16(0.1).0)));
}

#[test]
fn closing_counts_a_frame_cut_off_and_counters_survive_reconnection() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    let b = bytes(Message::Force(0.3), 101);
    s.receive(&mut h, t0, &b[..7]);
    h.closed();
    assert!(!h.connected());
    assert_eq!(h.counters().stream.truncated, 1);
    h.opened(t0 + 500 * MS);
    s.receive(&mut h, t0 + 500 * MS, &bytes(device_hello(VERSION), 0));
    s.receive(&mut h, t0 + 500 * MS, &bytes(Message::Force(0.5), 1));
    assert!(h.connected());
    let c = h.counters();
    assert_eq!((c.stream.truncated, c.stream.frames, c.force), (1, 3, 1));
    assert_eq!(s.inbound, [Inbound::Force(0.5)]);
}

#[test]
fn goodbye_sends_a_zero_sample() {
    let t0 = Instant::now();
    let mut s = Sink::new();
    let mut h = up(t0, &mut s);
    let mut out = Vec::new();
    h.goodbye(&mut out);
    assert!(matches!(frames(&out)[..], [(_, Message::Actuation(0))]));
}

/// A device HELLO the host did not ask for — the device reset mid-session
/// (its power-up HELLO), or it never got the host's HELLO and says so — is
/// answered with a HELLO once, so the device engages again; the answer to
/// that HELLO is not answered again.
#[test]
fn an_unasked_device_hello_is_answered_once() {
    let t0 = Instant::now();
    let mut sink = Sink::new();
    let mut h = up(t0, &mut sink);
    let mut out = Vec::new();
    // Long after the handshake: the device resets.
    let t1 = t0 + 2000 * MS;
    sink.receive(&mut h, t1, &bytes(device_hello(VERSION), 0));
    h.transmit(t1, &[0.5], &mut out);
    let sent = frames(&out);
    assert!(matches!(sent[0].1, Message::Hello(x) if x.role == Role::Host), "{sent:?}");
    assert!(matches!(sent[1].1, Message::Actuation(_)), "{sent:?}");
    // The device's answer comes back at once: no HELLO again.
    out.clear();
    sink.receive(&mut h, t1 + MS, &bytes(device_hello(VERSION), 1));
    h.transmit(t1 + MS, &[0.5], &mut out);
    assert!(frames(&out).iter().all(|(_, m)| !matches!(m, Message::Hello(_))), "{:?}", frames(&out));
    assert!(h.connected());
}

/// Host and device back to back, the host's first HELLO lost on the way
/// and the device's power-up HELLO taken for its answer: the device says
/// HELLO when it hears frames, the host answers, and the samples flow.
#[test]
fn a_lost_host_hello_is_recovered() {
    use crate::serial::device::{DeviceConfig, DeviceSession};
    let t0 = Instant::now();
    let mut dev = DeviceSession::new(DeviceConfig::default(), t0);
    let mut d2h = Vec::new();
    let power_up = dev.hello();
    dev.send(power_up, &mut d2h);
    let mut h = HostSession::new(config(), t0);
    h.opened(t0);
    let mut h2d = Vec::new();
    h.transmit(t0, &[], &mut h2d);
    h2d.clear(); // lost
    let mut sink = Sink::new();
    sink.receive(&mut h, t0, &d2h);
    d2h.clear();
    assert!(h.connected(), "the power-up HELLO taken for an answer");
    let mut received = Vec::new();
    for k in 1..600u32 {
        let now = t0 + k * MS;
        h.transmit(now, &[0.25], &mut h2d);
        dev.receive(now, &h2d, &mut d2h, &mut |v| received.push(v));
        h2d.clear();
        sink.receive(&mut h, now, &d2h);
        d2h.clear();
    }
    assert!(dev.engaged(), "the device engaged after all");
    assert!(received.len() > 250, "{} samples reached it", received.len());
}
