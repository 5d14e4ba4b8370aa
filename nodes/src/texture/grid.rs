//! The (load, velocity) grid of actuation signals U_ij (dissertation
//! Fig. 5.6, Fig. 6.7), loaded from recordings.
//!
//! Each cell is one recording (`docs/recording-format.md`) whose sidecar
//! names its condition: `condition.load_g` (m_i) and
//! `condition.velocity_cm_s` (v_j). The grid's axes are the distinct loads
//! and velocities found. Only the sidecars of every candidate are read at
//! first; the samples are loaded only for the cells a session can reach —
//! the cells that bracket the declared load and velocity ranges after the
//! clamping of §6.4 — so a session confined to 60–85 g never opens the
//! 110 g recordings.
//!
//! Every reachable cell must exist: a missing one is an error naming the
//! condition and what was found, as are duplicates, a condition without load
//! or velocity, a non-positive velocity, and cells at different rates.
//!
//! A cell may declare `condition.carrier = "nyquist"`: its actuation rides
//! a Nyquist-rate carrier, u\[n\] = (−1)ⁿ·a\[n\] with a slowly varying
//! envelope a (the optimized synthesis' cells, docs/synthesis.md). The
//! grid records it ([`Grid::carrier`]); every reachable cell must agree.
//!
//! A grid may be declared a grid of **forces** ([`Expect::Force`]: what a
//! chain that renders the texture's force through `synth.live` reads).
//! Each reachable cell must then hold newtons (its channel's unit `N`) and
//! no offset that the 10 Hz high-pass of §5.1.1 would have removed
//! ([`offset_ratio`] at most [`OFFSET_RATIO_MAX`]): the force as the sensor
//! measured it (friction and bias, 0.1–0.45 N) or an actuation grid
//! (`narx-SAMPLE`, unit `1`) is refused with the command that makes a
//! proper one.

use crate::recording::format::{Recording, RecordingPaths};
use std::path::{Path, PathBuf};

/// What can be wrong with a grid. Every message names the file or folder.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// The folder cannot be listed.
    #[error("{}: cannot list the grid folder: {message}", path.display())]
    Folder {
        /// The folder.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// No recording was found.
    #[error("{where_}: no recording with a load and velocity condition{filter}; a grid cell is a recording whose sidecar sets condition.load_g and condition.velocity_cm_s")]
    Empty {
        /// Folder or list.
        where_: String,
        /// The material filter, if any.
        filter: String,
    },
    /// A sidecar cannot be read or lacks a condition.
    #[error("{}: {message}", path.display())]
    Sidecar {
        /// The sidecar.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Two recordings claim one cell.
    #[error("{} and {} both hold the cell load {load} g, velocity {velocity} cm/s; keep one", a.display(), b.display())]
    Duplicate {
        /// First recording.
        a: PathBuf,
        /// Second recording.
        b: PathBuf,
        /// Load in g.
        load: f64,
        /// Velocity in cm/s.
        velocity: f64,
    },
    /// A cell the session can reach has no recording.
    #[error("{where_}: the grid cell load {load} g, velocity {velocity} cm/s is missing (loads {loads:?} g × velocities {velocities:?} cm/s were found, {found} of {total} reachable cells present); record or synthesize it, or narrow load_range/velocity_range")]
    MissingCell {
        /// Folder or list.
        where_: String,
        /// Missing load in g.
        load: f64,
        /// Missing velocity in cm/s.
        velocity: f64,
        /// The load axis.
        loads: Vec<f64>,
        /// The velocity axis.
        velocities: Vec<f64>,
        /// Reachable cells present.
        found: usize,
        /// Reachable cells in all.
        total: usize,
    },
    /// Cells that disagree on their carrier, or a carrier not known.
    #[error("{}: {message}", path.display())]
    Carrier {
        /// The sidecar.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Cells at different sample rates.
    #[error("{}: recorded at {rate} Hz but {} at {first} Hz; every grid cell must have one rate", path.display(), first_path.display())]
    Rate {
        /// The odd one.
        path: PathBuf,
        /// Its rate.
        rate: f64,
        /// The first cell.
        first_path: PathBuf,
        /// The first cell's rate.
        first: f64,
    },
    /// The recording itself is unreadable.
    #[error("{0}")]
    Recording(String),
    /// A cell of a grid of forces that holds no proper force ([`Expect::Force`]).
    #[error("{}: {message}; {}", path.display(), FORCES_FIX)]
    NotForce {
        /// The sidecar.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// How a refused grid of forces is made properly (the end of every
/// [`GridError::NotForce`] message).
pub const FORCES_FIX: &str =
    "a force-rendering chain (synth.live) needs a forces-SAMPLE folder: the force in newtons, \
     high-passed at 10 Hz, over constant-speed stretches — `evflow library from-recordings --excitation DIR \
     --textures DIR --out LIB` makes LIB/forces-SAMPLE from a lab's recordings as the sensor measured them \
     (docs/rig.md), `evflow library build` on the simulated lab";

/// What the cells of a grid must be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Expect {
    /// Anything (actuation or force; no check).
    #[default]
    Any,
    /// Forces: unit `N`, no offset ([`offset_ratio`] ≤ [`OFFSET_RATIO_MAX`]).
    Force,
}

/// Window of [`offset_ratio`]'s slow part, s.
pub const OFFSET_WINDOW_S: f64 = 0.25;

/// The largest [`offset_ratio`] of a cell in a grid of forces. On the
/// simulated lab's five profiles × ten samples (the seven of §5.3 and
/// generated-1…3) × the 3×3 grid, the forces high-passed at 10 Hz over
/// their constant-speed stretch (what `evflow library build` writes) reach
/// at most 0.079, and the same stretches of the raw force (friction and
/// sensor bias, as measured) at least 2.30: 0.4 is about 5× from both.
pub const OFFSET_RATIO_MAX: f64 = 0.4;

/// How much of `x` (sampled at `rate` Hz) is an offset: the rms of its
/// means over consecutive windows of [`OFFSET_WINDOW_S`] (the last window
/// takes the remainder; a signal shorter than one window is one window)
/// over the rms of its variation around them. A force high-passed at
/// 10 Hz has almost nothing below 4 Hz, so its window means are small
/// beside its variation; a raw force's offset — one sign per stroke
/// direction, so stretches of both directions are caught too — is many
/// times its variation. 0 for a signal with no slow part; infinite for a
/// constant non-zero one (or all but rounding).
pub fn offset_ratio(x: &[f64], rate: f64) -> f64 {
    let n = x.len();
    if n == 0 {
        return 0.0;
    }
    let w = ((OFFSET_WINDOW_S * rate).round() as usize).clamp(1, n);
    let windows = n / w;
    let (mut slow, mut fast) = (0.0, 0.0);
    for k in 0..windows {
        let end = if k + 1 == windows { n } else { (k + 1) * w };
        let seg = &x[k * w..end];
        let m = seg.iter().sum::<f64>() / seg.len() as f64;
        slow += seg.len() as f64 * m * m;
        fast += seg.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    }
    if slow == 0.0 {
        0.0
    } else {
        (slow / fast).sqrt()
    }
}

/// Checks a cell of a grid of forces: `unit` is its channel's, `samples` its samples.
fn check_force(path: &Path, channel: &str, unit: &str, samples: &[f64], rate: f64) -> Result<(), GridError> {
    let json = RecordingPaths::new(path).json;
    if unit != "N" {
        let shown = if unit.is_empty() { "no unit".to_string() } else { format!("unit `{unit}`") };
        return Err(GridError::NotForce {
            path: json,
            message: format!(
                "channel `{channel}` has {shown}, not `N`: not a force (an actuation grid such as narx-SAMPLE \
                 holds unit `1`)"
            ),
        });
    }
    let ratio = offset_ratio(samples, rate);
    if ratio > OFFSET_RATIO_MAX {
        let mean = samples.iter().sum::<f64>() / samples.len().max(1) as f64;
        return Err(GridError::NotForce {
            path: json,
            message: format!(
                "the force carries an offset (mean {mean:.3} N): its {OFFSET_WINDOW_S} s means are {ratio:.2} \
                 times its variation around them, where a force high-passed at 10 Hz stays below \
                 {OFFSET_RATIO_MAX} — the force as the sensor measured it (friction, bias), which would play a \
                 saturated carrier"
            ),
        });
    }
    Ok(())
}

/// One candidate cell: its condition and files, samples not yet loaded.
#[derive(Debug, Clone)]
pub struct CellInfo {
    /// The recording (as named by the user or found in the folder).
    pub path: PathBuf,
    /// m_i in g.
    pub load: f64,
    /// v_j in cm/s.
    pub velocity: f64,
    /// Sample rate in Hz.
    pub rate: f64,
    /// Channel names.
    pub channels: Vec<String>,
    /// Channel units, in the order of `channels` (empty when unknown).
    pub units: Vec<String>,
    /// Display gain of the condition (1 when absent).
    pub gain: f64,
    /// Whether the cell rides a Nyquist-rate carrier (`condition.carrier`).
    pub carrier: bool,
}

/// Where to find the cells and which to use.
#[derive(Debug, Clone, Default)]
pub struct GridSource {
    /// A folder: every `*.json` sidecar in it is a candidate.
    pub folder: Option<PathBuf>,
    /// Or explicit recordings.
    pub paths: Vec<PathBuf>,
    /// Keep only this material (`condition.material`); empty keeps all.
    pub material: String,
    /// The channel holding U_ij; empty means the recording's only channel.
    pub channel: String,
    /// Loads a session can reach, g (`[lo, hi]`); `None` = all.
    pub load_range: Option<(f64, f64)>,
    /// Velocities a session can reach, cm/s; `None` = all.
    pub velocity_range: Option<(f64, f64)>,
    /// Multiply each cell by its condition's display gain.
    pub apply_gain: bool,
    /// What the cells must be (a grid of forces is checked).
    pub expect: Expect,
}

/// The loaded grid: axes ascending, cells row-major (load, then velocity).
#[derive(Debug, Clone)]
pub struct Grid {
    /// m_i, g, ascending (only the reachable ones).
    pub loads: Vec<f64>,
    /// v_j, cm/s, ascending (only the reachable ones).
    pub velocities: Vec<f64>,
    /// Sample rate of every cell, Hz.
    pub rate: f64,
    /// U_ij, `cells[i * velocities.len() + j]`.
    pub cells: Vec<Vec<f64>>,
    /// The recordings, in the order of `cells`.
    pub paths: Vec<PathBuf>,
    /// Whether the cells ride a Nyquist-rate carrier, u\[n\] = (−1)ⁿ·a\[n\]
    /// (their sidecars' `condition.carrier = "nyquist"`).
    pub carrier: bool,
}

impl Grid {
    /// U_ij.
    pub fn cell(&self, i: usize, j: usize) -> &[f64] {
        &self.cells[i * self.velocities.len() + j]
    }

    /// Builds a grid from signals in memory (tests, tools): `cells[i][j]`
    /// is U_ij at `rate`.
    pub fn from_signals(loads: Vec<f64>, velocities: Vec<f64>, rate: f64, cells: Vec<Vec<Vec<f64>>>) -> Self {
        let paths = vec![PathBuf::new(); loads.len() * velocities.len()];
        Self { loads, velocities, rate, cells: cells.into_iter().flatten().collect(), paths, carrier: false }
    }

    /// Loads the reachable part of the grid described by `src`.
    pub fn load(src: &GridSource) -> Result<Self, GridError> {
        let (where_, candidates) = list_candidates(src)?;
        let mut cells: Vec<CellInfo> = Vec::new();
        for path in candidates {
            if let Some(c) = read_cell(&path, src.folder.is_some())? {
                if !src.material.is_empty() && c.material.as_deref() != Some(src.material.as_str()) {
                    continue;
                }
                cells.push(c.info);
            }
        }
        if cells.is_empty() {
            let filter =
                if src.material.is_empty() { String::new() } else { format!(" of material `{}`", src.material) };
            return Err(GridError::Empty { where_, filter });
        }
        let loads = axis(cells.iter().map(|c| c.load));
        let velocities = axis(cells.iter().map(|c| c.velocity));
        let at = slots(&cells, &loads, &velocities)?;
        let (i0, i1) = reachable(&loads, src.load_range);
        let (j0, j1) = reachable(&velocities, src.velocity_range);
        check_complete(&at, &loads, &velocities, (i0, i1), (j0, j1), where_)?;
        let mut grid = Grid {
            loads: loads[i0..=i1].to_vec(),
            velocities: velocities[j0..=j1].to_vec(),
            rate: 0.0,
            cells: Vec::new(),
            paths: Vec::new(),
            carrier: false,
        };
        let mut first: Option<&CellInfo> = None;
        for i in i0..=i1 {
            for j in j0..=j1 {
                let Some(k) = at[i * velocities.len() + j] else { continue };
                let c = &cells[k];
                match first {
                    None => first = Some(c),
                    Some(f) => check_agrees(c, f)?,
                }
                grid.cells.push(cell_samples(c, src)?);
                grid.paths.push(c.path.clone());
            }
        }
        grid.rate = first.map(|c| c.rate).unwrap_or(0.0);
        grid.carrier = first.is_some_and(|c| c.carrier);
        Ok(grid)
    }
}

/// Where each cell sits on the (load, velocity) axes: `slots[i · velocities + j]`
/// is the index in `cells` of the cell at load i and velocity j; two cells
/// at one condition are an error.
fn slots(cells: &[CellInfo], loads: &[f64], velocities: &[f64]) -> Result<Vec<Option<usize>>, GridError> {
    let index = |axis: &[f64], x: f64| axis.iter().position(|a| same(*a, x)).unwrap_or(0);
    let mut at: Vec<Option<usize>> = vec![None; loads.len() * velocities.len()];
    for (k, c) in cells.iter().enumerate() {
        let slot = index(loads, c.load) * velocities.len() + index(velocities, c.velocity);
        if let Some(prev) = at[slot] {
            return Err(GridError::Duplicate {
                a: cells[prev].path.clone(),
                b: c.path.clone(),
                load: c.load,
                velocity: c.velocity,
            });
        }
        at[slot] = Some(k);
    }
    Ok(at)
}

/// Every cell of the reachable rectangle (loads `i0..=i1`, velocities
/// `j0..=j1`) is there; the error names the first missing one.
fn check_complete(
    at: &[Option<usize>],
    loads: &[f64],
    velocities: &[f64],
    (i0, i1): (usize, usize),
    (j0, j1): (usize, usize),
    where_: String,
) -> Result<(), GridError> {
    let total = (i1 - i0 + 1) * (j1 - j0 + 1);
    let found = (i0..=i1)
        .flat_map(|i| (j0..=j1).map(move |j| (i, j)))
        .filter(|(i, j)| at[i * velocities.len() + j].is_some())
        .count();
    for i in i0..=i1 {
        for j in j0..=j1 {
            if at[i * velocities.len() + j].is_none() {
                return Err(GridError::MissingCell {
                    where_,
                    load: loads[i],
                    velocity: velocities[j],
                    loads: loads.to_vec(),
                    velocities: velocities.to_vec(),
                    found,
                    total,
                });
            }
        }
    }
    Ok(())
}

/// Cell `c` agrees with the grid's `first` cell on its rate and carrier.
fn check_agrees(c: &CellInfo, first: &CellInfo) -> Result<(), GridError> {
    if !same(first.rate, c.rate) {
        return Err(GridError::Rate {
            path: c.path.clone(),
            rate: c.rate,
            first_path: first.path.clone(),
            first: first.rate,
        });
    }
    if first.carrier != c.carrier {
        let says = |x: bool| if x { "rides a Nyquist-rate carrier" } else { "has no carrier" };
        return Err(GridError::Carrier {
            path: RecordingPaths::new(&c.path).json,
            message: format!(
                "{} but {} {}; every cell of a grid must agree (condition.carrier)",
                says(c.carrier),
                first.path.display(),
                says(first.carrier)
            ),
        });
    }
    Ok(())
}

/// The samples of cell `c`'s channel: checked as a force when `src`
/// expects one, times the condition's gain when it applies it.
fn cell_samples(c: &CellInfo, src: &GridSource) -> Result<Vec<f64>, GridError> {
    let channel = pick_channel(c, &src.channel)?;
    let rec =
        Recording::open_channels(&c.path, &[channel.as_str()]).map_err(|e| GridError::Recording(e.to_string()))?;
    rec.require_complete().map_err(|e| GridError::Recording(e.to_string()))?;
    let mut samples = rec.into_channels().remove(0);
    if src.expect == Expect::Force {
        let unit = c.channels.iter().position(|n| *n == channel).map_or("", |k| c.units[k].as_str());
        check_force(&c.path, &channel, unit, &samples, c.rate)?;
    }
    if src.apply_gain {
        samples.iter_mut().for_each(|x| *x *= c.gain);
    }
    Ok(samples)
}

/// Equal within 1e-9 relative (conditions written by different tools).
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

/// Distinct values, ascending.
fn axis(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| same(*a, *b));
    v
}

/// The index range of `axis` a session confined to `range` can touch:
/// from the lower bracket of the clamped low end to the upper bracket of
/// the clamped high end.
pub fn reachable(axis: &[f64], range: Option<(f64, f64)>) -> (usize, usize) {
    let last = axis.len() - 1;
    let Some((lo, hi)) = range else { return (0, last) };
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    let i0 = axis.iter().rposition(|a| *a <= lo).unwrap_or(0);
    let i1 = axis.iter().position(|a| *a >= hi).unwrap_or(last);
    (i0.min(i1), i1.max(i0))
}

/// The system's message for a grid folder that cannot be listed, and,
/// when it does not exist, the folders beside it of the same kind (the
/// name's part before its first `-`, e.g. `forces-`) with the nearest
/// named: `sample=felt` finds `forces-felt-fabric`.
fn missing_folder(folder: &Path, e: &std::io::Error) -> String {
    let message = e.to_string();
    if e.kind() != std::io::ErrorKind::NotFound {
        return message;
    }
    let (Some(parent), Some(name)) = (folder.parent(), folder.file_name().and_then(|n| n.to_str())) else {
        return message;
    };
    let kind = name.split_once('-').map_or(name, |(k, _)| k);
    let Ok(rd) = std::fs::read_dir(if parent.as_os_str().is_empty() { Path::new(".") } else { parent }) else {
        return message;
    };
    let mut beside: Vec<String> = rd
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| n.split_once('-').is_some_and(|(k, _)| k == kind))
        .collect();
    if beside.is_empty() {
        return message;
    }
    beside.sort();
    let help = evflow_engine::suggest::help(name, beside.iter().map(String::as_str));
    format!("{message}; the {kind}-* folders beside it are {}: {help}", beside.join(", "))
}

fn list_candidates(src: &GridSource) -> Result<(String, Vec<PathBuf>), GridError> {
    if let Some(folder) = &src.folder {
        let rd = std::fs::read_dir(folder)
            .map_err(|e| GridError::Folder { path: folder.clone(), message: missing_folder(folder, &e) })?;
        let mut v: Vec<PathBuf> = rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("json"))
            .collect();
        v.sort();
        Ok((folder.display().to_string(), v))
    } else {
        let where_ = match src.paths.first() {
            Some(p) => format!("the grid list ({} recordings, first {})", src.paths.len(), p.display()),
            None => "the grid list (empty)".into(),
        };
        Ok((where_, src.paths.clone()))
    }
}

struct Candidate {
    info: CellInfo,
    material: Option<String>,
}

/// Reads a sidecar. In a folder a sidecar without a condition is skipped
/// (it is not a grid cell); in an explicit list it is an error.
fn read_cell(path: &Path, lenient: bool) -> Result<Option<Candidate>, GridError> {
    let paths = RecordingPaths::new(path);
    let bad = |message: String| GridError::Sidecar { path: paths.json.clone(), message };
    let text = evflow_engine::files::read_regular_to_string(&paths.json).map_err(|e| {
        bad(if e.kind() == std::io::ErrorKind::NotFound { "no such recording sidecar".into() } else { e.to_string() })
    })?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    if v.get("format").and_then(|f| f.as_str()) != Some(crate::recording::format::FORMAT_NAME) {
        if lenient {
            return Ok(None);
        }
        return Err(bad("not an evflow recording sidecar".into()));
    }
    let cond = v.get("condition");
    let num = |k: &str| cond.and_then(|c| c.get(k)).and_then(|x| x.as_f64());
    let (load, velocity) = match (num("load_g"), num("velocity_cm_s")) {
        (Some(l), Some(v)) => (l, v),
        _ if lenient => return Ok(None),
        _ => return Err(bad("the condition lacks load_g or velocity_cm_s, so it is no grid cell".into())),
    };
    if !(load.is_finite() && velocity.is_finite() && velocity > 0.0) {
        return Err(bad(format!("condition load {load} g, velocity {velocity} cm/s: a grid cell needs a finite load and a positive velocity")));
    }
    let rate = v.get("rate").and_then(|r| r.as_f64()).unwrap_or(0.0);
    let listed: Vec<(String, String)> = v
        .get("channels")
        .and_then(|c| c.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|c| {
                    let name = c.get("name").and_then(|n| n.as_str())?;
                    Some((name.to_string(), c.get("unit").and_then(|u| u.as_str()).unwrap_or("").to_string()))
                })
                .collect()
        })
        .unwrap_or_default();
    let (channels, units) = listed.into_iter().unzip();
    let gain = num("gain").unwrap_or(1.0);
    let material = cond.and_then(|c| c.get("material")).and_then(|m| m.as_str()).map(String::from);
    let carrier = match cond.and_then(|c| c.get("carrier")) {
        None => false,
        Some(c) => match c.as_str() {
            Some("nyquist") => true,
            Some("none") => false,
            _ => {
                return Err(GridError::Carrier {
                    path: paths.json.clone(),
                    message: format!("condition.carrier is {c}; give \"nyquist\" or \"none\""),
                })
            }
        },
    };
    Ok(Some(Candidate {
        info: CellInfo { path: paths.wav, load, velocity, rate, channels, units, gain, carrier },
        material,
    }))
}

fn pick_channel(c: &CellInfo, wanted: &str) -> Result<String, GridError> {
    if !wanted.is_empty() {
        return Ok(wanted.to_string());
    }
    match c.channels.as_slice() {
        [one] => Ok(one.clone()),
        many => Err(GridError::Sidecar {
            path: RecordingPaths::new(&c.path).json,
            message: format!(
                "has {} channels ({}); set `channel` to the one holding the actuation signal",
                many.len(),
                many.join(", ")
            ),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_grid_folder_names_the_folders_of_its_kind_and_the_nearest() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["forces-felt-fabric", "forces-plastic-sheet", "narx-felt-fabric"] {
            std::fs::create_dir(dir.path().join(f)).unwrap();
        }
        let missing = dir.path().join("forces-felt");
        let e = std::fs::read_dir(&missing).unwrap_err();
        let m = missing_folder(&missing, &e);
        assert!(m.contains("forces-felt-fabric, forces-plastic-sheet") && !m.contains("narx"), "{m}");
        assert!(m.ends_with("did you mean `forces-felt-fabric`?"), "{m}");
        // Nothing of its kind beside it: the system's message alone.
        let other = dir.path().join("cells-x");
        let e = std::fs::read_dir(&other).unwrap_err();
        assert_eq!(missing_folder(&other, &e), e.to_string());
    }

    #[test]
    fn reachable_cells_bracket_the_clamped_range() {
        let v = [3.0, 4.0, 5.0, 6.0, 7.0];
        assert_eq!(reachable(&v, None), (0, 4));
        assert_eq!(reachable(&v, Some((3.5, 4.5))), (0, 2));
        assert_eq!(reachable(&v, Some((4.0, 5.0))), (1, 2));
        assert_eq!(reachable(&v, Some((0.0, 1.0))), (0, 0));
        assert_eq!(reachable(&v, Some((9.0, 20.0))), (4, 4));
        assert_eq!(reachable(&[85.0], Some((60.0, 110.0))), (0, 0));
    }

    /// `n` samples at 1 kHz of a texture-like variation (20 and 37 Hz, 0.03 N
    /// rms in all) plus `offset(t)`.
    fn force(n: usize, offset: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 / 1000.0;
                let tau = std::f64::consts::TAU;
                0.03 * ((tau * 20.0 * t).sin() + (tau * 37.0 * t + 1.0).sin()) + offset(t)
            })
            .collect()
    }

    #[test]
    fn the_offset_ratio_is_the_slow_part_over_the_variation() {
        // No offset: the 250 ms means of 20 and 37 Hz sines are small.
        let r = offset_ratio(&force(2500, |_| 0.0), 1000.0);
        assert!(r < 0.05, "{r}");
        // A constant offset of 0.3 N over 0.03 N rms of variation: 10.
        let r = offset_ratio(&force(2500, |_| 0.3), 1000.0);
        assert!((r - 10.0).abs() < 0.5, "{r}");
        // Friction of each stroke direction: ±0.3 N per 1 s stretch, mean 0 over the cell.
        let both = force(2000, |t| if t < 1.0 { 0.3 } else { -0.3 });
        let r = offset_ratio(&both, 1000.0);
        assert!((r - 10.0).abs() < 0.5, "{r}");
        // Edge cases: nothing, silence, a constant, a cell shorter than one window.
        assert_eq!(offset_ratio(&[], 1000.0), 0.0);
        assert_eq!(offset_ratio(&[0.0; 100], 1000.0), 0.0);
        assert!(offset_ratio(&[0.2; 100], 1000.0) > 1e6);
        assert!(offset_ratio(&force(100, |_| 0.3), 1000.0) > 5.0);
    }

    /// Writes a one-channel cell `u-TAG` with `unit` into `dir`.
    fn cell(dir: &Path, tag: &str, load: f64, velocity: f64, unit: &str, samples: &[f64]) {
        use crate::recording::format::{Channel, RecordingMeta, RecordingWriter};
        let mut meta = RecordingMeta::new(1000.0, vec![Channel::new("u", unit)]);
        meta.condition.load_g = Some(load);
        meta.condition.velocity_cm_s = Some(velocity);
        let mut w = RecordingWriter::create(&dir.join(format!("u-{tag}")), meta).unwrap();
        w.write_interleaved(samples).unwrap();
        w.finish().unwrap();
    }

    fn forces(dir: &Path) -> GridSource {
        GridSource {
            folder: Some(dir.to_path_buf()),
            channel: "u".into(),
            expect: Expect::Force,
            ..GridSource::default()
        }
    }

    #[test]
    fn a_grid_of_forces_takes_high_passed_newtons_and_refuses_the_rest_naming_the_fix() {
        let dir = tempfile::tempdir().unwrap();
        let good = force(2000, |_| 0.0);
        cell(dir.path(), "60g-3cms", 60.0, 3.0, "N", &good);
        cell(dir.path(), "60g-7cms", 60.0, 7.0, "N", &good);
        let g = Grid::load(&forces(dir.path())).unwrap();
        assert_eq!(g.cells.len(), 2);

        // The raw force (0.25 N of friction) in one cell.
        cell(dir.path(), "60g-7cms", 60.0, 7.0, "N", &force(2000, |_| 0.25));
        let e = Grid::load(&forces(dir.path())).unwrap_err().to_string();
        assert!(e.contains("u-60g-7cms.json") && e.contains("carries an offset (mean 0.250 N)"), "{e}");
        assert!(e.contains("evflow library from-recordings") && e.contains("forces-SAMPLE"), "{e}");
        // Unchecked, the same grid loads (an actuation chain's choice).
        assert!(Grid::load(&GridSource { expect: Expect::Any, ..forces(dir.path()) }).is_ok());

        // An actuation (narx-SAMPLE's unit `1`), and a force with no unit.
        for (unit, says) in [("1", "unit `1`, not `N`"), ("", "no unit, not `N`")] {
            cell(dir.path(), "60g-7cms", 60.0, 7.0, unit, &good);
            let e = Grid::load(&forces(dir.path())).unwrap_err().to_string();
            assert!(e.contains("u-60g-7cms.json") && e.contains(says) && e.contains("narx-SAMPLE"), "{e}");
            assert!(e.contains("evflow library from-recordings"), "{e}");
        }
        // A cell the session cannot reach is not opened, so not checked.
        let narrow = GridSource { velocity_range: Some((3.0, 3.0)), ..forces(dir.path()) };
        assert!(Grid::load(&narrow).is_ok());
    }

    #[test]
    fn the_interp_doc_states_the_threshold() {
        let doc = crate::texture::interp::SPEC.doc;
        assert!(
            doc.contains(&format!("at most {OFFSET_RATIO_MAX} times")),
            "interp's doc and OFFSET_RATIO_MAX disagree"
        );
    }
}
