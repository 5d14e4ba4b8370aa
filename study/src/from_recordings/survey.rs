//! What a lab's two folders of recordings hold, checked before anything is
//! built: every recording readable and finite, its channels and units, its
//! condition, one rate per folder (a whole multiple of 1 kHz), a forward
//! constant-speed stretch, one excitation per condition, every texture at
//! a condition with an excitation, every texture's conditions a full
//! load × speed grid. Each error names the file and says what to do.

use crate::setup::Cond;
use crate::StudyError;
use evflow_nodes::filters::segment::SpeedRule;
use evflow_nodes::recording::format::{Recording, RecordingMeta};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

type Result<T> = std::result::Result<T, StudyError>;

/// The rate every recording is taken to (the chains' rate), Hz.
pub const CHAIN_RATE: f64 = 1000.0;

/// `segment`'s constant-speed rule as the shipped recordings graphs apply
/// it: within 2 % of the set speed, settled for 100 ms.
pub const TOLERANCE: f64 = 0.02;
/// See [`TOLERANCE`], s.
pub const SETTLE_S: f64 = 0.1;

/// The shortest forward constant-speed stretch a texture recording must
/// hold, s: the loop `interp` plays is at most as long as the shortest cell.
pub const MIN_STRETCH_S: f64 = 0.5;

/// One excitation recording: the display driven by `u`, one per condition.
#[derive(Debug, Clone)]
pub struct Excitation {
    /// Its sidecar.
    pub path: PathBuf,
    /// Its condition.
    pub cond: Cond,
    /// Its rate, Hz.
    pub rate: f64,
    /// `condition.material` (the display), when given.
    pub display: Option<String>,
    /// Whether `u` takes one magnitude only (±c: a binary excitation).
    pub binary: bool,
}

/// The recording a texture's cell at one condition is made from.
#[derive(Debug, Clone)]
pub struct Texture {
    /// Its sidecar (the first by name of the texture's recordings there).
    pub path: PathBuf,
    /// Its condition.
    pub cond: Cond,
    /// Its rate, Hz.
    pub rate: f64,
    /// `condition.material`.
    pub material: String,
    /// The other recordings of this texture and condition (repetitions,
    /// the repeat baseline of §5.3.1), not used for the cell.
    pub repeats: Vec<PathBuf>,
}

/// The two folders, checked.
#[derive(Debug, Clone)]
pub struct Survey {
    /// One per condition, in condition order (load, then speed).
    pub excitation: Vec<Excitation>,
    /// One per texture and condition, texture by texture (by name), condition by condition.
    pub textures: Vec<Texture>,
}

impl Survey {
    /// The textures, by name.
    pub fn samples(&self) -> Vec<String> {
        let mut v: Vec<String> = self.textures.iter().map(|t| t.material.clone()).collect();
        v.dedup();
        v
    }
}

fn bad(path: &Path, message: impl std::fmt::Display) -> StudyError {
    StudyError::Recording(format!("{}: {message}", path.display()))
}

/// The sidecars of a folder's recordings, sorted by name, absolute (the
/// graphs read relative paths from their own folder).
fn sidecars(dir: &Path, what: &str) -> Result<Vec<PathBuf>> {
    let cannot = |e: std::io::Error| StudyError::Io {
        path: dir.to_path_buf(),
        message: format!("cannot list the folder of {what} recordings: {e}"),
    };
    let rd = std::fs::canonicalize(dir).and_then(std::fs::read_dir).map_err(cannot)?;
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("json"))
        .collect();
    v.sort();
    if v.is_empty() {
        return Err(bad(
            dir,
            format!(
                "no {what} recordings (NAME.json + NAME.wav, docs/recording-format.md; `evflow import` writes them)"
            ),
        ));
    }
    Ok(v)
}

/// Opens a recording, every channel loaded and checked finite, complete.
fn open(path: &Path) -> Result<Recording> {
    let rec = Recording::open(path).map_err(|e| StudyError::Recording(e.to_string()))?;
    rec.require_complete().map_err(|e| StudyError::Recording(e.to_string()))?;
    Ok(rec)
}

/// Checks that `meta` has each `(channel, unit)`; `kind` names the recording's kind.
fn channels(path: &Path, meta: &RecordingMeta, want: &[(&str, &str)], kind: &str) -> Result<()> {
    let listed = || {
        let all: Vec<String> = meta.channels.iter().map(|c| format!("{} [{}]", c.name, c.unit)).collect();
        format!(
            "{}; {kind} holds {}",
            all.join(", "),
            want.iter().map(|(n, u)| format!("{n} [{u}]")).collect::<Vec<_>>().join(", ")
        )
    };
    for (name, unit) in want {
        let Some(k) = meta.channel_index(name) else {
            return Err(bad(path, format!("no channel `{name}` (channels: {}; docs/rig.md)", listed())));
        };
        let has = &meta.channels[k].unit;
        if has != unit {
            let shown = if has.is_empty() { "no unit".to_string() } else { format!("unit `{has}`") };
            let hint = match *unit {
                "N" => "write the force in newtons",
                "m/s" => "write the velocity in m/s, signed, +x forward",
                _ => "write the actuation as sent to the amplifier, in [−1, 1], unit `1`",
            };
            return Err(bad(
                path,
                format!("channel `{name}` has {shown}, not `{unit}`: {hint} (channels: {})", listed()),
            ));
        }
    }
    Ok(())
}

/// The condition (load and speed, finite and positive).
fn condition(path: &Path, meta: &RecordingMeta) -> Result<Cond> {
    let c = &meta.condition;
    match (c.load_g, c.velocity_cm_s) {
        (Some(m), Some(v)) if m > 0.0 && v > 0.0 => Ok(Cond { mass: m, speed: v }),
        (Some(m), Some(v)) => Err(bad(path, format!("condition load_g = {m}, velocity_cm_s = {v}: both must be positive"))),
        _ => Err(bad(
            path,
            "the sidecar's condition lacks load_g or velocity_cm_s (give them: `evflow import --load-g G --velocity-cm-s V`)",
        )),
    }
}

/// The rate: a whole multiple of the chains' 1 kHz.
fn rate(path: &Path, rate: f64) -> Result<f64> {
    let k = (rate / CHAIN_RATE).round();
    if k < 1.0 || (rate - k * CHAIN_RATE).abs() > 1e-9 * rate {
        return Err(bad(
            path,
            format!(
                "recorded at {rate} Hz; the route takes whole multiples of 1 kHz (1 kHz, 10 kHz, …): every \
                 recording is resampled to the chains' 1 kHz in a graph whose rates must be integer multiples \
                 (docs/rig.md, Rates; write the nominal rate if the clock's error is negligible)"
            ),
        ));
    }
    Ok(rate)
}

/// The forward constant-speed gate of `velocity` (m/s) at `c`'s speed.
pub fn forward_gate(velocity: &[f64], speed_cm_s: f64, rate: f64) -> Vec<bool> {
    SpeedRule::new(speed_cm_s, TOLERANCE, SETTLE_S, rate, 1.0).gate(velocity)
}

/// The longest run of `gate` (the first of equal ones), as a range.
pub fn longest_run(gate: &[bool]) -> Option<std::ops::Range<usize>> {
    let mut best: Option<std::ops::Range<usize>> = None;
    let mut i = 0;
    while i < gate.len() {
        if !gate[i] {
            i += 1;
            continue;
        }
        let start = i;
        while i < gate.len() && gate[i] {
            i += 1;
        }
        if best.as_ref().is_none_or(|b| i - start > b.len()) {
            best = Some(start..i);
        }
    }
    best
}

/// Checks that the recording has a forward constant-speed stretch of at
/// least `min_s` seconds; returns its length in seconds.
fn stretch(path: &Path, rec: &Recording, c: &Cond, min_s: f64) -> Result<f64> {
    let v = rec.channel("velocity").unwrap_or_default();
    let run = longest_run(&forward_gate(v, c.speed, rec.rate())).map_or(0, |r| r.len());
    let seconds = run as f64 / rec.rate();
    if run == 0 || seconds < min_s {
        let fastest = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let found = if run == 0 { "none".to_string() } else { format!("only {seconds:.2} s") };
        return Err(bad(
            path,
            format!(
                "needs a forward constant-speed stretch of at least {min_s} s — `velocity` within {}% of +{} cm/s \
                 (the condition's velocity_cm_s) for {SETTLE_S} s and more — and holds {found} (largest |velocity| \
                 {fastest:.4} m/s): is velocity_cm_s right, is `velocity` in m/s and positive towards +x?",
                TOLERANCE * 100.0,
                c.speed
            ),
        ));
    }
    Ok(seconds)
}

/// Checks one folder's rates agree; returns the error naming both files.
fn one_rate(kind: &str, first: &(PathBuf, f64), path: &Path, r: f64) -> Result<()> {
    if r != first.1 {
        return Err(bad(
            path,
            format!(
                "recorded at {r} Hz but {} at {} Hz: record every {kind} recording of a folder at one rate \
                 (a recording from another session or acquisition?)",
                first.0.display(),
                first.1
            ),
        ));
    }
    Ok(())
}

/// A texture name that can name a folder (`forces-NAME`).
fn material(path: &Path, meta: &RecordingMeta) -> Result<String> {
    let Some(m) = meta.condition.material.clone() else {
        return Err(bad(path, "the sidecar's condition names no material (give it: `evflow import --material NAME`)"));
    };
    let ok = !m.is_empty()
        && m.len() <= 100
        && !m.starts_with('.')
        && m.chars().all(|ch| ch.is_ascii_alphanumeric() || matches!(ch, '-' | '_' | '.'));
    if !ok {
        return Err(bad(
            path,
            format!(
                "material `{m}` cannot name the folder forces-{m}: use letters, digits, `-`, `_` and `.` \
                 (not first), at most 100"
            ),
        ));
    }
    Ok(m)
}

/// Reads and checks the excitation folder.
pub fn excitation(dir: &Path) -> Result<Vec<Excitation>> {
    let mut by_tag: BTreeMap<String, Excitation> = BTreeMap::new();
    let mut first_rate: Option<(PathBuf, f64)> = None;
    for path in sidecars(dir, "excitation")? {
        let rec = open(&path)?;
        let meta = rec.meta();
        channels(&path, meta, &[("u", "1"), ("force", "N"), ("velocity", "m/s")], "an excitation recording")?;
        let cond = condition(&path, meta)?;
        let r = rate(&path, rec.rate())?;
        match &first_rate {
            None => first_rate = Some((path.clone(), r)),
            Some(f) => one_rate("excitation", f, &path, r)?,
        }
        let u = rec.channel("u").unwrap_or_default();
        let peak = u.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if peak > 1.0 + 1e-9 {
            return Err(bad(
                &path,
                format!("`u` reaches {peak}: the actuation is in [−1, 1], the amplifier's full scale"),
            ));
        }
        if u.iter().all(|x| *x == u[0]) {
            return Err(bad(
                &path,
                "`u` is constant: an excitation recording drives the display across the band (docs/rig.md)",
            ));
        }
        stretch(&path, &rec, &cond, SETTLE_S)?;
        let magnitude = |x: f64| (x.abs() * 1e9).round() as i64;
        let nonzero: std::collections::BTreeSet<i64> = u.iter().filter(|x| **x != 0.0).map(|x| magnitude(*x)).collect();
        let e = Excitation {
            path: path.clone(),
            cond,
            rate: r,
            display: meta.condition.material.clone(),
            binary: nonzero.len() == 1 && u.iter().all(|x| *x != 0.0),
        };
        if let Some(prev) = by_tag.get(&cond.tag()) {
            return Err(bad(
                &path,
                format!(
                    "a second excitation at {} (the first: {}); one per condition makes one model per condition — \
                     keep a second one for validation in a folder of its own (docs/rig.md, Repetitions)",
                    cond.label(),
                    prev.path.display()
                ),
            ));
        }
        by_tag.insert(cond.tag(), e);
    }
    let mut v: Vec<Excitation> = by_tag.into_values().collect();
    v.sort_by(|a, b| a.cond.mass.total_cmp(&b.cond.mass).then(a.cond.speed.total_cmp(&b.cond.speed)));
    Ok(v)
}

/// Reads and checks the textures folder against the excitation's conditions.
pub fn textures(dir: &Path, excitation: &[Excitation]) -> Result<Vec<Texture>> {
    let mut chosen: BTreeMap<(String, String), Texture> = BTreeMap::new();
    let mut first_rate: Option<(PathBuf, f64)> = None;
    let trained: Vec<String> = excitation.iter().map(|e| e.cond.label()).collect();
    for path in sidecars(dir, "texture")? {
        let rec = open(&path)?;
        let meta = rec.meta();
        channels(&path, meta, &[("force", "N"), ("velocity", "m/s")], "a texture recording")?;
        let cond = condition(&path, meta)?;
        let m = material(&path, meta)?;
        let r = rate(&path, rec.rate())?;
        match &first_rate {
            None => first_rate = Some((path.clone(), r)),
            Some(f) => one_rate("texture", f, &path, r)?,
        }
        if !excitation.iter().any(|e| e.cond.tag() == cond.tag()) {
            return Err(bad(
                &path,
                format!(
                    "{m} at {}, a condition with no excitation recording (excitation at: {}); record the display's \
                     excitation there too, or leave this recording out — the models of a condition come from its \
                     excitation",
                    cond.label(),
                    trained.join("; ")
                ),
            ));
        }
        stretch(&path, &rec, &cond, MIN_STRETCH_S)?;
        let key = (m.clone(), cond.tag());
        match chosen.get_mut(&key) {
            Some(t) => t.repeats.push(path.clone()),
            None => {
                chosen.insert(key, Texture { path: path.clone(), cond, rate: r, material: m, repeats: Vec::new() });
            }
        }
    }
    let mut v: Vec<Texture> = chosen.into_values().collect();
    v.sort_by(|a, b| {
        a.material
            .cmp(&b.material)
            .then(a.cond.mass.total_cmp(&b.cond.mass))
            .then(a.cond.speed.total_cmp(&b.cond.speed))
    });
    full_grids(dir, &v)?;
    Ok(v)
}

/// Every texture's conditions must make a full load × speed grid: `interp`
/// needs each cell between the loads and speeds a session reaches.
fn full_grids(dir: &Path, textures: &[Texture]) -> Result<()> {
    let mut by_material: BTreeMap<&str, Vec<Cond>> = BTreeMap::new();
    for t in textures {
        by_material.entry(&t.material).or_default().push(t.cond);
    }
    for (m, conds) in by_material {
        let mut loads: Vec<f64> = conds.iter().map(|c| c.mass).collect();
        let mut speeds: Vec<f64> = conds.iter().map(|c| c.speed).collect();
        for axis in [&mut loads, &mut speeds] {
            axis.sort_by(f64::total_cmp);
            axis.dedup();
        }
        let missing: Vec<String> = loads
            .iter()
            .flat_map(|&mass| speeds.iter().map(move |&speed| Cond { mass, speed }))
            .filter(|c| !conds.iter().any(|d| d.tag() == c.tag()))
            .map(|c| c.label())
            .collect();
        if !missing.is_empty() {
            return Err(bad(
                dir,
                format!(
                    "texture `{m}` is recorded at loads {loads:?} g × speeds {speeds:?} cm/s but not at {}: the live \
                     chains interpolate over a full grid (interp), so record it there (and the excitation), or \
                     leave the odd recordings out",
                    missing.join("; ")
                ),
            ));
        }
    }
    Ok(())
}

/// Reads and checks both folders.
pub fn survey(excitation_dir: &Path, textures_dir: &Path) -> Result<Survey> {
    let excitation = excitation(excitation_dir)?;
    let textures = textures(textures_dir, &excitation)?;
    Ok(Survey { excitation, textures })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_run_is_the_first_of_the_longest() {
        let g = |s: &str| s.chars().map(|c| c == '1').collect::<Vec<bool>>();
        assert_eq!(longest_run(&g("0011100111")), Some(2..5));
        assert_eq!(longest_run(&g("0110111100")), Some(4..8));
        assert_eq!(longest_run(&g("000")), None);
        assert_eq!(longest_run(&[]), None);
    }
}
