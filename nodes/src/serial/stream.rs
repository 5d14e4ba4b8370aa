//! An incremental frame decoder over a byte stream.
//!
//! Bytes arrive in arbitrary pieces (a serial read returns whatever the
//! driver holds); [`StreamDecoder::feed`] takes each piece and hands every
//! complete, CRC-checked frame to a callback. It never panics, whatever the
//! bytes, and resynchronizes by itself:
//!
//! 1. Bytes before the sync pair `A5 5A` are discarded (counted as garbage).
//! 2. A declared length above 64 means the sync pair was not a frame start:
//!    one byte is discarded and the search goes on (`bad_length`).
//! 3. Once the whole candidate is buffered, its CRC decides. On a mismatch
//!    only the first byte is discarded and the search resumes inside the
//!    candidate, so a frame that starts within a damaged one is still found.
//!    The failure counts as `truncated` when another sync pair begins inside
//!    the candidate (a frame cut short by the next one), else as `bad_crc`.
//! 4. [`StreamDecoder::end_of_stream`] (a disconnect) delivers the complete
//!    frames still buffered and discards the rest; a started frame among it
//!    counts as `truncated`.
//!
//! Every byte fed ends up in exactly one of: a valid frame, the garbage
//! count, or the buffer (at most one frame's worth): [`StreamStats`] keeps
//! the books, and the tests check they balance.

use super::frame::{self, Frame, MAX_FRAME, MAX_PAYLOAD, OVERHEAD, SYNC};

/// Counters of a decoder since it was made.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamStats {
    /// Bytes fed.
    pub bytes: u64,
    /// Valid frames delivered.
    pub frames: u64,
    /// Bytes of valid frames.
    pub frame_bytes: u64,
    /// Bytes discarded: not part of any valid frame.
    pub garbage_bytes: u64,
    /// Candidates whose CRC did not match.
    pub bad_crc: u64,
    /// Candidates cut short by the start of another frame, or by the end of
    /// the stream.
    pub truncated: u64,
    /// Sync pairs followed by a length above the maximum.
    pub bad_length: u64,
}

impl StreamStats {
    /// Rejected candidates of every kind.
    pub fn bad_frames(&self) -> u64 {
        self.bad_crc + self.truncated + self.bad_length
    }
}

/// Buffer size: room for one whole frame plus a read's worth of bytes.
const CAP: usize = 4 * MAX_FRAME;

/// The incremental decoder. Allocates its buffer once, in [`StreamDecoder::new`].
pub struct StreamDecoder {
    buf: Box<[u8; CAP]>,
    start: usize,
    end: usize,
    stats: StreamStats,
}

impl Default for StreamDecoder {
    fn default() -> Self {
        Self::new()
    }
}

/// What the scan found at the front of the buffer.
enum Step {
    /// A frame at the front, `n` bytes long.
    Frame(Frame, usize),
    /// Discard `n` bytes (garbage or the first byte of a rejected candidate).
    Skip(usize),
    /// Nothing more can be decided until more bytes arrive.
    NeedMore,
}

impl StreamDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self { buf: Box::new([0; CAP]), start: 0, end: 0, stats: StreamStats::default() }
    }

    /// The counters.
    pub fn stats(&self) -> StreamStats {
        self.stats
    }

    /// Bytes waiting for the rest of a frame.
    pub fn buffered(&self) -> usize {
        self.end - self.start
    }

    /// Takes `data`, calling `on_frame` for each complete valid frame in
    /// stream order.
    pub fn feed(&mut self, mut data: &[u8], mut on_frame: impl FnMut(Frame)) {
        self.stats.bytes += data.len() as u64;
        while !data.is_empty() {
            if self.start > 0 {
                self.buf.copy_within(self.start..self.end, 0);
                self.end -= self.start;
                self.start = 0;
            }
            let n = data.len().min(CAP - self.end);
            self.buf[self.end..self.end + n].copy_from_slice(&data[..n]);
            self.end += n;
            data = &data[n..];
            self.drain(&mut on_frame);
        }
    }

    /// The stream ended (a disconnect): frames still complete among the
    /// buffered bytes are delivered (a damaged candidate with a long
    /// declared length may have been waiting over them); the rest is
    /// discarded, and each frame start left incomplete counts as truncated.
    pub fn end_of_stream(&mut self, mut on_frame: impl FnMut(Frame)) {
        loop {
            self.drain(&mut on_frame);
            let rest = &self.buf[self.start..self.end];
            if rest.is_empty() {
                break;
            }
            if rest.len() >= 2 && rest[..2] == SYNC {
                self.stats.truncated += 1;
            }
            self.start += 1;
            self.stats.garbage_bytes += 1;
        }
        self.start = 0;
        self.end = 0;
    }

    fn drain(&mut self, on_frame: &mut impl FnMut(Frame)) {
        loop {
            match self.step() {
                Step::Frame(f, n) => {
                    self.start += n;
                    self.stats.frames += 1;
                    self.stats.frame_bytes += n as u64;
                    on_frame(f);
                }
                Step::Skip(n) => {
                    self.start += n;
                    self.stats.garbage_bytes += n as u64;
                }
                Step::NeedMore => return,
            }
        }
    }

    fn step(&mut self) -> Step {
        let b = &self.buf[self.start..self.end];
        // Find the next sync pair (or a lone first sync byte at the end).
        let Some(i) = (0..b.len()).find(|&i| b[i] == SYNC[0] && (i + 1 == b.len() || b[i + 1] == SYNC[1])) else {
            return if b.is_empty() { Step::NeedMore } else { Step::Skip(b.len()) };
        };
        if i > 0 {
            return Step::Skip(i);
        }
        if b.len() < 3 {
            return Step::NeedMore;
        }
        let len = b[2] as usize;
        if len > MAX_PAYLOAD {
            self.stats.bad_length += 1;
            return Step::Skip(1);
        }
        let n = OVERHEAD + len;
        if b.len() < n {
            return Step::NeedMore;
        }
        match frame::check(&b[..n]) {
            Ok(f) => Step::Frame(f, n),
            Err(_) => {
                if b[1..n].windows(2).any(|w| w == SYNC) {
                    self.stats.truncated += 1;
                } else {
                    self.stats.bad_crc += 1;
                }
                Step::Skip(1)
            }
        }
    }
}

#[cfg(test)]
#[path = "stream_tests.rs"]
mod tests;
