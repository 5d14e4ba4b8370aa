//! How `interp` hands a table to `playback`: frames on a fast stream.
//!
//! Ports carry only samples, so a table travels as a **frame** of F samples
//! on the `table` port, one frame per update period: F = stream_rate /
//! update_rate (e.g. 20 kHz / 10 Hz = 2000). Frame f occupies table-port
//! samples f·F .. (f+1)·F and is laid out as
//!
//! | offset | value |
//! |---|---|
//! | 0 | [`MAGIC`] |
//! | 1 | F |
//! | 2 | T, loop length in table samples |
//! | 3 | X, seam overlap in table samples |
//! | 4 | loop length in cm (T·v_u / f_s) |
//! | 5 | f_s, the table's sample rate in Hz (the grid recordings' rate) |
//! | 6 | m_u used, g (after clamping) |
//! | 7 | v_u used, cm/s (after clamping) |
//! | 8 | generation (frame number f) |
//! | 9 | flags: 1 = improved scheme (else basic), + 2 = the table is a carrier's envelope |
//! | 10 … 10+T+X−1 | the table U_{u,u}\[0 .. T+X\] |
//! | rest | 0 |
//!
//! With flag 2 the table holds the envelope a of an actuation that rides a
//! Nyquist-rate carrier, u = (−1)ⁿ·a (`interp` demodulated its cells):
//! `playback` reads the envelope and multiplies by (−1)ᵐ at its own output
//! sample m, so the carrier stays at the output's Nyquist rate whatever the
//! re-sampling and the playhead did to the table.
//!
//! Sending the table as samples spreads its computation evenly over the
//! ticks of the update period (stream_rate / base rate samples per tick)
//! and keeps block and tick processing identical. The price is latency: a
//! table computed from the condition at the start of frame f is complete,
//! and played, one update period later.

/// Marks a frame's first sample.
pub const MAGIC: f64 = 640_064.125;

/// Samples of header before the table.
pub const HEADER: usize = 10;

/// Offsets in the header.
pub mod at {
    /// [`super::MAGIC`].
    pub const MAGIC: usize = 0;
    /// Frame length F.
    pub const FRAME: usize = 1;
    /// Loop length T.
    pub const LEN: usize = 2;
    /// Seam overlap X.
    pub const OVERLAP: usize = 3;
    /// Loop length in cm.
    pub const LOOP_CM: usize = 4;
    /// Table sample rate, Hz.
    pub const RATE: usize = 5;
    /// m_u, g.
    pub const LOAD: usize = 6;
    /// v_u, cm/s.
    pub const VELOCITY: usize = 7;
    /// Frame number.
    pub const GENERATION: usize = 8;
    /// Flags: [`super::IMPROVED`] + [`super::CARRIER`].
    pub const FLAGS: usize = 9;
}

/// Flag: the table was computed by the improved scheme (Eq. 6.4).
pub const IMPROVED: u32 = 1;

/// Flag: the table is the envelope of a Nyquist-rate carrier.
pub const CARRIER: u32 = 2;

/// A received frame's header, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Header {
    /// Loop length T.
    pub len: usize,
    /// Seam overlap X.
    pub overlap: usize,
    /// Loop length, cm.
    pub loop_cm: f64,
    /// Table rate, Hz.
    pub rate: f64,
    /// The table is a carrier's envelope: play it times (−1)ᵐ.
    pub carrier: bool,
}

impl Header {
    /// Reads and checks the header of a complete frame of length `frame`
    /// (`None` if it is not a table frame).
    pub fn read(f: &[f64], frame: usize) -> Option<Header> {
        let whole = |x: f64| x.is_finite() && x >= 0.0 && x.fract() == 0.0 && x < 1e12;
        if f.len() < HEADER || f[at::MAGIC] != MAGIC || f[at::FRAME] != frame as f64 {
            return None;
        }
        let (t, x) = (f[at::LEN], f[at::OVERLAP]);
        if !(whole(t) && whole(x) && t >= 2.0) {
            return None;
        }
        let (len, overlap) = (t as usize, x as usize);
        if HEADER + len + overlap > frame || overlap > len {
            return None;
        }
        let (loop_cm, rate) = (f[at::LOOP_CM], f[at::RATE]);
        if !(loop_cm.is_finite() && loop_cm > 0.0 && rate.is_finite() && rate > 0.0) {
            return None;
        }
        if !f[HEADER..HEADER + len + overlap].iter().all(|v| v.is_finite()) {
            return None;
        }
        let flags = f[at::FLAGS];
        if !(whole(flags) && flags < 4.0) {
            return None;
        }
        Some(Header { len, overlap, loop_cm, rate, carrier: flags as u32 & CARRIER != 0 })
    }
}
