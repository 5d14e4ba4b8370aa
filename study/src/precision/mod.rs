//! Error against run time of every computation with a tolerance or a
//! discretization (issue 26, point 2; `evflow report precision`): each a
//! work-precision [`Curve`] of settings against a reference that is exact
//! or an order of magnitude more precise, with its shipped default marked,
//! and one summary [`table::Row`] — the default's error and cost, and the
//! cheapest setting within 10 % of the best error.
//!
//! The computations reuse the code of the reports and studies that drew
//! them first (`report resample`, `foaw`, `mesh`, `narx`, the texture and
//! live studies, the graph `lab-work-precision.toml`); graphs run through
//! [`crate::graphs`] with typed values.

pub mod butterworth;
pub mod curve;
pub mod decimate;
pub mod foaw;
#[cfg(feature = "lab")]
pub mod integrators;
#[cfg(feature = "mesh")]
pub mod live_mesh;
#[cfg(feature = "synth")]
pub mod live_texture;
#[cfg(feature = "mesh")]
pub mod mesh;
#[cfg(feature = "synth")]
pub mod narx;
#[cfg(feature = "synth")]
pub mod optimize;
#[cfg(feature = "texture")]
pub mod resample;
pub mod table;
#[cfg(feature = "synth")]
pub mod volterra;

pub use curve::{Curve, WorkPoint};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// How much each curve measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Size {
    /// Few settings and short signals: the whole report in seconds (tests, CI).
    Ci,
    /// Every setting, full-length signals, the best of several timed runs.
    Full,
}

impl Size {
    /// From `ci` or `full`.
    pub fn from_word(w: &str) -> Option<Self> {
        match w {
            "ci" => Some(Size::Ci),
            "full" => Some(Size::Full),
            _ => None,
        }
    }

    /// Timed runs per setting (the fastest is kept).
    pub fn repeats(self) -> usize {
        match self {
            Size::Ci => 1,
            Size::Full => 5,
        }
    }
}

/// Why a curve could not be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PrecisionError {
    /// A method refused its setting.
    #[error("{0}")]
    Method(String),
    /// A graph could not be loaded or run.
    #[error(transparent)]
    Graph(#[from] crate::graphs::GraphError),
    /// A study the curve runs failed.
    #[error("{0}")]
    Study(String),
    /// `--only` named no computation.
    #[error("no computation `{0}`; the computations are: {list}", list = names().join(", "))]
    Unknown(String),
}

/// The computations, in the report's order. Each gives one curve, except
/// `lab`, which gives one per lab node, and `optimize`, one per lab profile.
pub fn names() -> Vec<&'static str> {
    let mut v = Vec::new();
    #[cfg(feature = "lab")]
    v.push("lab");
    v.extend(["butterworth", "decimate"]);
    #[cfg(feature = "texture")]
    v.extend(["resample", "interp-kernel"]);
    v.push("foaw");
    #[cfg(feature = "mesh")]
    v.push("mesh-gradient");
    #[cfg(feature = "synth")]
    v.extend(["volterra-memory", "optimize", "narx", "live-texture"]);
    #[cfg(feature = "mesh")]
    v.push("live-mesh");
    v
}

/// Measures computation `name` (one of [`names`]); `graphs` is the folder
/// of the shipped graphs.
pub fn run(name: &str, graphs: &Path, size: Size) -> Result<Vec<Curve>, PrecisionError> {
    // Absolute: the graphs' own paths (recordings, models) are relative to their files.
    // (Only the lab, synth and mesh families' computations run graphs.)
    #[cfg_attr(not(any(feature = "lab", feature = "synth", feature = "mesh")), allow(unused_variables))]
    let graphs = &std::fs::canonicalize(graphs)
        .map_err(|e| PrecisionError::Study(format!("the graphs folder {}: {e}", graphs.display())))?;
    match name {
        #[cfg(feature = "lab")]
        "lab" => integrators::curves(graphs, size),
        "butterworth" => Ok(vec![butterworth::curve(size)?]),
        "decimate" => Ok(vec![decimate::curve(size)?]),
        #[cfg(feature = "texture")]
        "resample" => Ok(vec![resample::curve(size)?]),
        #[cfg(feature = "texture")]
        "interp-kernel" => Ok(vec![resample::interp_curve(size)?]),
        "foaw" => Ok(vec![foaw::curve(size)?]),
        #[cfg(feature = "mesh")]
        "mesh-gradient" => Ok(vec![mesh::curve(size)?]),
        #[cfg(feature = "synth")]
        "volterra-memory" => Ok(vec![volterra::curve(size)?]),
        #[cfg(feature = "synth")]
        "optimize" => optimize::curves(graphs, size),
        #[cfg(feature = "synth")]
        "narx" => Ok(vec![narx::curve(graphs, size)?]),
        #[cfg(feature = "synth")]
        "live-texture" => Ok(vec![live_texture::curve(graphs, size)?]),
        #[cfg(feature = "mesh")]
        "live-mesh" => Ok(vec![live_mesh::curve(graphs, size)?]),
        other => Err(PrecisionError::Unknown(other.to_string())),
    }
}

/// The fastest of `repeats` (at least one) runs of `f`, s.
pub fn time_best(repeats: usize, mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    best
}

/// A folder for a curve's work files under the system's temporary folder,
/// removed with everything in it when dropped.
#[derive(Debug)]
pub struct Scratch(PathBuf);

impl Scratch {
    /// A new empty folder, its name starting with `what`.
    pub fn new(what: &str) -> Result<Self, PrecisionError> {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.subsec_nanos());
        let dir = std::env::temp_dir().join(format!("evflow-precision-{what}-{}-{n}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| PrecisionError::Study(format!("{}: {e}", dir.display())))?;
        Ok(Self(dir))
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
