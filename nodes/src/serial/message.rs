//! The typed messages carried in frames (`docs/serial-protocol.md`): the
//! hello/version handshake, actuation out, touch and force in, heartbeat
//! and fault reports. Every field is little endian; reals are IEEE-754
//! binary32.

use super::frame::{self, Frame, FrameError, MAX_FRAME, MAX_PAYLOAD};

/// The protocol version this code speaks (HELLO's first byte).
pub const VERSION: u8 = 1;

/// Frame type codes.
pub mod kind {
    /// Handshake, both directions.
    pub const HELLO: u8 = 0x01;
    /// One actuation sample, host → device.
    pub const ACTUATION: u8 = 0x10;
    /// Touch position and load, device → host.
    pub const TOUCH: u8 = 0x20;
    /// Lateral force, device → host.
    pub const FORCE: u8 = 0x21;
    /// Liveness and fault state, both directions.
    pub const HEARTBEAT: u8 = 0x30;
    /// A change of the device's fault state, device → host.
    pub const FAULT: u8 = 0x31;
}

/// Who sent a HELLO.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The computer running the graph.
    Host = 0,
    /// The microcontroller at the display.
    Device = 1,
}

/// Capability bits of a HELLO.
pub mod caps {
    /// The host sends actuation frames; the device plays them.
    pub const ACTUATION: u16 = 0x0001;
    /// The device sends touch frames.
    pub const TOUCH: u16 = 0x0002;
    /// The device sends force frames.
    pub const FORCE: u16 = 0x0004;
}

/// Fault bits of HEARTBEAT and FAULT frames (the device's current state).
pub mod faults {
    /// Amplifier output current above its limit.
    pub const OVERCURRENT: u16 = 0x0001;
    /// The amplifier reports a fault or lost its supply.
    pub const AMPLIFIER: u16 = 0x0002;
    /// No valid frame from the host for 100 ms: the device ramped its
    /// output to zero (its watchdog).
    pub const HOST_TIMEOUT: u16 = 0x0004;
    /// The touch sensor stopped answering.
    pub const TOUCH_SENSOR: u16 = 0x0008;
    /// Over temperature.
    pub const OVERTEMP: u16 = 0x0010;
    /// The emergency stop is pressed.
    pub const EMERGENCY_STOP: u16 = 0x0020;
    /// Any other fault.
    pub const OTHER: u16 = 0x8000;
    /// Names of the bits, for reports.
    pub const NAMES: [(u16, &str); 7] = [
        (OVERCURRENT, "overcurrent"),
        (AMPLIFIER, "amplifier"),
        (HOST_TIMEOUT, "host timeout"),
        (TOUCH_SENSOR, "touch sensor"),
        (OVERTEMP, "over temperature"),
        (EMERGENCY_STOP, "emergency stop"),
        (OTHER, "other"),
    ];
}

/// The handshake: each side says which protocol version it speaks, what it
/// does and at which rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hello {
    /// Protocol version ([`VERSION`]).
    pub version: u8,
    /// Who sends it.
    pub role: Role,
    /// [`caps`] bits.
    pub caps: u16,
    /// Actuation samples per second (host: what it sends; device: what it
    /// plays; also the force rate when the device sends force).
    pub actuation_hz: u16,
    /// Touch frames per second (host: what it expects; device: what it sends).
    pub touch_hz: u16,
}

/// Where the finger is and how hard it presses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Position along the display's x axis, m.
    pub x: f32,
    /// Position along the display's y axis, m.
    pub y: f32,
    /// Normal load, N.
    pub load: f32,
    /// Bit 0: the finger touches the display (x, y and load are valid).
    pub flags: u8,
}

impl Touch {
    /// True when bit 0 of `flags` is set.
    pub fn contact(&self) -> bool {
        self.flags & 1 != 0
    }
}

/// A message of the protocol.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Message {
    /// Handshake.
    Hello(Hello),
    /// One actuation sample: `i16`, +32767 = +1.0 (50 V at the amplifier
    /// output), −32767 = −1.0.
    Actuation(i16),
    /// Touch position and load.
    Touch(Touch),
    /// Lateral force, N.
    Force(f32),
    /// Liveness: the sender's fault bits and its uptime in ms (wraps).
    Heartbeat {
        /// [`faults`] bits now set.
        faults: u16,
        /// Milliseconds since the sender started.
        uptime_ms: u32,
    },
    /// The device's fault bits changed; this is the new set.
    Fault {
        /// [`faults`] bits now set.
        faults: u16,
    },
}

/// A frame whose type or payload this version does not understand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MessageError {
    /// An unknown frame type.
    #[error("unknown frame type {0:#04x}")]
    UnknownType(u8),
    /// A payload of the wrong length for its type.
    #[error("frame type {kind:#04x} carries {len} payload bytes, expected {expected}")]
    BadLength {
        /// The frame type.
        kind: u8,
        /// Its payload length.
        len: usize,
        /// The length the type requires.
        expected: usize,
    },
    /// A HELLO with an unknown role byte.
    #[error("HELLO with unknown role {0}")]
    BadRole(u8),
}

/// Payload length of each known type.
pub fn payload_len(kind: u8) -> Option<usize> {
    Some(match kind {
        kind::HELLO => 8,
        kind::ACTUATION => 2,
        kind::TOUCH => 13,
        kind::FORCE => 4,
        kind::HEARTBEAT => 6,
        kind::FAULT => 2,
        _ => return None,
    })
}

fn f32_at(p: &[u8], i: usize) -> f32 {
    f32::from_le_bytes([p[i], p[i + 1], p[i + 2], p[i + 3]])
}
fn u16_at(p: &[u8], i: usize) -> u16 {
    u16::from_le_bytes([p[i], p[i + 1]])
}

impl Message {
    /// The frame type of this message.
    pub fn kind(&self) -> u8 {
        match self {
            Message::Hello(_) => kind::HELLO,
            Message::Actuation(_) => kind::ACTUATION,
            Message::Touch(_) => kind::TOUCH,
            Message::Force(_) => kind::FORCE,
            Message::Heartbeat { .. } => kind::HEARTBEAT,
            Message::Fault { .. } => kind::FAULT,
        }
    }

    /// Writes the payload into `out`; returns its length.
    pub fn write_payload(&self, out: &mut [u8; MAX_PAYLOAD]) -> usize {
        let n = match *self {
            Message::Hello(h) => {
                out[0] = h.version;
                out[1] = h.role as u8;
                out[2..4].copy_from_slice(&h.caps.to_le_bytes());
                out[4..6].copy_from_slice(&h.actuation_hz.to_le_bytes());
                out[6..8].copy_from_slice(&h.touch_hz.to_le_bytes());
                8
            }
            Message::Actuation(v) => {
                out[..2].copy_from_slice(&v.to_le_bytes());
                2
            }
            Message::Touch(t) => {
                out[0..4].copy_from_slice(&t.x.to_le_bytes());
                out[4..8].copy_from_slice(&t.y.to_le_bytes());
                out[8..12].copy_from_slice(&t.load.to_le_bytes());
                out[12] = t.flags;
                13
            }
            Message::Force(f) => {
                out[..4].copy_from_slice(&f.to_le_bytes());
                4
            }
            Message::Heartbeat { faults, uptime_ms } => {
                out[..2].copy_from_slice(&faults.to_le_bytes());
                out[2..6].copy_from_slice(&uptime_ms.to_le_bytes());
                6
            }
            Message::Fault { faults } => {
                out[..2].copy_from_slice(&faults.to_le_bytes());
                2
            }
        };
        debug_assert_eq!(Some(n), payload_len(self.kind()));
        n
    }

    /// Writes the whole frame (with sequence number `seq`) into `out`;
    /// returns the bytes written.
    pub fn encode(&self, seq: u16, out: &mut [u8]) -> Result<usize, FrameError> {
        let mut p = [0u8; MAX_PAYLOAD];
        let n = self.write_payload(&mut p);
        frame::encode(self.kind(), seq, &p[..n], out)
    }

    /// The frame bytes as an array (for examples and tests).
    pub fn to_bytes(&self, seq: u16) -> ([u8; MAX_FRAME], usize) {
        let mut out = [0u8; MAX_FRAME];
        let n = self.encode(seq, &mut out).expect("every message fits a frame");
        (out, n)
    }

    /// The message a frame carries.
    pub fn from_frame(f: &Frame) -> Result<Self, MessageError> {
        let p = f.payload();
        let expected = payload_len(f.kind).ok_or(MessageError::UnknownType(f.kind))?;
        if p.len() != expected {
            return Err(MessageError::BadLength { kind: f.kind, len: p.len(), expected });
        }
        Ok(match f.kind {
            kind::HELLO => Message::Hello(Hello {
                version: p[0],
                role: match p[1] {
                    0 => Role::Host,
                    1 => Role::Device,
                    r => return Err(MessageError::BadRole(r)),
                },
                caps: u16_at(p, 2),
                actuation_hz: u16_at(p, 4),
                touch_hz: u16_at(p, 6),
            }),
            kind::ACTUATION => Message::Actuation(i16::from_le_bytes([p[0], p[1]])),
            kind::TOUCH => Message::Touch(Touch { x: f32_at(p, 0), y: f32_at(p, 4), load: f32_at(p, 8), flags: p[12] }),
            kind::FORCE => Message::Force(f32_at(p, 0)),
            kind::HEARTBEAT => {
                Message::Heartbeat { faults: u16_at(p, 0), uptime_ms: u32::from_le_bytes([p[2], p[3], p[4], p[5]]) }
            }
            _ => Message::Fault { faults: u16_at(p, 0) },
        })
    }
}

/// Full scale of an actuation sample: +32767 is +1.0.
pub const ACTUATION_FULL_SCALE: f64 = 32767.0;

/// An actuation value (1.0 = 50 V at the amplifier output) as the frame's
/// `i16`, rounded to nearest; values beyond ±1 are clipped to ±32767 and
/// NaN is sent as 0. Returns the sample and whether it was clipped (or NaN).
pub fn actuation_to_i16(u: f64) -> (i16, bool) {
    if u.is_nan() {
        return (0, true);
    }
    let v = (u * ACTUATION_FULL_SCALE).round();
    let c = v.clamp(-ACTUATION_FULL_SCALE, ACTUATION_FULL_SCALE);
    (c as i16, c != v)
}

/// An actuation sample back to its value (−32768, never sent, reads −1.0).
pub fn actuation_from_i16(v: i16) -> f64 {
    (v as f64 / ACTUATION_FULL_SCALE).max(-1.0)
}

/// Names of the fault bits set in `bits`, joined with commas.
pub fn fault_names(bits: u16) -> String {
    let mut v: Vec<String> =
        faults::NAMES.iter().filter(|(b, _)| bits & b != 0).map(|(_, n)| (*n).to_string()).collect();
    let known: u16 = faults::NAMES.iter().map(|(b, _)| b).fold(0, |a, b| a | b);
    if bits & !known != 0 {
        v.push(format!("bits {:#06x}", bits & !known));
    }
    v.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all() -> Vec<Message> {
        vec![
            Message::Hello(Hello {
                version: VERSION,
                role: Role::Device,
                caps: caps::TOUCH | caps::FORCE,
                actuation_hz: 1000,
                touch_hz: 40,
            }),
            Message::Actuation(-12345),
            Message::Touch(Touch { x: 0.0375, y: -0.01, load: 0.8, flags: 1 }),
            Message::Force(-0.125),
            Message::Heartbeat { faults: faults::AMPLIFIER, uptime_ms: 0xDEAD_BEEF },
            Message::Fault { faults: faults::OVERCURRENT | faults::OTHER },
        ]
    }

    #[test]
    fn every_message_round_trips() {
        for m in all() {
            let (b, n) = m.to_bytes(513);
            let f = frame::decode(&b[..n]).unwrap();
            assert_eq!(f.seq, 513);
            assert_eq!(Message::from_frame(&f).unwrap(), m);
            assert_eq!(f.payload().len(), payload_len(m.kind()).unwrap());
        }
    }

    #[test]
    fn unknown_types_wrong_lengths_and_roles_are_refused() {
        let f = Frame::new(0x7F, 0, &[1, 2]).unwrap();
        assert_eq!(Message::from_frame(&f), Err(MessageError::UnknownType(0x7F)));
        let f = Frame::new(kind::FORCE, 0, &[1, 2, 3]).unwrap();
        assert_eq!(Message::from_frame(&f), Err(MessageError::BadLength { kind: kind::FORCE, len: 3, expected: 4 }));
        let f = Frame::new(kind::HELLO, 0, &[1, 9, 0, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(Message::from_frame(&f), Err(MessageError::BadRole(9)));
    }

    #[test]
    fn actuation_scaling_rounds_clips_and_inverts() {
        assert_eq!(actuation_to_i16(1.0), (32767, false));
        assert_eq!(actuation_to_i16(-1.0), (-32767, false));
        assert_eq!(actuation_to_i16(0.5), (16384, false)); // 16383.5 rounds away from zero
        assert_eq!(actuation_to_i16(1.5), (32767, true));
        assert_eq!(actuation_to_i16(-1e300), (-32767, true));
        assert_eq!(actuation_to_i16(f64::NAN), (0, true));
        assert_eq!(actuation_to_i16(f64::INFINITY), (32767, true));
        assert_eq!(actuation_from_i16(-32768), -1.0);
        for k in (-32767..=32767).step_by(97) {
            let v = k as i16;
            assert_eq!(actuation_to_i16(actuation_from_i16(v)).0, v);
        }
        // Quantization error is at most half a step.
        for i in 0..=2000 {
            let u = -1.0 + i as f64 / 1000.0;
            let back = actuation_from_i16(actuation_to_i16(u).0);
            assert!((back - u).abs() <= 0.5 / ACTUATION_FULL_SCALE + 1e-15);
        }
    }

    #[test]
    fn fault_names_list_every_bit() {
        assert_eq!(fault_names(0), "");
        assert_eq!(fault_names(faults::OVERCURRENT | faults::HOST_TIMEOUT), "overcurrent, host timeout");
        assert_eq!(fault_names(0x0100), "bits 0x0100");
    }
}
