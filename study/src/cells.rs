//! Grid cells U_ij for `interp` (dissertation §5.3.3): one trained
//! condition's signal cut to its constant-speed stretch and written as a
//! recording (channel `u`) whose sidecar names the condition, the sample
//! and the gain `interp`'s `apply_gain` multiplies in.

use super::recordings::{channel, gate};
use super::setup::Cond;
use super::StudyError;
use evflow_nodes::filters::segment::open_runs;
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::path::{Path, PathBuf};

/// The file name of the cell of `sample` at `c` in a grid folder.
pub fn name(sample: &str, c: &Cond) -> String {
    format!("u-{sample}-{}", c.tag())
}

/// Writes channel `channel` of the graphs/synthesize.toml recording `from`
/// (over its `steady` gate) as the cell of `sample` at `c` into `grid`, at
/// `gain` (Table 5.1's, which `interp` applies), marked
/// `condition.carrier = "nyquist"` when `carrier` (the method's actuation
/// rides a Nyquist-rate carrier: [`super::row::Method::carrier`]; every
/// cell of a grid must agree, so an optimized cell kept from the inverse
/// model's start — where the forward model has no carrier gain — is marked
/// too). The
/// `narx` node's output lags the force by its look-ahead; a grid cell is a
/// texture loop, so that shift of a few samples does not matter. Returns
/// the cell's path (without extension).
pub fn write_actuation(
    from: &Path,
    channel_name: &str,
    grid: &Path,
    sample: &str,
    c: &Cond,
    gain: f64,
    carrier: bool,
) -> Result<PathBuf, StudyError> {
    let (rate, u) = channel(from, channel_name)?;
    let (_, steady) = channel(from, "steady")?;
    let mut kept = Vec::new();
    open_runs(&[&steady], u.len().min(steady.len()), |a, b| kept.extend_from_slice(&u[a..b]));
    let source = format!("evflow study: graphs/synthesize.toml, `{channel_name}` over the constant-speed stretch");
    write(&kept, rate, "1", grid, sample, c, gain, carrier, source, from)
}

/// Writes the recorded force (channel `force`, newtons) of the texture
/// recording `from`, made at `c`, over its constant-speed stretch
/// (`segment`'s rule, as graphs/synthesize.toml gates), as the cell of
/// `sample` at `c` into `grid`, gain 1: the grid that "forces first"
/// interpolates before it synthesizes.
pub fn write_force(from: &Path, grid: &Path, sample: &str, c: &Cond) -> Result<PathBuf, StudyError> {
    let (rate, f) = channel(from, "force")?;
    let keep = gate(from, c.speed)?;
    let kept: Vec<f64> = f.iter().zip(&keep).filter(|(_, k)| **k).map(|(v, _)| *v).collect();
    let source = "evflow study: the recorded force over the constant-speed stretch".to_string();
    write(&kept, rate, "N", grid, sample, c, 1.0, false, source, from)
}

/// Writes `kept`, a force in newtons at `rate` Hz already cut to its
/// constant-speed stretch, as the cell of `sample` at `c` into `grid`,
/// gain 1, with `source` (what [`write_force`] writes for a lab recording
/// it cuts itself; `evflow library from-recordings`). `from` names the
/// recording in errors.
pub fn write_force_samples(
    kept: &[f64],
    rate: f64,
    grid: &Path,
    sample: &str,
    c: &Cond,
    source: String,
    from: &Path,
) -> Result<PathBuf, StudyError> {
    write(kept, rate, "N", grid, sample, c, 1.0, false, source, from)
}

#[allow(clippy::too_many_arguments)]
fn write(
    kept: &[f64],
    rate: f64,
    unit: &str,
    grid: &Path,
    sample: &str,
    c: &Cond,
    gain: f64,
    carrier: bool,
    source: String,
    from: &Path,
) -> Result<PathBuf, StudyError> {
    if kept.is_empty() {
        return Err(StudyError::Recording(format!("{}: no constant-speed samples", from.display())));
    }
    std::fs::create_dir_all(grid).map_err(|e| StudyError::Io { path: grid.to_path_buf(), message: e.to_string() })?;
    let mut meta = RecordingMeta::new(rate, vec![Channel::new("u", unit)]);
    meta.condition.load_g = Some(c.mass);
    meta.condition.velocity_cm_s = Some(c.speed);
    meta.condition.material = Some(sample.into());
    meta.condition.gain = Some(gain);
    if carrier {
        meta.condition.extra.insert("carrier".into(), "nyquist".into());
    }
    meta.source = source;
    let path = grid.join(name(sample, c));
    let io = |e: evflow_nodes::recording::format::RecordingError| StudyError::Io {
        path: path.clone(),
        message: e.to_string(),
    };
    let mut w = RecordingWriter::create(&path, meta).map_err(io)?;
    w.write_interleaved(kept).map_err(io)?;
    w.finish().map_err(io)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_nodes::recording::format::Recording;

    #[test]
    fn an_actuation_cell_keeps_the_steady_stretch_and_names_its_condition() {
        let dir = tempfile::tempdir().unwrap();
        let from = dir.path().join("synth");
        let mut meta = RecordingMeta::new(1000.0, vec![Channel::new("u", "1"), Channel::new("steady", "1")]);
        meta.source = "test".into();
        let mut w = RecordingWriter::create(&from, meta).unwrap();
        // u = 0, 1, …, 9; steady over 2..5 and 7..9.
        let steady = [0., 0., 1., 1., 1., 0., 0., 1., 1., 0.];
        let frames: Vec<f64> = (0..10).flat_map(|i| [i as f64 / 10.0, steady[i]]).collect();
        w.write_interleaved(&frames).unwrap();
        w.finish().unwrap();
        let c = Cond { mass: 60.0, speed: 3.0 };
        let cell = write_actuation(&from, "u", &dir.path().join("grid"), "felt-fabric", &c, 0.8, false).unwrap();
        assert_eq!(cell, dir.path().join("grid/u-felt-fabric-60g-3cms"));
        let rec = Recording::open(&cell).unwrap();
        let u: Vec<f64> = rec.channel("u").unwrap().iter().map(|x| (x * 10.0).round()).collect();
        assert_eq!(u, [2.0, 3.0, 4.0, 7.0, 8.0]);
        assert_eq!(rec.meta().condition.gain, Some(0.8));
        assert_eq!(rec.meta().condition.load_g, Some(60.0));
        // A recording without the channel, or with no steady sample, is an error.
        assert!(write_actuation(&from, "nope", dir.path(), "felt-fabric", &c, 1.0, false).is_err());
    }
}
