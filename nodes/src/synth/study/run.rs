//! The texture study's driver: for every lab profile, the models of every
//! condition, the recordings of every texture, and every row.

use super::models::{self, Models};
use super::recordings;
use super::row::{self, Row, RowInputs};
use super::setup::{Cond, Profile};
use super::StudyError;
use std::path::PathBuf;
use std::time::Instant;

/// What a study covers and how.
#[derive(Debug, Clone)]
pub struct StudyConfig {
    /// The folder of the shipped graphs.
    pub graphs: PathBuf,
    /// Where models, recordings and runs go.
    pub work: PathBuf,
    /// Lab profiles.
    pub profiles: Vec<Profile>,
    /// Texture samples.
    pub samples: Vec<String>,
    /// Trained conditions.
    pub conds: Vec<Cond>,
    /// The gain sweep.
    pub gains: Vec<f64>,
    /// NARX training epochs at most.
    pub epochs: u32,
    /// The optimized synthesis' iteration budget.
    pub iterations: usize,
    /// Also the inverse model on multilevel excitation.
    pub multilevel: bool,
    /// Also the achievable floor (optimization through the display itself).
    pub floor: bool,
    /// The optimized synthesis' objective (`synth.optimize`'s `objective`,
    /// which takes the waveform where a pass keeps less than one spectral
    /// segment).
    pub objective: String,
}

/// Where a study is.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// Building the models of a profile and condition.
    Models(&'a Profile, Cond),
    /// Running a row.
    Row(&'a Profile, &'a str, Cond, usize, usize),
}

/// What a study found.
#[derive(Debug, Clone)]
pub struct Study {
    /// Every row, profile by profile, condition by condition, sample by sample.
    pub rows: Vec<Row>,
    /// The models of each profile and condition.
    pub models: Vec<(String, Cond, Models)>,
    /// Wall-clock time, s.
    pub seconds: f64,
}

/// Runs a study.
pub fn run(cfg: &StudyConfig, progress: &mut dyn FnMut(Progress<'_>)) -> Result<Study, StudyError> {
    let t0 = Instant::now();
    for g in [
        "model-build.toml",
        "forward-build.toml",
        "record-textures.toml",
        "synthesize.toml",
        "synthesize-optimized.toml",
        "play-actuation.toml",
    ] {
        if !cfg.graphs.join(g).is_file() {
            return Err(StudyError::Missing(cfg.graphs.join(g)));
        }
    }
    if cfg.gains.is_empty() || cfg.gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(StudyError::Config("the gains must be positive numbers, at least one".into()));
    }
    let total = cfg.profiles.len() * cfg.samples.len() * cfg.conds.len();
    let mut done = 0;
    let mut rows = Vec::new();
    let mut all_models = Vec::new();
    for profile in &cfg.profiles {
        let pdir = cfg.work.join(&profile.name);
        let rec_dir = recordings::folder(&cfg.work, profile);
        for c in &cfg.conds {
            progress(Progress::Models(profile, *c));
            let m = models::build(&cfg.graphs, profile, c, cfg.epochs, cfg.multilevel, &pdir.join("models"))?;
            for sample in &cfg.samples {
                done += 1;
                progress(Progress::Row(profile, sample, *c, done, total));
                recordings::record_pair(&cfg.graphs, profile, sample, c, &rec_dir)?;
                let inputs = RowInputs {
                    graphs: &cfg.graphs,
                    profile,
                    sample,
                    cond: *c,
                    models: &m,
                    recordings: &rec_dir,
                    gains: &cfg.gains,
                    iterations: cfg.iterations,
                    objective: &cfg.objective,
                    optimized: None,
                    dir: pdir.join("rows").join(format!("{sample}-{}", c.tag())),
                };
                let mut r = row::run(&inputs)?;
                if cfg.floor {
                    r.achievable = Some(super::floor::achievable(&inputs)?);
                }
                rows.push(r);
            }
            all_models.push((profile.name.clone(), *c, m));
        }
    }
    Ok(Study { rows, models: all_models, seconds: t0.elapsed().as_secs_f64() })
}
