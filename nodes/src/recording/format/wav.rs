//! The WAV container: the header evflow writes, and a chunk parser that
//! accepts any float64 WAV (other chunks, `WAVE_FORMAT_EXTENSIBLE`).
//!
//! Layout written (58 bytes, then the samples), as scipy.io.wavfile writes
//! float data: `RIFF` size `WAVE`, an 18-byte `fmt ` chunk (tag 3, cbSize 0),
//! a `fact` chunk (frames), and the `data` chunk last so it can grow.

use std::io::{Read, Seek, SeekFrom};

/// Bytes before the first sample.
pub(crate) const HEADER_LEN: u64 = 58;
/// Offset of the RIFF size field (file length − 8).
pub(crate) const RIFF_SIZE_AT: u64 = 4;
/// Offset of the `fact` chunk's frame count.
pub(crate) const FACT_FRAMES_AT: u64 = 46;
/// Offset of the `data` chunk's size field.
pub(crate) const DATA_SIZE_AT: u64 = 54;
/// Bytes per sample.
pub(crate) const SAMPLE_BYTES: usize = 8;

const WAVE_FORMAT_PCM: u16 = 1;
const WAVE_FORMAT_IEEE_FLOAT: u16 = 3;
const WAVE_FORMAT_EXTENSIBLE: u16 = 0xFFFE;
/// The tail shared by the KSDATAFORMAT_SUBTYPE GUIDs (after the 2-byte tag).
const SUBTYPE_TAIL: [u8; 14] = [0, 0, 0, 0, 0x10, 0, 0x80, 0, 0, 0xAA, 0, 0x38, 0x9B, 0x71];

/// The rate written in the header: the recording's rate rounded, at least 1.
pub(crate) fn header_rate(rate: f64) -> u32 {
    rate.round().clamp(1.0, u32::MAX as f64) as u32
}

/// The largest frame count whose RIFF size (data + 50) fits in 32 bits.
pub(crate) fn max_frames(channels: usize) -> u64 {
    (u64::from(u32::MAX) - (HEADER_LEN - 8)) / (channels * SAMPLE_BYTES) as u64
}

/// The header for `channels` channels at `rate` Hz holding `frames` frames.
/// `frames` must not exceed [`max_frames`].
pub(crate) fn header(channels: u16, rate: u32, frames: u64) -> [u8; HEADER_LEN as usize] {
    let block_align = u32::from(channels) * SAMPLE_BYTES as u32;
    let data = frames * u64::from(block_align);
    let mut h = [0u8; HEADER_LEN as usize];
    h[0..4].copy_from_slice(b"RIFF");
    h[4..8].copy_from_slice(&riff_size(data).to_le_bytes());
    h[8..12].copy_from_slice(b"WAVE");
    h[12..16].copy_from_slice(b"fmt ");
    h[16..20].copy_from_slice(&18u32.to_le_bytes());
    h[20..22].copy_from_slice(&WAVE_FORMAT_IEEE_FLOAT.to_le_bytes());
    h[22..24].copy_from_slice(&channels.to_le_bytes());
    h[24..28].copy_from_slice(&rate.to_le_bytes());
    h[28..32].copy_from_slice(&rate.saturating_mul(block_align).to_le_bytes());
    h[32..34].copy_from_slice(&(block_align as u16).to_le_bytes());
    h[34..36].copy_from_slice(&64u16.to_le_bytes());
    h[36..38].copy_from_slice(&0u16.to_le_bytes());
    h[38..42].copy_from_slice(b"fact");
    h[42..46].copy_from_slice(&4u32.to_le_bytes());
    h[46..50].copy_from_slice(&(frames as u32).to_le_bytes());
    h[50..54].copy_from_slice(b"data");
    h[54..58].copy_from_slice(&(data as u32).to_le_bytes());
    h
}

/// The RIFF size field for `data` bytes of samples.
pub(crate) fn riff_size(data: u64) -> u32 {
    (data + HEADER_LEN - 8) as u32
}

/// What a WAV's header says, and where its samples are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WavInfo {
    /// Interleaved channels.
    pub channels: usize,
    /// Header rate in Hz.
    pub rate: u32,
    /// Offset of the first sample.
    pub data_offset: u64,
    /// Whole frames the `data` chunk claims.
    pub claimed_frames: u64,
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Why a header cannot be read: broken RIFF, another sample type, or the
/// file could not be read.
#[derive(Debug)]
pub(crate) enum WavProblem {
    /// The RIFF structure is broken (message for people).
    Broken(String),
    /// Well-formed, but the samples are not 64-bit float (what they are).
    NotFloat64(String),
    /// The operating system refused a read or a seek.
    Io(std::io::Error),
}

/// The largest `fmt ` body read: the 40 bytes of `WAVE_FORMAT_EXTENSIBLE`
/// are all that is looked at.
const FMT_READ: u64 = 64;

/// Reads the header of the WAV file `r` of `len` bytes, reading only the
/// chunk headers and the `fmt ` body (never the samples, never past `len`).
/// Walks the chunks in the file (not trusting the RIFF size, which a crashed
/// writer may have left stale) up to the `data` chunk.
pub(crate) fn parse<R: Read + Seek>(r: &mut R, len: u64) -> Result<WavInfo, WavProblem> {
    let broken = |m: &str| WavProblem::Broken(m.to_string());
    if len < 12 {
        return Err(broken(&format!("{len} bytes, shorter than a RIFF header (12)")));
    }
    let mut head = [0u8; 12];
    read_at(r, 0, &mut head)?;
    if &head[0..4] != b"RIFF" {
        return Err(broken("does not start with `RIFF`"));
    }
    if &head[8..12] != b"WAVE" {
        return Err(broken("RIFF file of another type than `WAVE`"));
    }
    let mut fmt: Option<(usize, u32)> = None;
    let mut pos = 12u64;
    loop {
        if pos + 8 > len {
            return Err(broken(if fmt.is_some() { "no `data` chunk" } else { "no `fmt ` chunk" }));
        }
        let mut chunk = [0u8; 8];
        read_at(r, pos, &mut chunk)?;
        let id = &chunk[0..4];
        let size = u64::from(u32_at(&chunk, 4));
        let body = pos + 8;
        if id == b"data" {
            let Some((channels, rate)) = fmt else {
                return Err(broken("`data` chunk before the `fmt ` chunk"));
            };
            let claimed_frames = size / (channels * SAMPLE_BYTES) as u64;
            return Ok(WavInfo { channels, rate, data_offset: body, claimed_frames });
        }
        if id == b"fmt " {
            if size < 16 || body + 16 > len {
                return Err(broken("`fmt ` chunk shorter than 16 bytes"));
            }
            let mut f = vec![0u8; size.min(len - body).min(FMT_READ) as usize];
            read_at(r, body, &mut f)?;
            fmt = Some(read_fmt(&f)?);
        }
        // Chunks are padded to an even length.
        pos = body + size + (size & 1);
    }
}

/// Fills `buf` from offset `at` of `r`.
fn read_at<R: Read + Seek>(r: &mut R, at: u64, buf: &mut [u8]) -> Result<(), WavProblem> {
    r.seek(SeekFrom::Start(at)).map_err(WavProblem::Io)?;
    r.read_exact(buf).map_err(WavProblem::Io)
}

/// Checks the `fmt ` chunk body: 64-bit IEEE float, consistent block size.
fn read_fmt(f: &[u8]) -> Result<(usize, u32), WavProblem> {
    let mut tag = u16_at(f, 0);
    let channels = usize::from(u16_at(f, 2));
    let rate = u32_at(f, 4);
    let block_align = usize::from(u16_at(f, 12));
    let bits = u16_at(f, 14);
    if tag == WAVE_FORMAT_EXTENSIBLE {
        // cbSize (2) + valid bits (2) + channel mask (4) + subformat GUID (16).
        if f.len() < 40 {
            return Err(WavProblem::Broken("WAVE_FORMAT_EXTENSIBLE `fmt ` chunk shorter than 40 bytes".into()));
        }
        if f[26..40] != SUBTYPE_TAIL {
            return Err(WavProblem::NotFloat64("of an unknown WAVE_FORMAT_EXTENSIBLE subformat".into()));
        }
        tag = u16_at(f, 24);
    }
    if tag != WAVE_FORMAT_IEEE_FLOAT || bits != 64 {
        let what = match tag {
            WAVE_FORMAT_PCM => format!("{bits}-bit integers (PCM, format 1)"),
            WAVE_FORMAT_IEEE_FLOAT => format!("{bits}-bit floats (format 3)"),
            t => format!("of WAV format {t}, {bits} bits"),
        };
        return Err(WavProblem::NotFloat64(what));
    }
    if channels == 0 {
        return Err(WavProblem::Broken("the header declares 0 channels".into()));
    }
    if block_align != channels * SAMPLE_BYTES {
        return Err(WavProblem::Broken(format!(
            "block size {block_align} bytes does not match {channels} channels of 8 bytes"
        )));
    }
    Ok((channels, rate))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    /// A reader that counts the bytes read from it.
    struct Counting<R> {
        inner: R,
        read: u64,
    }
    impl<R: Read> Read for Counting<R> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.inner.read(buf)?;
            self.read += n as u64;
            Ok(n)
        }
    }
    impl<R: Seek> Seek for Counting<R> {
        fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
            self.inner.seek(pos)
        }
    }

    #[test]
    fn the_header_is_read_without_the_samples() {
        // 2 channels, a million frames: 16 MB of samples, 58 bytes of header.
        let mut file = header(2, 1000, 1_000_000).to_vec();
        file.resize(file.len() + 16_000_000, 0);
        let len = file.len() as u64;
        let mut r = Counting { inner: Cursor::new(file), read: 0 };
        let info = parse(&mut r, len).unwrap();
        assert_eq!((info.channels, info.rate, info.data_offset, info.claimed_frames), (2, 1000, 58, 1_000_000));
        assert!(r.read <= 12 + 3 * 8 + FMT_READ, "{} bytes read for the header", r.read);
    }

    #[test]
    fn a_chunk_size_past_the_end_stops_the_walk() {
        // A `LIST` chunk claiming 4 GiB before the `fmt `: no data chunk in reach.
        let mut b = b"RIFF\0\0\0\0WAVELIST".to_vec();
        b.extend_from_slice(&u32::MAX.to_le_bytes());
        b.extend_from_slice(&[0; 100]);
        let len = b.len() as u64;
        match parse(&mut Cursor::new(b), len) {
            Err(WavProblem::Broken(m)) => assert_eq!(m, "no `fmt ` chunk"),
            other => panic!("{other:?}"),
        }
    }
}
