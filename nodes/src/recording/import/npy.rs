//! NumPy `.npy` files (format versions 1.0, 2.0 and 3.0), read by hand.
//!
//! The layout (NumPy's `numpy/lib/format.py`, "NPY format"):
//!
//! | bytes | holds |
//! |---|---|
//! | 6 | magic `\x93NUMPY` |
//! | 2 | major, minor version (1.0, 2.0 or 3.0) |
//! | 2 (v1) or 4 (v2, v3) | header length, little-endian |
//! | header length | a Python dict literal, e.g. `{'descr': '<f8', 'fortran_order': False, 'shape': (3000, 2), }`, padded with spaces and a newline (ASCII in v1/v2, UTF-8 in v3) |
//! | rest | the array's bytes, C (row-major) or Fortran (column-major) order |
//!
//! Shape `(n,)` is one channel of `n` frames, `(n, c)` is `c` channels of
//! `n` frames. Samples of `f8`, `f4` and 1–8-byte signed and unsigned
//! integers in either byte order become `f64`. Everything else (object,
//! complex, text, structured arrays, 0-D or 3-D shapes, data shorter or
//! longer than the header claims) is refused with a message saying what was
//! found.

use super::error::{non_finite_word, ImportError};
use std::path::Path;

/// The magic string every `.npy` file starts with.
const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// The longest header accepted. NumPy itself refuses headers over 10 000
/// bytes unless told otherwise; this leaves room without letting a hostile
/// length claim drive the parser.
const MAX_HEADER: usize = 1 << 20;

/// Nesting depth of the header literal (NumPy's has 2: dict, shape tuple).
const MAX_DEPTH: usize = 8;

/// An `.npy` array as frames of channels.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct NpyArray {
    /// Frames (rows).
    pub frames: usize,
    /// Channels (columns); 1 for a 1-D array.
    pub channels: usize,
    /// Samples, interleaved frame after frame (`frame0ch0, frame0ch1, …`).
    pub samples: Vec<f64>,
    /// What was read, in words: `NumPy 1.0, <f8, shape (3000, 2), C order`.
    pub description: String,
}

/// Parses the bytes of an `.npy` file; `path` is only used in messages.
pub(super) fn parse(bytes: &[u8], path: &Path) -> Result<NpyArray, ImportError> {
    let err = |message: String| ImportError::Npy { path: path.to_path_buf(), message };
    let (major, minor, text, data_at) = header_text(bytes).map_err(err)?;
    let header = Header::parse(text).map_err(|m| err(format!("header {m}")))?;
    let dtype = Dtype::parse(&header.descr).map_err(err)?;
    let (frames, channels) = frames_and_channels(&header).map_err(err)?;
    let shape = shape_text(&header.shape);
    check_data_size(&header, &shape, (frames, channels), dtype.size, bytes.len() - data_at).map_err(err)?;
    let samples = samples(&bytes[data_at..], &dtype, frames, channels, header.fortran_order);
    if let Some(k) = samples.iter().position(|x| !x.is_finite()) {
        return Err(ImportError::NonFinite {
            path: path.to_path_buf(),
            channel: k % channels,
            frame: (k / channels) as u64,
            what: non_finite_word(samples[k]),
        });
    }
    let order = if header.shape.len() == 1 {
        ""
    } else if header.fortran_order {
        ", Fortran order"
    } else {
        ", C order"
    };
    Ok(NpyArray {
        frames,
        channels,
        samples,
        description: format!("NumPy {major}.{minor}, {}, shape {shape}{order}", header.descr),
    })
}

/// The format version, the header's text and where the data starts; the
/// message says what is wrong.
fn header_text(bytes: &[u8]) -> Result<(u8, u8, &str, usize), String> {
    if bytes.is_empty() {
        return Err("the file is empty".into());
    }
    if bytes.len() < 8 || &bytes[..6] != MAGIC {
        return Err("it does not start with the .npy magic `\\x93NUMPY` (was it written by np.save?)".into());
    }
    let (major, minor) = (bytes[6], bytes[7]);
    let (len_bytes, utf8) = match (major, minor) {
        (1, 0) => (2, false),
        (2, 0) => (4, false),
        (3, 0) => (4, true),
        _ => return Err(format!("format version {major}.{minor} is not one this evflow reads (1.0, 2.0 and 3.0)")),
    };
    if bytes.len() < 8 + len_bytes {
        return Err("the file ends inside the header length".into());
    }
    let header_len = if len_bytes == 2 {
        usize::from(u16::from_le_bytes([bytes[8], bytes[9]]))
    } else {
        u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize
    };
    if header_len > MAX_HEADER {
        return Err(format!("the header claims {header_len} bytes; headers longer than {MAX_HEADER} are refused"));
    }
    let start = 8 + len_bytes;
    let data_at = start + header_len;
    if bytes.len() < data_at {
        return Err(format!(
            "the header claims {header_len} bytes but the file ends after {} (cut short?)",
            bytes.len() - start
        ));
    }
    let raw = &bytes[start..data_at];
    let text = if utf8 {
        std::str::from_utf8(raw).map_err(|_| "the header is not UTF-8".to_string())?
    } else {
        if !raw.is_ascii() {
            return Err("the header holds non-ASCII bytes (version 1.0/2.0 headers are ASCII)".into());
        }
        // ASCII is valid UTF-8.
        std::str::from_utf8(raw).map_err(|_| "the header is not ASCII".to_string())?
    };
    Ok((major, minor, text, data_at))
}

/// The recording's frames and channels from the header's shape: (n,) or
/// (n, c), with samples, and not more channels than frames.
fn frames_and_channels(header: &Header) -> Result<(usize, usize), String> {
    let (frames, channels) = match header.shape.as_slice() {
        [] => return Err("shape () is a single number, not a recording; save a 1-D or 2-D array".into()),
        [n] => (*n, 1),
        [n, c] => (*n, *c),
        s => {
            return Err(format!(
                "shape {} has {} dimensions; a recording is 1-D (frames,) or 2-D (frames, channels)",
                shape_text(s),
                s.len()
            ))
        }
    };
    let shape = shape_text(&header.shape);
    if frames == 0 || channels == 0 {
        return Err(format!("shape {shape} holds no samples"));
    }
    if header.shape.len() == 2 && channels > frames {
        return Err(format!(
            "shape {shape} reads as {channels} channels of {frames} frames; a recording is (frames, channels): \
             save the transpose (arr.T) or np.column_stack([...]) of the channels"
        ));
    }
    Ok((frames, channels))
}

/// The data holds exactly the `frames` × `channels` samples of `size`
/// bytes the header describes (`present` bytes follow the header).
fn check_data_size(
    header: &Header,
    shape: &str,
    (frames, channels): (usize, usize),
    size: usize,
    present: usize,
) -> Result<(), String> {
    let expected = frames
        .checked_mul(channels)
        .and_then(|n| n.checked_mul(size))
        .ok_or_else(|| format!("shape {shape} of {} claims more bytes than any file can hold", header.descr))?;
    if present < expected {
        return Err(format!(
            "truncated: shape {shape} of {} needs {expected} bytes of data but the file holds {present}",
            header.descr
        ));
    }
    if present > expected {
        return Err(format!(
            "{} bytes follow the {expected} bytes of data that shape {shape} of {} describes (the header does not \
             describe the file)",
            present - expected,
            header.descr
        ));
    }
    Ok(())
}

/// The samples of `data`, interleaved frame after frame.
fn samples(data: &[u8], dtype: &Dtype, frames: usize, channels: usize, fortran_order: bool) -> Vec<f64> {
    let mut samples = Vec::with_capacity(frames * channels);
    samples.extend(data.chunks_exact(dtype.size).map(dtype.convert));
    if fortran_order && channels > 1 {
        // Column-major: element (frame i, channel j) is at j·frames + i.
        let column_major = std::mem::take(&mut samples);
        samples.reserve_exact(column_major.len());
        for i in 0..frames {
            samples.extend((0..channels).map(|j| column_major[j * frames + i]));
        }
    }
    samples
}

/// `(3000, 2)`, `(3000,)`, `()`: a shape as Python prints it.
fn shape_text(s: &[usize]) -> String {
    match s {
        [n] => format!("({n},)"),
        _ => format!("({})", s.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    }
}

/// The three keys of an `.npy` header.
#[derive(Debug, Clone, PartialEq)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

impl Header {
    /// Parses the header's dict literal; the message says what is wrong.
    fn parse(text: &str) -> Result<Header, String> {
        let mut p = Lexer { s: text.as_bytes(), pos: 0 };
        let value = p.value(0)?;
        p.skip_space();
        if p.pos != p.s.len() {
            return Err(format!("has text after its closing `}}` at byte {}", p.pos));
        }
        let Lit::Dict(entries) = value else {
            return Err(format!("is {}, not a dict", value.kind()));
        };
        let (mut descr, mut fortran, mut shape) = (None, None, None);
        for (k, v) in entries {
            let Lit::Str(key) = k else {
                return Err(format!("has a key that is {}, not a string", k.kind()));
            };
            let slot_taken = match key.as_str() {
                "descr" => descr.replace(v).is_some(),
                "fortran_order" => fortran.replace(v).is_some(),
                "shape" => shape.replace(v).is_some(),
                other => return Err(format!("has an unexpected key `{other}` (expected descr, fortran_order, shape)")),
            };
            if slot_taken {
                return Err(format!("lists `{key}` twice"));
            }
        }
        let descr = match descr {
            Some(Lit::Str(s)) => s,
            Some(Lit::List(_)) => {
                return Err("describes a structured array (named fields); save a plain numeric array instead, \
                            e.g. np.column_stack([arr[name] for name in arr.dtype.names]).astype(np.float64)"
                    .into())
            }
            Some(v) => return Err(format!("`descr` is {}, not a dtype string like '<f8'", v.kind())),
            None => return Err("has no `descr` (the dtype)".into()),
        };
        let fortran_order = match fortran {
            Some(Lit::Bool(b)) => b,
            Some(v) => return Err(format!("`fortran_order` is {}, not True or False", v.kind())),
            None => return Err("has no `fortran_order`".into()),
        };
        let shape = match shape {
            Some(Lit::Tuple(items)) => items
                .into_iter()
                .map(|d| match d {
                    Lit::Int(n) => Ok(n),
                    other => Err(format!("`shape` holds {}, not a non-negative integer", other.kind())),
                })
                .collect::<Result<Vec<_>, _>>()?,
            Some(v) => return Err(format!("`shape` is {}, not a tuple", v.kind())),
            None => return Err("has no `shape`".into()),
        };
        Ok(Header { descr, fortran_order, shape })
    }
}

/// A Python literal, the subset `.npy` headers use.
#[derive(Debug, Clone, PartialEq)]
enum Lit {
    Str(String),
    Bool(bool),
    Int(usize),
    None,
    Tuple(Vec<Lit>),
    List(Vec<Lit>),
    Dict(Vec<(Lit, Lit)>),
}

impl Lit {
    fn kind(&self) -> String {
        match self {
            Lit::Str(s) => format!("the string '{s}'"),
            Lit::Bool(b) => (if *b { "True" } else { "False" }).to_string(),
            Lit::Int(n) => format!("the number {n}"),
            Lit::None => "None".into(),
            Lit::Tuple(_) => "a tuple".into(),
            Lit::List(_) => "a list".into(),
            Lit::Dict(_) => "a dict".into(),
        }
    }
}

/// A recursive-descent reader of Python literals, depth-limited.
struct Lexer<'a> {
    s: &'a [u8],
    pos: usize,
}

impl Lexer<'_> {
    fn skip_space(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_space();
        self.s.get(self.pos).copied()
    }

    fn value(&mut self, depth: usize) -> Result<Lit, String> {
        if depth > MAX_DEPTH {
            return Err(format!("nests deeper than {MAX_DEPTH} levels"));
        }
        let Some(c) = self.peek() else {
            return Err("ends where a value was expected".into());
        };
        match c {
            b'{' => self.dict(depth),
            b'(' | b'[' => self.sequence(c, depth),
            b'\'' | b'"' => self.string(c),
            b'0'..=b'9' | b'-' | b'+' => self.number(c),
            _ => self.word(c),
        }
    }

    /// A dict, at its `{`.
    fn dict(&mut self, depth: usize) -> Result<Lit, String> {
        self.pos += 1;
        let mut entries = Vec::new();
        loop {
            if self.peek() == Some(b'}') {
                self.pos += 1;
                return Ok(Lit::Dict(entries));
            }
            let k = self.value(depth + 1)?;
            if self.peek() != Some(b':') {
                return Err(format!("misses a `:` after a key at byte {}", self.pos));
            }
            self.pos += 1;
            let v = self.value(depth + 1)?;
            entries.push((k, v));
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {}
                _ => return Err(format!("misses a `,` or `}}` at byte {}", self.pos)),
            }
        }
    }

    /// A tuple or a list, at its `open`ing `(` or `[`.
    fn sequence(&mut self, open: u8, depth: usize) -> Result<Lit, String> {
        let close = if open == b'(' { b')' } else { b']' };
        self.pos += 1;
        let mut items = Vec::new();
        let mut trailing_comma = false;
        loop {
            if self.peek() == Some(close) {
                self.pos += 1;
                // `(5)` is the number 5 in Python; `(5,)` a tuple.
                if open == b'(' && items.len() == 1 && !trailing_comma {
                    return Ok(items.pop().unwrap_or(Lit::None));
                }
                return Ok(if open == b'(' { Lit::Tuple(items) } else { Lit::List(items) });
            }
            items.push(self.value(depth + 1)?);
            trailing_comma = false;
            match self.peek() {
                Some(b',') => {
                    self.pos += 1;
                    trailing_comma = true;
                }
                Some(x) if x == close => {}
                _ => return Err(format!("misses a `,` or `{}` at byte {}", close as char, self.pos)),
            }
        }
    }

    /// A string, at its `quote`.
    fn string(&mut self, quote: u8) -> Result<Lit, String> {
        self.pos += 1;
        let from = self.pos;
        while self.pos < self.s.len() && self.s[self.pos] != quote {
            if self.s[self.pos] == b'\\' {
                return Err(format!("holds an escape sequence in a string at byte {}", self.pos));
            }
            self.pos += 1;
        }
        if self.pos >= self.s.len() {
            return Err("ends inside a string".into());
        }
        let text = String::from_utf8_lossy(&self.s[from..self.pos]).into_owned();
        self.pos += 1;
        Ok(Lit::Str(text))
    }

    /// A non-negative integer, at its first digit or sign `c`.
    fn number(&mut self, c: u8) -> Result<Lit, String> {
        let from = self.pos;
        if c == b'-' || c == b'+' {
            self.pos += 1;
        }
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_digit() {
            self.pos += 1;
        }
        let digits = std::str::from_utf8(&self.s[from..self.pos]).unwrap_or("");
        // Python 2 wrote long integers as `3000L`.
        if matches!(self.s.get(self.pos), Some(b'L') | Some(b'l')) {
            self.pos += 1;
        }
        if digits.starts_with('-') {
            return Err(format!("holds the negative number {digits}"));
        }
        digits.trim_start_matches('+').parse::<usize>().map(Lit::Int).map_err(|_| {
            if digits.trim_start_matches('+').is_empty() {
                format!("holds a lone sign at byte {from}")
            } else {
                format!("holds the number {digits}, too large for this machine")
            }
        })
    }

    /// `True`, `False` or `None`, at its first character `c`.
    fn word(&mut self, c: u8) -> Result<Lit, String> {
        let from = self.pos;
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_alphanumeric() {
            self.pos += 1;
        }
        match &self.s[from..self.pos] {
            b"True" => Ok(Lit::Bool(true)),
            b"False" => Ok(Lit::Bool(false)),
            b"None" => Ok(Lit::None),
            b"" => Err(format!("holds an unexpected `{}` at byte {from}", char::from(c).escape_default())),
            w => Err(format!("holds an unexpected word `{}` at byte {from}", String::from_utf8_lossy(w))),
        }
    }
}

/// A numeric dtype evflow converts to `f64`.
#[derive(Clone, Copy)]
struct Dtype {
    size: usize,
    convert: fn(&[u8]) -> f64,
}

macro_rules! converter {
    ($t:ty, $from:ident) => {{
        fn f(b: &[u8]) -> f64 {
            let mut a = [0u8; std::mem::size_of::<$t>()];
            a.copy_from_slice(b);
            <$t>::$from(a) as f64
        }
        f as fn(&[u8]) -> f64
    }};
}

impl Dtype {
    /// `<f8`, `>i2`, `|u1`, …; the message names the dtype and says why
    /// it is refused.
    fn parse(descr: &str) -> Result<Dtype, String> {
        let refuse = |why: &str| Err(format!("dtype '{descr}' {why}"));
        let Some(order @ ('<' | '>' | '|' | '=')) = descr.chars().next() else {
            return refuse("has no byte-order mark (`<`, `>`, `|` or `=`), which NumPy always writes");
        };
        let rest = &descr[1..];
        let little = match order {
            '>' => false,
            '=' => cfg!(target_endian = "little"),
            _ => true, // `<`, or `|` for one-byte types
        };
        let kind = rest.chars().next().unwrap_or(' ');
        let size: Option<usize> = rest.get(1..).and_then(|s| s.parse().ok());
        let hint = "convert it with arr.astype(np.float64) before np.save";
        match (kind, size) {
            ('O', _) => refuse(&format!("is an object array (Python objects, not numbers); {hint}")),
            ('c', _) => {
                refuse("is complex; a recording holds real samples (save arr.real and arr.imag as two channels)")
            }
            ('U' | 'S' | 'a', _) => refuse(&format!("holds text, not numbers; {hint}")),
            ('M' | 'm', _) => refuse(&format!("holds dates or time spans, not samples; {hint}")),
            ('b', _) => refuse(&format!("is boolean; {hint}")),
            ('V', _) => refuse("is raw bytes (void), not numbers"),
            ('f', Some(2)) => refuse(&format!("is float16, which evflow does not read; {hint}")),
            ('f', Some(s)) if s > 8 => refuse(&format!("is a {}-bit float wider than float64; {hint}", s * 8)),
            ('f' | 'i' | 'u', Some(s)) if s > 1 && order == '|' => {
                refuse("is a multi-byte type marked `|` (byte order not applicable)")
            }
            ('f', Some(4)) => Ok(Dtype {
                size: 4,
                convert: if little { converter!(f32, from_le_bytes) } else { converter!(f32, from_be_bytes) },
            }),
            ('f', Some(8)) => Ok(Dtype {
                size: 8,
                convert: if little { converter!(f64, from_le_bytes) } else { converter!(f64, from_be_bytes) },
            }),
            ('i', Some(1)) => Ok(Dtype { size: 1, convert: converter!(i8, from_le_bytes) }),
            ('u', Some(1)) => Ok(Dtype { size: 1, convert: converter!(u8, from_le_bytes) }),
            ('i', Some(2)) => Ok(Dtype {
                size: 2,
                convert: if little { converter!(i16, from_le_bytes) } else { converter!(i16, from_be_bytes) },
            }),
            ('u', Some(2)) => Ok(Dtype {
                size: 2,
                convert: if little { converter!(u16, from_le_bytes) } else { converter!(u16, from_be_bytes) },
            }),
            ('i', Some(4)) => Ok(Dtype {
                size: 4,
                convert: if little { converter!(i32, from_le_bytes) } else { converter!(i32, from_be_bytes) },
            }),
            ('u', Some(4)) => Ok(Dtype {
                size: 4,
                convert: if little { converter!(u32, from_le_bytes) } else { converter!(u32, from_be_bytes) },
            }),
            ('i', Some(8)) => Ok(Dtype {
                size: 8,
                convert: if little { converter!(i64, from_le_bytes) } else { converter!(i64, from_be_bytes) },
            }),
            ('u', Some(8)) => Ok(Dtype {
                size: 8,
                convert: if little { converter!(u64, from_le_bytes) } else { converter!(u64, from_be_bytes) },
            }),
            _ => refuse(&format!(
                "is not a type evflow reads (float64/32 and 8–64-bit integers, e.g. '<f8', '>i2'); {hint}"
            )),
        }
    }
}
