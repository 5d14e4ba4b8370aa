//! The texture study's driver: for every lab profile, the models of every
//! condition, the recordings of every texture, and every row — on several
//! threads through `evflow_engine::batch` (the models of every profile and
//! condition at once, then every row at once), with the same results in
//! the same order as on one.

use super::models::{self, Models};
use super::recordings;
use super::row::{self, Row, RowInputs};
use super::scope::Scope;
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_engine::batch::{for_each_ordered, Shard};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A texture study to run: its [`Scope`], the profiles it names resolved,
/// where the graphs are and the work goes, and its slice.
#[derive(Debug, Clone)]
pub struct StudyConfig {
    /// What it covers and how.
    pub scope: Scope,
    /// The scope's lab profiles, resolved ([`StudyConfig::new`]).
    pub profiles: Vec<Profile>,
    /// The folder of the shipped graphs.
    pub graphs: PathBuf,
    /// Where models, recordings and runs go.
    pub work: PathBuf,
    /// The slice of the (profile, condition) cells to run ([`Shard::ALL`]:
    /// every one); each cell's models and rows run in the slice that holds it.
    pub shard: Shard,
}

impl StudyConfig {
    /// The config of `scope` run from the shipped graphs in `graphs`, its
    /// work under `work`: the scope's profiles resolved (a name, or a
    /// profile file), its slice `shard`.
    pub fn new(scope: Scope, graphs: PathBuf, work: PathBuf, shard: Shard) -> Result<Self, StudyError> {
        let profiles = scope.profiles.iter().map(|p| Profile::resolve(p, &graphs)).collect::<Result<Vec<_>, _>>()?;
        Ok(Self { scope, profiles, graphs, work, shard })
    }

    /// The config of a merged study's tables: profiles by name only (no
    /// graph is run from it), `base` as graphs and work.
    pub fn merged(scope: Scope, base: &Path, shard: Shard) -> Self {
        let profiles = scope.profiles.iter().map(|n| Profile { name: n.clone(), path: None }).collect();
        Self { scope, profiles, graphs: base.to_path_buf(), work: base.join("work"), shard }
    }

    /// Every (profile, condition) cell, profile by profile, in study order.
    pub fn all_cells(&self) -> Vec<(&Profile, Cond)> {
        self.profiles.iter().flat_map(|p| self.scope.conds.iter().map(move |c| (p, *c))).collect()
    }

    /// The cells of this config's shard.
    pub fn cells(&self) -> Vec<(&Profile, Cond)> {
        let all = self.all_cells();
        all[self.shard.range(all.len())].to_vec()
    }
}

/// What a study has finished (reported in study order, whatever order the
/// threads finish in).
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// The models of a profile and condition are built (or failed).
    Models(&'a Profile, Cond),
    /// A row is done (or failed): profile, sample, condition, rows done, rows in all.
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
    /// The steps that failed, `(step, reason)`, in study order: a model
    /// build (whose rows are then not run) or a row. The others are kept.
    pub failures: Vec<(String, String)>,
}

/// Runs a study on one thread; the first failed step is the error.
pub fn run(cfg: &StudyConfig, progress: &mut dyn FnMut(Progress<'_>)) -> Result<Study, StudyError> {
    let study = run_on(cfg, 1, progress)?;
    match study.failures.first() {
        Some((what, why)) => Err(StudyError::Config(format!("{what}: {why}"))),
        None => Ok(study),
    }
}

/// Runs a study with `jobs` steps at once: first the models of every
/// profile and condition, then every row. A step that fails is listed in
/// [`Study::failures`] and the others go on; only a study that cannot
/// start (a graph missing, bad gains) is an error.
pub fn run_on(cfg: &StudyConfig, jobs: usize, progress: &mut dyn FnMut(Progress<'_>)) -> Result<Study, StudyError> {
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
    if cfg.scope.gains.is_empty() || cfg.scope.gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(StudyError::Config("the gains must be positive numbers, at least one".into()));
    }
    let never = AtomicBool::new(false);
    let mut failures = Vec::new();

    // The models of every profile and condition.
    let cells = cfg.cells();
    let mut built: Vec<Option<Models>> = Vec::with_capacity(cells.len());
    let build = |_: usize, (profile, c): (&Profile, Cond)| {
        let dir = cfg.work.join(&profile.name).join("models");
        models::build(&cfg.graphs, profile, &c, cfg.scope.epochs, cfg.scope.multilevel, cfg.scope.times, &dir)
    };
    for_each_ordered(cells.clone(), jobs, &never, build, |k, outcome| {
        let (profile, c) = cells[k];
        progress(Progress::Models(profile, c));
        match outcome.map_err(StudyError::Config).and_then(|r| r) {
            Ok(m) => built.push(Some(m)),
            Err(e) => {
                let why = format!("{e} (its {} rows were not run)", cfg.scope.samples.len());
                failures.push((format!("{}: models at {}", profile.name, c.label()), why));
                built.push(None);
            }
        }
    });

    // Every row whose models were built.
    let total = cells.len() * cfg.scope.samples.len();
    let rows_to_run: Vec<(usize, &str)> = (0..cells.len())
        .filter(|k| built[*k].is_some())
        .flat_map(|k| cfg.scope.samples.iter().map(move |s| (k, s.as_str())))
        .collect();
    let one_row = |_: usize, (k, sample): (usize, &str)| -> Result<Row, StudyError> {
        let (profile, c) = cells[k];
        let m = built[k].as_ref().expect("rows run only where the models were built");
        let pdir = cfg.work.join(&profile.name);
        let rec_dir = recordings::folder(&cfg.work, profile);
        recordings::record_pair(&cfg.graphs, profile, sample, &c, &rec_dir)?;
        let inputs = RowInputs {
            graphs: &cfg.graphs,
            profile,
            sample,
            cond: c,
            models: m,
            recordings: &rec_dir,
            gains: &cfg.scope.gains,
            iterations: cfg.scope.iterations,
            objective: &cfg.scope.objective,
            optimized: None,
            dir: pdir.join("rows").join(format!("{sample}-{}", c.tag())),
        };
        let mut r = row::run(&inputs)?;
        if cfg.scope.floor {
            r.achievable = Some(super::floor::achievable(&inputs)?);
        }
        Ok(r)
    };
    let mut rows = Vec::new();
    let mut done = total - rows_to_run.len();
    for_each_ordered(rows_to_run.clone(), jobs, &never, one_row, |j, outcome| {
        let (k, sample) = rows_to_run[j];
        let (profile, c) = cells[k];
        done += 1;
        progress(Progress::Row(profile, sample, c, done, total));
        match outcome.map_err(StudyError::Config).and_then(|r| r) {
            Ok(r) => rows.push(r),
            Err(e) => failures.push((format!("{}: {sample} at {}", profile.name, c.label()), e.to_string())),
        }
    });
    let all_models = cells.iter().zip(built).filter_map(|((p, c), m)| m.map(|m| (p.name.clone(), *c, m))).collect();
    Ok(Study { rows, models: all_models, seconds: t0.elapsed().as_secs_f64(), failures })
}
