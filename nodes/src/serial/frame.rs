//! One frame of the serial protocol: sync bytes, length, type, sequence
//! number, payload and CRC (`docs/serial-protocol.md`).
//!
//! ```text
//! offset  size  field
//! 0       2     sync: 0xA5 0x5A
//! 2       1     len: payload length N, 0..=64
//! 3       1     type
//! 4       2     seq: sequence number, u16 little endian
//! 6       N     payload (little endian fields)
//! 6+N     2     CRC-16/CCITT-FALSE of bytes 2 .. 6+N, u16 little endian
//! ```

use super::crc;

/// The two bytes every frame starts with.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
/// Bytes before the payload: sync (2), len (1), type (1), seq (2).
pub const HEADER: usize = 6;
/// Bytes a frame adds to its payload: header and CRC.
pub const OVERHEAD: usize = HEADER + 2;
/// The longest payload a frame may carry.
pub const MAX_PAYLOAD: usize = 64;
/// The longest frame.
pub const MAX_FRAME: usize = OVERHEAD + MAX_PAYLOAD;

/// What is wrong with a frame or a request to encode one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// A payload longer than [`MAX_PAYLOAD`].
    #[error("payload of {0} bytes is longer than the {MAX_PAYLOAD} a frame carries")]
    PayloadTooLong(usize),
    /// The output buffer cannot hold the frame.
    #[error("the buffer holds {have} bytes but the frame needs {need}")]
    BufferTooSmall {
        /// Bytes the frame needs.
        need: usize,
        /// Bytes the buffer has.
        have: usize,
    },
    /// The bytes do not start with [`SYNC`].
    #[error("the frame does not start with the sync bytes A5 5A")]
    BadSync,
    /// The declared length exceeds [`MAX_PAYLOAD`].
    #[error("declared payload length {0} exceeds {MAX_PAYLOAD}")]
    BadLength(u8),
    /// Fewer bytes than the header declares.
    #[error("frame truncated: {have} of {need} bytes")]
    Truncated {
        /// Bytes the frame needs.
        need: usize,
        /// Bytes there are.
        have: usize,
    },
    /// More bytes than the header declares.
    #[error("{0} bytes after the end of the frame")]
    Trailing(usize),
    /// The CRC does not match.
    #[error("CRC mismatch: frame says {stored:#06x}, bytes give {computed:#06x}")]
    BadCrc {
        /// The CRC carried by the frame.
        stored: u16,
        /// The CRC of its bytes.
        computed: u16,
    },
}

/// A decoded frame (fixed size, `Copy`: no allocation to pass it around).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// Frame type.
    pub kind: u8,
    /// Sequence number.
    pub seq: u16,
    len: u8,
    payload: [u8; MAX_PAYLOAD],
}

impl Frame {
    /// A frame carrying `payload`.
    pub fn new(kind: u8, seq: u16, payload: &[u8]) -> Result<Self, FrameError> {
        if payload.len() > MAX_PAYLOAD {
            return Err(FrameError::PayloadTooLong(payload.len()));
        }
        let mut p = [0u8; MAX_PAYLOAD];
        p[..payload.len()].copy_from_slice(payload);
        Ok(Self { kind, seq, len: payload.len() as u8, payload: p })
    }

    /// The payload bytes.
    pub fn payload(&self) -> &[u8] {
        &self.payload[..self.len as usize]
    }

    /// Bytes this frame takes on the wire.
    pub fn wire_len(&self) -> usize {
        OVERHEAD + self.len as usize
    }

    /// Writes the frame to the start of `out`; returns the bytes written.
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, FrameError> {
        encode(self.kind, self.seq, self.payload(), out)
    }
}

/// Writes a frame of type `kind` with sequence number `seq` and `payload`
/// to the start of `out`; returns the bytes written (`payload.len()` + 8).
pub fn encode(kind: u8, seq: u16, payload: &[u8], out: &mut [u8]) -> Result<usize, FrameError> {
    if payload.len() > MAX_PAYLOAD {
        return Err(FrameError::PayloadTooLong(payload.len()));
    }
    let n = OVERHEAD + payload.len();
    if out.len() < n {
        return Err(FrameError::BufferTooSmall { need: n, have: out.len() });
    }
    out[..2].copy_from_slice(&SYNC);
    out[2] = payload.len() as u8;
    out[3] = kind;
    out[4..6].copy_from_slice(&seq.to_le_bytes());
    out[HEADER..HEADER + payload.len()].copy_from_slice(payload);
    let c = crc::crc16(&out[2..HEADER + payload.len()]);
    out[HEADER + payload.len()..n].copy_from_slice(&c.to_le_bytes());
    Ok(n)
}

/// Decodes exactly one frame from `bytes` (no more, no less).
pub fn decode(bytes: &[u8]) -> Result<Frame, FrameError> {
    if bytes.len() < 3 {
        if bytes.iter().zip(SYNC).any(|(a, b)| *a != b) {
            return Err(FrameError::BadSync);
        }
        return Err(FrameError::Truncated { need: OVERHEAD, have: bytes.len() });
    }
    if bytes[..2] != SYNC {
        return Err(FrameError::BadSync);
    }
    let len = bytes[2];
    if len as usize > MAX_PAYLOAD {
        return Err(FrameError::BadLength(len));
    }
    let n = OVERHEAD + len as usize;
    if bytes.len() < n {
        return Err(FrameError::Truncated { need: n, have: bytes.len() });
    }
    if bytes.len() > n {
        return Err(FrameError::Trailing(bytes.len() - n));
    }
    check(bytes)
}

/// Checks the CRC of a complete candidate `bytes` (sync and length already
/// checked, `bytes.len()` = 8 + len) and builds the frame.
pub(crate) fn check(bytes: &[u8]) -> Result<Frame, FrameError> {
    let len = bytes[2] as usize;
    let body = &bytes[2..HEADER + len];
    let stored = u16::from_le_bytes([bytes[HEADER + len], bytes[HEADER + len + 1]]);
    let computed = crc::crc16(body);
    if stored != computed {
        return Err(FrameError::BadCrc { stored, computed });
    }
    let mut payload = [0u8; MAX_PAYLOAD];
    payload[..len].copy_from_slice(&bytes[HEADER..HEADER + len]);
    Ok(Frame { kind: bytes[3], seq: u16::from_le_bytes([bytes[4], bytes[5]]), len: len as u8, payload })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_of_every_length() {
        let mut buf = [0u8; MAX_FRAME];
        for len in 0..=MAX_PAYLOAD {
            let payload: Vec<u8> = (0..len as u8).map(|b| b.wrapping_mul(37)).collect();
            let n = encode(0x21, 0xBEEF, &payload, &mut buf).unwrap();
            assert_eq!(n, len + OVERHEAD);
            let f = decode(&buf[..n]).unwrap();
            assert_eq!((f.kind, f.seq, f.payload()), (0x21, 0xBEEF, &payload[..]));
            assert_eq!(f.wire_len(), n);
        }
    }

    #[test]
    fn layout_is_little_endian_with_the_crc_over_length_to_payload() {
        let mut buf = [0u8; 16];
        let n = encode(0x10, 0x0102, &[0xAA, 0xBB], &mut buf).unwrap();
        assert_eq!(&buf[..6], &[0xA5, 0x5A, 2, 0x10, 0x02, 0x01]);
        assert_eq!(&buf[6..8], &[0xAA, 0xBB]);
        let c = crc::crc16(&[2, 0x10, 0x02, 0x01, 0xAA, 0xBB]);
        assert_eq!(&buf[8..n], &c.to_le_bytes());
    }

    #[test]
    fn refuses_what_is_not_one_good_frame() {
        let mut buf = [0u8; MAX_FRAME + 4];
        assert_eq!(encode(1, 0, &[0; 65], &mut buf), Err(FrameError::PayloadTooLong(65)));
        assert_eq!(encode(1, 0, &[0; 4], &mut buf[..11]), Err(FrameError::BufferTooSmall { need: 12, have: 11 }));
        let n = encode(0x21, 7, &[1, 2, 3, 4], &mut buf).unwrap();
        assert!(decode(&buf[..n]).is_ok());
        assert!(matches!(decode(&buf[..n - 1]), Err(FrameError::Truncated { need: 12, have: 11 })));
        assert_eq!(decode(&buf[..n + 1]), Err(FrameError::Trailing(1)));
        assert_eq!(decode(&buf[..1]), Err(FrameError::Truncated { need: OVERHEAD, have: 1 }));
        assert_eq!(decode(&[]), Err(FrameError::Truncated { need: OVERHEAD, have: 0 }));
        assert_eq!(decode(&[0x5A]), Err(FrameError::BadSync));
        let mut bad = buf;
        bad[1] = 0x55;
        assert_eq!(decode(&bad[..n]), Err(FrameError::BadSync));
        let mut bad = buf;
        bad[2] = 65;
        assert_eq!(decode(&bad[..n]), Err(FrameError::BadLength(65)));
        for i in 2..n {
            for bit in 0..8 {
                let mut bad = buf;
                bad[i] ^= 1 << bit;
                assert!(decode(&bad[..n]).is_err(), "flip of bit {bit} of byte {i} went unnoticed");
            }
        }
    }
}
