//! Importing a lab's own data as an evflow recording (`evflow import`).
//!
//! Reads a NumPy `.npy` array ([`npy`](self) format versions 1.0–3.0) or
//! delimited text (`.csv`, `.tsv`, `.txt`: see [`Delimiter`]) and writes it
//! as an evflow recording — `NAME.wav` (64-bit float) + `NAME.json`
//! (`docs/recording-format.md`) — with its rate, channel names and units,
//! experimental condition and a `source` naming the imported file.
//!
//! * **Columns.** A 1-D array or a one-column file is one channel; an
//!   `(n, c)` array or `c` columns are `c` channels of `n` frames. Names come
//!   from [`ImportOptions::channels`] (one per column of the file), else from
//!   the CSV header (made into port names: `Force X` → `Force_X`), else
//!   `ch0`, `ch1`, …; units from [`ImportOptions::units`] or the header
//!   (`force [N]`).
//! * **Rate.** [`ImportOptions::rate`], or inferred from a column named
//!   `time` or `t` (unit s, ms, us or ns; `s` when none), whose steps must be
//!   uniform within [`ImportOptions::time_tolerance`] of the mean step. The
//!   time column is then dropped unless [`ImportOptions::keep_time`]. Given
//!   both, they must agree.
//! * **Checks.** Every sample finite; every error names the file (and for
//!   text the line and column).
//! * **Atomic.** The source is read and checked whole before anything is
//!   written; the recording is written through
//!   [`RecordingWriter::create`]'s temporary files and renamed into place at
//!   the end, so an error leaves nothing at the destination. An existing
//!   recording is never replaced unless `force` is set.
//!
//! MATLAB `.mat` files are not read: `docs/rig.md` says why and shows the
//! MATLAB lines that write CSV (or the WAV + JSON pair) instead.

mod csv;
mod error;
mod npy;
#[cfg(test)]
mod tests;

pub use super::format::Written;
pub use csv::Delimiter;
pub use error::ImportError;

use super::format::{Channel, Condition, RecordingMeta, RecordingPaths, RecordingWriter, MAX_RATE_HZ, MIN_RATE_HZ};
use std::path::{Path, PathBuf};

/// How to import: everything the source does not say.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// Sample rate in Hz; `None` infers it from a time column.
    pub rate: Option<f64>,
    /// One name per column of the source (a column named `time` or `t` is
    /// the time column); `None` takes the CSV header, else `ch0`, `ch1`, ….
    pub channels: Option<Vec<String>>,
    /// One unit per column of the source (as [`ImportOptions::channels`]);
    /// `None` takes the CSV header's units, else none.
    pub units: Option<Vec<String>>,
    /// The experimental condition written to the sidecar.
    pub condition: Condition,
    /// The text delimiter; `None` detects it (a `.tsv` file: tab).
    pub delimiter: Option<Delimiter>,
    /// Keep the time column as a channel (it is dropped by default once it
    /// gave the rate).
    pub keep_time: bool,
    /// How far a time step may stray from the mean step, as a fraction of it
    /// (default 0.01); also how far `rate` and the time column may disagree.
    pub time_tolerance: f64,
    /// Replace an existing recording at the destination.
    pub force: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            rate: None,
            channels: None,
            units: None,
            condition: Condition::default(),
            delimiter: None,
            keep_time: false,
            time_tolerance: 0.01,
            force: false,
        }
    }
}

impl ImportOptions {
    /// Adds a `key=value` entry to the condition. The keys `load_g`,
    /// `velocity_cm_s` and `gain` take numbers and `material` text; any other
    /// key takes an integer or a number if the value reads as one,
    /// `true`/`false`, else text. A key already set is an error.
    pub fn add_condition(&mut self, entry: &str) -> Result<(), ImportError> {
        let usage = |m: String| ImportError::Usage(format!("--condition {entry}: {m}"));
        let Some((key, value)) = entry.split_once('=') else {
            return Err(usage("expected KEY=VALUE, e.g. trial=3".into()));
        };
        let (key, value) = (key.trim(), value.trim());
        if key.is_empty() || value.is_empty() {
            return Err(usage("expected KEY=VALUE with neither empty".into()));
        }
        let c = &mut self.condition;
        let taken = match key {
            "load_g" | "velocity_cm_s" | "gain" => {
                let x: f64 = value.parse().map_err(|_| usage(format!("`{value}` is not a number")))?;
                let slot = match key {
                    "load_g" => &mut c.load_g,
                    "velocity_cm_s" => &mut c.velocity_cm_s,
                    _ => &mut c.gain,
                };
                slot.replace(x).is_some()
            }
            "material" => c.material.replace(value.to_string()).is_some(),
            _ => {
                let v = if let Ok(i) = value.parse::<i64>() {
                    serde_json::Value::from(i)
                } else if let Ok(x) = value.parse::<f64>() {
                    serde_json::Number::from_f64(x)
                        .map(serde_json::Value::Number)
                        .ok_or_else(|| usage(format!("`{value}` is not a finite number")))?
                } else {
                    match value {
                        "true" => serde_json::Value::Bool(true),
                        "false" => serde_json::Value::Bool(false),
                        text => serde_json::Value::String(text.to_string()),
                    }
                };
                c.extra.insert(key.to_string(), v).is_some()
            }
        };
        if taken {
            return Err(usage(format!("`{key}` is given twice")));
        }
        Ok(())
    }
}

/// A source read and checked, ready to be written.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    /// Rate, channels, condition and source text of the recording to write.
    pub meta: RecordingMeta,
    /// Frames (samples per channel).
    pub frames: usize,
    /// What was decided on the way (rate inferred, column dropped, names
    /// changed), one sentence each, for the user.
    pub notes: Vec<String>,
    samples: Vec<f64>,
}

impl Imported {
    /// The samples, interleaved frame after frame.
    pub fn samples(&self) -> &[f64] {
        &self.samples
    }

    /// The samples of one channel, by name.
    pub fn channel(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.meta.channel_index(name)?;
        Some(self.samples.iter().skip(c).step_by(self.meta.channels.len()).copied().collect())
    }

    /// Length in seconds.
    pub fn duration(&self) -> f64 {
        self.frames as f64 / self.meta.rate
    }

    /// Writes the recording at `dest` (`NAME`, `NAME.wav` or `NAME.json`),
    /// creating its folder. Refuses to replace an existing recording unless
    /// `force`. On any error nothing is left at the destination (folders it
    /// created are removed again).
    pub fn write(&self, dest: &Path, force: bool) -> Result<Written, ImportError> {
        self.write_until(dest, force, &std::sync::atomic::AtomicBool::new(false))
    }

    /// [`Imported::write`], stopping with [`ImportError::Interrupted`] (and
    /// nothing at the destination) when `stop` is set: the CLI sets it on
    /// SIGINT, SIGTERM or SIGHUP. Frames are written in pieces of
    /// [`WRITE_FRAMES`], `stop` checked before each and before the renames.
    pub fn write_until(
        &self,
        dest: &Path,
        force: bool,
        stop: &std::sync::atomic::AtomicBool,
    ) -> Result<Written, ImportError> {
        use std::sync::atomic::Ordering;
        let paths = RecordingPaths::new(dest);
        let existed = [&paths.wav, &paths.json].map(|p| p.exists());
        if !force {
            for (p, e) in [&paths.wav, &paths.json].into_iter().zip(existed) {
                if e {
                    return Err(ImportError::Exists { path: p.clone() });
                }
            }
        }
        let created = create_folders(paths.wav.parent())?;
        let interrupted = || ImportError::Interrupted { path: paths.wav.clone() };
        let result = (|| {
            let mut w = RecordingWriter::create(dest, self.meta.clone())?;
            let per = WRITE_FRAMES * self.meta.channels.len().max(1);
            for piece in self.samples.chunks(per) {
                if stop.load(Ordering::SeqCst) {
                    return Err(interrupted());
                }
                w.write_interleaved(piece)?;
            }
            if stop.load(Ordering::SeqCst) {
                return Err(interrupted());
            }
            Ok(w.finish()?)
        })();
        result.inspect_err(|_| {
            // The writer removes its temporary files; should it fail between
            // its two renames, the one that landed goes too.
            for (p, was) in [&paths.wav, &paths.json].into_iter().zip(existed) {
                if !was {
                    let _ = std::fs::remove_file(p);
                }
            }
            for dir in created.iter().rev() {
                let _ = std::fs::remove_dir(dir);
            }
        })
    }
}

/// Frames written at a time by [`Imported::write_until`] between checks
/// of its stop flag.
pub const WRITE_FRAMES: usize = 1 << 16;

/// Creates `dir` and its missing parents; returns the ones it created,
/// outermost first.
fn create_folders(dir: Option<&Path>) -> Result<Vec<PathBuf>, ImportError> {
    let Some(dir) = dir.filter(|d| !d.as_os_str().is_empty()) else { return Ok(Vec::new()) };
    let missing: Vec<PathBuf> =
        dir.ancestors().take_while(|a| !a.as_os_str().is_empty() && !a.exists()).map(Path::to_path_buf).collect();
    std::fs::create_dir_all(dir).map_err(|source| ImportError::Io { path: dir.to_path_buf(), source })?;
    Ok(missing.into_iter().rev().collect())
}

/// Where `evflow import SRC [--out OUT]` writes: `OUT` itself (`NAME`,
/// `NAME.wav` or `NAME.json`), or inside `OUT` when it is an existing folder
/// or ends with a path separator, named after `SRC`; without `OUT`, beside
/// `SRC` with its extension replaced (`runs/felt.csv` → `runs/felt.wav` +
/// `runs/felt.json`).
pub fn destination(src: &Path, out: Option<&Path>) -> PathBuf {
    let stem = src.file_stem().map(PathBuf::from).unwrap_or_else(|| PathBuf::from("imported"));
    match out {
        None => src.with_file_name(stem),
        Some(o) => {
            let s = o.as_os_str().to_string_lossy();
            if o.is_dir() || s.ends_with('/') || s.ends_with(std::path::MAIN_SEPARATOR) {
                o.join(stem)
            } else {
                o.to_path_buf()
            }
        }
    }
}

/// Reads and checks `src` (nothing is written).
pub fn read(src: &Path, opts: &ImportOptions) -> Result<Imported, ImportError> {
    let ext = src.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let kind = match ext.as_deref() {
        Some("npy") => Kind::Npy,
        Some("csv" | "txt") => Kind::Text(opts.delimiter),
        Some("tsv") => Kind::Text(opts.delimiter.or(Some(Delimiter::Tab))),
        Some("mat") => return Err(ImportError::Mat { path: src.to_path_buf() }),
        Some("npz") => return Err(ImportError::Npz { path: src.to_path_buf() }),
        Some(e) => return Err(ImportError::UnsupportedKind { path: src.to_path_buf(), what: format!("a .{e} file") }),
        None => {
            return Err(ImportError::UnsupportedKind {
                path: src.to_path_buf(),
                what: "a file without an extension".into(),
            })
        }
    };
    let bytes = read_regular(src)?;
    let mut notes = Vec::new();
    let table = match kind {
        Kind::Npy => {
            let a = npy::parse(&bytes, src)?;
            Columns { heads: None, columns: a.channels, samples: a.samples, lines: None, description: a.description }
        }
        Kind::Text(delimiter) => {
            let text = decode_text(bytes, &mut notes);
            let t = csv::parse(&text, src, delimiter)?;
            if let Some(line) = t.header_from_comment {
                notes.push(format!("header read from the comment on line {line}"));
            }
            let description = format!(
                "{} rows, {} delimiter{}",
                t.rows(),
                t.delimiter.name(),
                if t.header.is_some() { ", header row" } else { "" }
            );
            Columns {
                heads: t.header.map(|h| h.into_iter().map(|h| (h.name, h.unit)).collect()),
                columns: t.columns,
                samples: t.samples,
                lines: Some(t.lines),
                description,
            }
        }
    };
    assemble(src, table, opts, notes)
}

/// The text of a delimited file: UTF-8 (with or without a byte-order
/// mark), UTF-16 with a byte-order mark (Excel's "Unicode text"), else
/// Latin-1 (every byte a character), with a note saying which.
fn decode_text(bytes: Vec<u8>, notes: &mut Vec<String>) -> String {
    let utf16 = |le: bool| {
        let units = bytes[2..].chunks_exact(2).map(|p| {
            if le {
                u16::from_le_bytes([p[0], p[1]])
            } else {
                u16::from_be_bytes([p[0], p[1]])
            }
        });
        char::decode_utf16(units).map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER)).collect::<String>()
    };
    match bytes.get(..2) {
        Some([0xff, 0xfe]) => {
            notes.push("the file is UTF-16 (little-endian)".into());
            return utf16(true);
        }
        Some([0xfe, 0xff]) => {
            notes.push("the file is UTF-16 (big-endian)".into());
            return utf16(false);
        }
        _ => {}
    }
    match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            notes.push("the file is not UTF-8: read as Latin-1".into());
            e.into_bytes().iter().map(|&b| char::from(b)).collect()
        }
    }
}

/// Reads `src` and writes it as a recording at `dest` (see [`destination`]
/// for a folder as `dest`): [`read`], then [`Imported::write`].
pub fn import_file(src: &Path, dest: &Path, opts: &ImportOptions) -> Result<Written, ImportError> {
    read(src, opts)?.write(&destination(src, Some(dest)), opts.force)
}

enum Kind {
    Npy,
    Text(Option<Delimiter>),
}

/// A source's columns before names, units and rate are settled.
struct Columns {
    /// Names and units from a header.
    heads: Option<Vec<(String, String)>>,
    columns: usize,
    /// Interleaved rows.
    samples: Vec<f64>,
    /// The file line of each row (text), for messages.
    lines: Option<Vec<usize>>,
    description: String,
}

/// The whole of `src`, which must be a regular file: a link to a device
/// (`/dev/zero`), a FIFO or a folder is refused before a byte is read, and
/// checked again on the open handle (the name may have been swapped).
fn read_regular(src: &Path) -> Result<Vec<u8>, ImportError> {
    use evflow_engine::files::{open_regular, OpenError};
    use std::io::Read;
    let io = |source| ImportError::Io { path: src.to_path_buf(), source };
    let (mut file, len) = open_regular(src).map_err(|e| match e {
        OpenError::Io(e) => io(e),
        OpenError::NotAFile { what } => ImportError::UnsupportedKind {
            path: src.to_path_buf(),
            what: if what == "a folder" { what.into() } else { format!("{what} (not a regular file)") },
        },
    })?;
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes)
}

/// Names, units, time column and rate: the recording's metadata.
fn assemble(src: &Path, t: Columns, opts: &ImportOptions, mut notes: Vec<String>) -> Result<Imported, ImportError> {
    let n = t.columns;
    let frames = t.samples.len() / n.max(1);
    let mut labels = Labels::of(src, &t, opts, &mut notes)?;
    let time = time_column(src, &labels.names, n, opts)?;
    let inferred = match time {
        Some(k) => inferred_rate(src, &t, k, &labels, frames, opts, &mut notes)?,
        None => None,
    };
    let rate = settle_rate(src, opts, inferred, t.lines.is_some(), time.is_some())?;
    let samples = drop_time(src, t.samples, n, time, opts, &mut labels, &mut notes)?;

    let condition = opts.condition.clone();
    check_condition(&condition).map_err(ImportError::Usage)?;
    let channels = labels.names.into_iter().zip(labels.units).map(|(n, u)| Channel::new(n, u)).collect();
    let meta = RecordingMeta {
        rate,
        channels,
        condition,
        source: format!("evflow import of {} ({})", src.display(), t.description),
    };
    Ok(Imported { meta, frames, notes, samples })
}

/// A mistake in the options for this source.
fn options_err(src: &Path, message: String) -> ImportError {
    ImportError::Options { path: src.to_path_buf(), message }
}

/// The channels' names and units, one per column of the source.
struct Labels {
    names: Vec<String>,
    units: Vec<String>,
}

impl Labels {
    /// Names from `--channels`, else the header (made into port names),
    /// else `ch0`, `ch1`, …, all different; units from `--units`, else the
    /// header, else none.
    fn of(src: &Path, t: &Columns, opts: &ImportOptions, notes: &mut Vec<String>) -> Result<Labels, ImportError> {
        let options = |message: String| options_err(src, message);
        let n = t.columns;
        let names: Vec<String> = match &opts.channels {
            Some(list) => {
                if list.len() != n {
                    return Err(options(format!(
                        "--channels lists {} name(s) but the file has {n} column(s)",
                        list.len()
                    )));
                }
                for name in list {
                    if !valid_name(name) {
                        return Err(ImportError::Usage(format!(
                            "--channels: `{name}` is not a valid channel name (letters, digits, `_`, `-`)"
                        )));
                    }
                }
                list.clone()
            }
            None => match &t.heads {
                Some(h) => h
                    .iter()
                    .enumerate()
                    .map(|(k, (raw, _))| {
                        let name = port_name(raw);
                        if name.is_empty() {
                            notes.push(format!("column {} has no usable name in the header: named ch{k}", k + 1));
                            format!("ch{k}")
                        } else {
                            if &name != raw {
                                notes.push(format!("header name `{raw}` written as channel `{name}`"));
                            }
                            name
                        }
                    })
                    .collect(),
                None => (0..n).map(|k| format!("ch{k}")).collect(),
            },
        };
        for (i, a) in names.iter().enumerate() {
            if let Some(j) = names[..i].iter().position(|b| b == a) {
                return Err(options(format!(
                    "columns {} and {} are both named `{a}`; name them with --channels",
                    j + 1,
                    i + 1
                )));
            }
        }
        let units: Vec<String> = match &opts.units {
            Some(list) if list.len() != n => {
                return Err(options(format!("--units lists {} unit(s) but the file has {n} column(s)", list.len())))
            }
            Some(list) => list.iter().map(|u| u.trim().to_string()).collect(),
            None => match &t.heads {
                Some(h) => h.iter().map(|(_, u)| u.clone()).collect(),
                None => vec![String::new(); n],
            },
        };
        Ok(Labels { names, units })
    }
}

/// The time column among the `n` (named `time` or `t`; at most one),
/// after checking the time tolerance.
fn time_column(src: &Path, names: &[String], n: usize, opts: &ImportOptions) -> Result<Option<usize>, ImportError> {
    let time: Vec<usize> = (0..n).filter(|&k| is_time_name(&names[k])).collect();
    if time.len() > 1 {
        return Err(options_err(
            src,
            format!(
                "columns {} are all time columns (named time or t); keep one, or rename the others with --channels",
                time.iter().map(|k| (k + 1).to_string()).collect::<Vec<_>>().join(", ")
            ),
        ));
    }
    let tol = opts.time_tolerance;
    if !(tol.is_finite() && (0.0..1.0).contains(&tol)) {
        return Err(ImportError::Usage(format!(
            "--time-tolerance {tol}: a fraction of the time step, at least 0 and below 1 (e.g. 0.01)"
        )));
    }
    Ok(time.first().copied())
}

/// The rate the time column `k` gives (with its name), when it has at
/// least two rows; its unit must be a unit of time.
fn inferred_rate(
    src: &Path,
    t: &Columns,
    k: usize,
    labels: &Labels,
    frames: usize,
    opts: &ImportOptions,
    notes: &mut Vec<String>,
) -> Result<Option<(f64, String)>, ImportError> {
    let (names, units) = (&labels.names, &labels.units);
    let scale = seconds_per(&units[k]).ok_or_else(|| {
        options_err(
            src,
            format!("time column `{}` has unit `{}`; give its times in s, ms, us or ns", names[k], units[k]),
        )
    })?;
    if frames < 2 {
        return Ok(None);
    }
    let rate = infer_rate(src, t, k, &names[k], scale, opts.time_tolerance)?;
    notes.push(format!("rate {rate} Hz from time column `{}`", names[k]));
    Ok(Some((rate, names[k].clone())))
}

/// The recording's rate: `--rate` (within the rates a recording may have,
/// and agreeing with a time column's), else the time column's; `text` and
/// `has_time` choose the hint when there is neither.
fn settle_rate(
    src: &Path,
    opts: &ImportOptions,
    inferred: Option<(f64, String)>,
    text: bool,
    has_time: bool,
) -> Result<f64, ImportError> {
    Ok(match (opts.rate, &inferred) {
        (Some(r), _) if !(r.is_finite() && r > 0.0) => {
            return Err(ImportError::Usage(format!("--rate {r}: not a positive number of Hz")))
        }
        (Some(r), _) if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&r) => {
            return Err(ImportError::Usage(format!(
                "--rate {}: outside the {} … {} Hz a recording may have for `recording.in` to play it",
                short(r),
                MIN_RATE_HZ,
                MAX_RATE_HZ
            )))
        }
        (Some(r), Some((i, name))) => {
            if (r - i).abs() > opts.time_tolerance * r {
                return Err(ImportError::RateDisagrees {
                    path: src.to_path_buf(),
                    given: r,
                    inferred: *i,
                    name: name.clone(),
                    tolerance_pct: opts.time_tolerance * 100.0,
                });
            }
            r
        }
        (Some(r), None) => r,
        (None, Some((i, _))) => *i,
        (None, None) => {
            let hint = match (text, has_time) {
                (_, true) => "the time column has a single row; give --rate HZ".to_string(),
                (true, false) => {
                    "give --rate HZ, or a time column in the header (`time [s]`, `t`, or named with --channels)".into()
                }
                (false, false) => {
                    "an .npy array holds none; give --rate HZ (or name a time column with --channels time,…)".into()
                }
            };
            return Err(ImportError::NoRate { path: src.to_path_buf(), hint });
        }
    })
}

/// Drops the time column `time` from the `n`-column rows unless
/// `--keep-time`, with its name and unit.
fn drop_time(
    src: &Path,
    samples: Vec<f64>,
    n: usize,
    time: Option<usize>,
    opts: &ImportOptions,
    labels: &mut Labels,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, ImportError> {
    let (Some(k), false) = (time, opts.keep_time) else { return Ok(samples) };
    if n == 1 {
        return Err(options_err(
            src,
            format!("the only column is the time column `{}`; there is nothing else to record", labels.names[k]),
        ));
    }
    let samples = samples
        .chunks_exact(n)
        .flat_map(|row| row.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, x)| *x))
        .collect();
    notes.push(format!("time column `{}` dropped (--keep-time keeps it)", labels.names[k]));
    labels.names.remove(k);
    labels.units.remove(k);
    Ok(samples)
}

/// The rate of a time column `k` (in units of `scale` seconds). Every step
/// must be within `tol` of the median step (the median, so that one gap
/// does not move the reference and the first irregular row is the one
/// named); the rate is then the least-squares slope over the whole
/// column, and within
/// 1e-6 of a whole number of Hz it is rounded to it (time stamps written in
/// decimal rarely give the exact rate back).
fn infer_rate(src: &Path, t: &Columns, k: usize, name: &str, scale: f64, tol: f64) -> Result<f64, ImportError> {
    let times: Vec<f64> = t.samples.iter().skip(k).step_by(t.columns).map(|x| x * scale).collect();
    let line = |i: usize| t.lines.as_ref().map_or(i + 1, |l| l[i]);
    let steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let mut sorted = steps.clone();
    let mid = sorted.len() / 2;
    let (_, median, _) = sorted.select_nth_unstable_by(mid, f64::total_cmp);
    let median = *median;
    for (i, &d) in steps.iter().enumerate() {
        if !(median > 0.0 && (d - median).abs() <= tol * median) {
            return Err(ImportError::IrregularTime {
                path: src.to_path_buf(),
                line: line(i + 1),
                previous: line(i),
                name: name.to_string(),
                step: d,
                expected: median,
                tolerance_pct: tol * 100.0,
            });
        }
    }
    // Least-squares slope of time against frame index: jitter at the two
    // ends weighs no more than anywhere else.
    let n = times.len() as f64;
    let (i_mean, t_mean) = ((n - 1.0) / 2.0, times.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, t) in times.iter().enumerate() {
        let di = i as f64 - i_mean;
        sxy += di * (t - t_mean);
        sxx += di * di;
    }
    let mean = sxy / sxx;
    let rate = 1.0 / mean;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(ImportError::Options {
            path: src.to_path_buf(),
            message: format!("time column `{name}` steps by {mean} s, which gives no usable rate"),
        });
    }
    if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
        return Err(ImportError::Options {
            path: src.to_path_buf(),
            message: format!(
                "time column `{name}` steps by {} s: {} Hz is outside the {} … {} Hz a recording may have \
                 for `recording.in` to play it (are the times in another unit? name it in the header, `t [ms]`)",
                short(mean),
                short(rate),
                MIN_RATE_HZ,
                MAX_RATE_HZ
            ),
        });
    }
    let whole = rate.round();
    Ok(if (rate - whole).abs() <= 1e-6 * rate { whole } else { rate })
}

/// `x` for a message: as Rust prints it, or in exponent form when that
/// would take hundreds of digits (1e308, 1e-300).
fn short(x: f64) -> String {
    if x != 0.0 && !(1e-6..1e12).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Seconds per unit of a time column: `s` (or none), `ms`, `us`/`µs`, `ns`.
fn seconds_per(unit: &str) -> Option<f64> {
    match unit.trim() {
        "" | "s" | "sec" => Some(1.0),
        "ms" => Some(1e-3),
        "us" | "µs" | "μs" => Some(1e-6),
        "ns" => Some(1e-9),
        _ => None,
    }
}

fn is_time_name(name: &str) -> bool {
    name.eq_ignore_ascii_case("time") || name.eq_ignore_ascii_case("t")
}

/// A valid channel (port) name: letters, digits, `_`, `-`.
fn valid_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// A header name as a port name: other characters become `_` (runs
/// collapsed, none at the ends). May be empty.
fn port_name(raw: &str) -> String {
    let mut out = String::new();
    for c in raw.trim().chars() {
        if c.is_ascii_alphanumeric() || c == '-' {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

/// Condition values must be finite; the load positive, the gain not
/// negative.
fn check_condition(c: &Condition) -> Result<(), String> {
    for (flag, v) in [("--load-g", c.load_g), ("--velocity-cm-s", c.velocity_cm_s), ("--gain", c.gain)] {
        if let Some(x) = v {
            if !x.is_finite() {
                return Err(format!("{flag} {x}: not a finite number"));
            }
        }
    }
    if let Some(x) = c.load_g.filter(|x| *x <= 0.0) {
        return Err(format!("--load-g {x}: a normal load is a positive number of grams"));
    }
    if let Some(x) = c.gain.filter(|x| *x < 0.0) {
        return Err(format!("--gain {x}: a display gain is not negative"));
    }
    if let Some(m) = c.material.as_ref().filter(|m| m.trim().is_empty()) {
        return Err(format!("--material `{m}`: empty"));
    }
    Ok(())
}
