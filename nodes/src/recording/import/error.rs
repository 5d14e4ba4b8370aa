//! Why an import failed ([`ImportError`]), shared by the readers of each
//! source format and the import itself.

use super::super::format::RecordingError;
use std::path::PathBuf;

/// Why an import failed. Every message starts with the file it concerns
/// (the source, or for writing the destination), and for delimited text
/// with the line (`force.csv:12: …`).
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The source could not be read, or a destination folder not created.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// The source's extension is not one evflow imports.
    #[error("{}: cannot import {what}; evflow import reads .npy (NumPy) and .csv, .tsv or .txt (delimited text)", path.display())]
    UnsupportedKind {
        /// The source.
        path: PathBuf,
        /// The kind found, in words (`a .xlsx file`, `a file without an extension`).
        what: String,
    },
    /// A MATLAB `.mat` file.
    #[error(
        "{}: MATLAB .mat files are not read (docs/rig.md says why); in MATLAB write the columns as CSV, e.g. \
         writematrix([t force u], 'NAME.csv') with a header via writetable, then `evflow import NAME.csv`",
        path.display()
    )]
    Mat {
        /// The source.
        path: PathBuf,
    },
    /// A NumPy `.npz` archive.
    #[error("{}: .npz archives are not read; save the array with np.save('NAME.npy', arr) and import that", path.display())]
    Npz {
        /// The source.
        path: PathBuf,
    },
    /// The `.npy` file is malformed or holds an array evflow cannot take.
    #[error("{}: not an importable .npy file: {message}", path.display())]
    Npy {
        /// The source.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A line of delimited text is malformed.
    #[error("{}:{line}: {message}", path.display())]
    Text {
        /// The source.
        path: PathBuf,
        /// Line number, from 1.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A cell of delimited text is not a finite number.
    #[error("{}:{line}: column {column}{}: {message}", path.display(), name.as_ref().map(|n| format!(" (`{n}`)")).unwrap_or_default())]
    Cell {
        /// The source.
        path: PathBuf,
        /// Line number, from 1.
        line: usize,
        /// Column number, from 1.
        column: usize,
        /// The column's name in the header, if any.
        name: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A sample of an `.npy` array is NaN or infinite.
    #[error("{}: column {channel} (from 0) frame {frame} is {what}; a recording holds finite samples", path.display())]
    NonFinite {
        /// The source.
        path: PathBuf,
        /// The column, from 0.
        channel: usize,
        /// The frame (row), from 0.
        frame: u64,
        /// `NaN`, `+Inf` or `-Inf`.
        what: &'static str,
    },
    /// The source holds no samples.
    #[error("{}: holds no samples: {what}", path.display())]
    Empty {
        /// The source.
        path: PathBuf,
        /// What it holds instead.
        what: String,
    },
    /// No rate was given and none could be inferred.
    #[error("{}: no sample rate: {hint}", path.display())]
    NoRate {
        /// The source.
        path: PathBuf,
        /// Where a rate could come from, for this kind of file.
        hint: String,
    },
    /// The time column's steps are not uniform.
    #[error(
        "{}:{line}: time column `{name}` steps by {step} s here (from line {previous}), where a uniform rate \
         needs {expected} s (the median step) ± {tolerance_pct} %; a recording has one fixed rate: resample the data first, or \
         widen the tolerance (--time-tolerance) if the time stamps only jitter",
        path.display()
    )]
    IrregularTime {
        /// The source.
        path: PathBuf,
        /// Line (or, for `.npy`, frame from 1) of the first irregular step.
        line: usize,
        /// Line of the row before it.
        previous: usize,
        /// The time column's name.
        name: String,
        /// The step found, in seconds.
        step: f64,
        /// The median step, in seconds.
        expected: f64,
        /// The tolerance, in percent of the mean step.
        tolerance_pct: f64,
    },
    /// The given rate and the time column disagree.
    #[error(
        "{}: --rate {given} Hz disagrees with the {inferred} Hz of time column `{name}` (more than {tolerance_pct} % apart)",
        path.display()
    )]
    RateDisagrees {
        /// The source.
        path: PathBuf,
        /// The rate given.
        given: f64,
        /// The rate from the time column.
        inferred: f64,
        /// The time column's name.
        name: String,
        /// The tolerance, in percent.
        tolerance_pct: f64,
    },
    /// The options do not fit the source (channel or unit count, a name, a
    /// condition value, the rate).
    #[error("{}: {message}", path.display())]
    Options {
        /// The source.
        path: PathBuf,
        /// What does not fit.
        message: String,
    },
    /// A `--condition key=value` (or another option) is malformed.
    #[error("{0}")]
    Usage(String),
    /// The destination holds a recording already.
    #[error("{}: already exists; give --force to replace it, or another --out", path.display())]
    Exists {
        /// The existing file.
        path: PathBuf,
    },
    /// Writing the recording failed (the message names the destination);
    /// nothing was left there.
    #[error(transparent)]
    Write(#[from] RecordingError),
    /// The import was stopped (Ctrl-C, SIGTERM) while writing; nothing was
    /// left at the destination.
    #[error("{}: import interrupted; nothing was written", path.display())]
    Interrupted {
        /// The destination's `NAME.wav`.
        path: PathBuf,
    },
}

/// `NaN`, `+Inf` or `-Inf`.
pub(super) fn non_finite_word(x: f64) -> &'static str {
    if x.is_nan() {
        "NaN"
    } else if x > 0.0 {
        "+Inf"
    } else {
        "-Inf"
    }
}
