//! The models a texture study builds per lab profile and condition: the
//! inverse NARX model on binary excitation (`graphs/model-build.toml`,
//! §5.2.1), the inverse model on multilevel excitation (`graphs/model-build-multilevel.toml`,
//! a 5-level MLS, §5.4/§7.2), and the forward model
//! (`graphs/forward-build.toml`).

use super::graphs::{run_graph, Sets};
use super::setup::{Cond, Profile};
use super::StudyError;
use std::path::{Path, PathBuf};

/// The models of one profile and condition.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Models {
    /// Inverse NARX, binary excitation.
    pub narx: PathBuf,
    /// Inverse NARX, multilevel excitation (None when not built).
    pub narx_multilevel: Option<PathBuf>,
    /// Forward model.
    pub forward: PathBuf,
    /// Seconds each took to build: inverse binary, inverse multilevel, forward.
    #[serde(with = "super::exact::triple")]
    pub seconds: [f64; 3],
}

/// Builds the models of `c` on `profile` into `dir`; `epochs` bounds the
/// NARX training; `multilevel` also builds the multilevel inverse model;
/// `record_time` writes each model's training time into its file (without
/// it the files are the same on every run: `--no-times`).
pub fn build(
    graphs: &Path,
    profile: &Profile,
    c: &Cond,
    epochs: u32,
    multilevel: bool,
    record_time: bool,
    dir: &Path,
) -> Result<Models, StudyError> {
    let common = c.sets().and(profile.sets());
    let narx_sets = common.int("epochs", epochs).flag("train.progress", false).flag("train.record_time", record_time);
    let t = std::time::Instant::now();
    run_graph(&graphs.join("model-build.toml"), &narx_sets, dir)?;
    let narx_s = t.elapsed().as_secs_f64();
    let narx = found(dir.join(format!("narx-{}.json", c.tag())))?;
    let mut ml_s = 0.0;
    let narx_multilevel = if multilevel {
        let ml_dir = dir.join("multilevel");
        let t = std::time::Instant::now();
        run_graph(&graphs.join("model-build-multilevel.toml"), &narx_sets, &ml_dir)?;
        ml_s = t.elapsed().as_secs_f64();
        Some(found(ml_dir.join(format!("narx-{}.json", c.tag())))?)
    } else {
        None
    };
    let t = std::time::Instant::now();
    let forward = forward(graphs, profile, c, record_time, dir)?;
    Ok(Models { narx, narx_multilevel, forward, seconds: [narx_s, ml_s, t.elapsed().as_secs_f64()] })
}

/// Identifies the forward model of `c` on `profile` (graphs/forward-build.toml)
/// into `dir`, and returns its file `forward-TAG.json`.
pub fn forward(
    graphs: &Path,
    profile: &Profile,
    c: &Cond,
    record_time: bool,
    dir: &Path,
) -> Result<PathBuf, StudyError> {
    let sets = c.sets().and(profile.sets()).flag("record_time", record_time);
    run_graph(&graphs.join("forward-build.toml"), &sets, dir)?;
    found(dir.join(format!("forward-{}.json", c.tag())))
}

/// Trains the inverse NARX model of `c` on `profile` alone
/// (graphs/model-build.toml, binary excitation) into `dir`, with `extra`
/// values set after the study's own (e.g. another network: `train.hidden`);
/// returns the model file.
pub fn inverse(
    graphs: &Path,
    profile: &Profile,
    c: &Cond,
    epochs: u32,
    extra: &Sets,
    dir: &Path,
) -> Result<PathBuf, StudyError> {
    let sets = c
        .sets()
        .and(profile.sets())
        .int("epochs", epochs)
        .flag("train.progress", false)
        .flag("train.record_time", true)
        .and(extra.clone());
    run_graph(&graphs.join("model-build.toml"), &sets, dir)?;
    found(dir.join(format!("narx-{}.json", c.tag())))
}

/// The models of `c` built before into `dir` (`narx-TAG.json` and
/// `forward-TAG.json`; no multilevel model): for a report that is given
/// its models instead of building them.
pub fn given(dir: &Path, c: &Cond) -> Result<Models, StudyError> {
    let narx = found(dir.join(format!("narx-{}.json", c.tag())))?;
    let forward = found(dir.join(format!("forward-{}.json", c.tag())))?;
    Ok(Models { narx, narx_multilevel: None, forward, seconds: [0.0; 3] })
}

fn found(p: PathBuf) -> Result<PathBuf, StudyError> {
    std::fs::canonicalize(&p).map_err(|_| StudyError::Missing(p))
}
