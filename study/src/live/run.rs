//! The live study's driver: for every lab profile, a model library on its
//! grid (models and cells of every sample, `study::library`, resumable);
//! then for every (profile, sample, user) item, every live chain over the
//! gain sweep ([`super::chains`]), the display floor and the stroke's
//! achievable floor ([`super::floor`], played by [`super::play`]) — on
//! several threads, with the same results in the same order as on one.

use super::chains;
use super::floor;
use super::floor::{Candidate, Goal};
use super::library::{self as live_library, LivePlan};
use super::play::{self, Stage};
use super::row::{Chain, LiveRow, StrokeFloor, TargetFloor};
use super::scope::{LiveScope, User};
use super::stroke::Stroke;
use crate::gains::choose;
use crate::library::{self, Plan};
use crate::row::Reading;
use crate::setup::{Cond, Profile};
use crate::StudyError;
use evflow_engine::batch::{for_each_ordered, Shard};
use evflow_nodes::lab::profile::LabProfile;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A live study to run.
#[derive(Debug, Clone)]
pub struct LiveConfig {
    /// What it covers.
    pub scope: LiveScope,
    /// The folder of the shipped graphs (absolute).
    pub graphs: PathBuf,
    /// Where libraries and runs go.
    pub work: PathBuf,
    /// The slice of the (profile, sample, user) items to run.
    pub shard: Shard,
    /// Steps at once.
    pub jobs: usize,
}

/// One item: indices into the scope's profiles, samples and users.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Item {
    /// Profile index.
    pub profile: usize,
    /// Sample index.
    pub sample: usize,
    /// User index.
    pub user: usize,
}

impl LiveConfig {
    /// Every item, profile by profile, sample by sample, user by user.
    pub fn all_items(&self) -> Vec<Item> {
        let s = &self.scope;
        let mut v = Vec::new();
        for profile in 0..s.profiles.len() {
            for sample in 0..s.samples.len() {
                for user in 0..s.users.len() {
                    v.push(Item { profile, sample, user });
                }
            }
        }
        v
    }

    /// This config's shard of the items.
    pub fn items(&self) -> Vec<Item> {
        let all = self.all_items();
        all[self.shard.range(all.len())].to_vec()
    }

    /// A profile's library folder (the live synthesis' own library when
    /// only the live synthesis plays).
    pub fn library(&self, profile: &Profile) -> PathBuf {
        self.work.join(&profile.name).join(if self.scope.live_only() { "live-library" } else { "library" })
    }
}

/// What a live study has finished.
#[derive(Debug, Clone)]
pub enum Progress<'a> {
    /// A profile's library is built (or failed).
    Library(&'a str),
    /// An item is done (or failed): profile, sample, user.
    Row(&'a str, &'a str, &'a str),
}

/// What a live study found.
#[derive(Debug, Clone)]
pub struct LiveStudy {
    /// Every row, in item order.
    pub rows: Vec<LiveRow>,
    /// The steps that failed, `(step, reason)`, in order.
    pub failures: Vec<(String, String)>,
    /// Wall-clock time, s.
    pub seconds: f64,
}

/// The live graphs a study runs, besides the library's.
const GRAPHS: [&str; 2] = [chains::GRAPH, play::GRAPH];

/// Runs a live study. A step that fails (a library, an item) is listed in
/// [`LiveStudy::failures`] and the others go on; a study that cannot start
/// (a graph or profile missing, a bad scope) is an error.
pub fn run(cfg: &LiveConfig, progress: &mut dyn FnMut(Progress<'_>)) -> Result<LiveStudy, StudyError> {
    let t0 = Instant::now();
    cfg.scope.validate().map_err(StudyError::Config)?;
    for g in GRAPHS {
        if !cfg.graphs.join(g).is_file() {
            return Err(StudyError::Missing(cfg.graphs.join(g)));
        }
    }
    let s = &cfg.scope;
    let profiles = s.profiles.iter().map(|p| Profile::resolve(p, &cfg.graphs)).collect::<Result<Vec<_>, _>>()?;
    let items = cfg.items();
    let mut failures = Vec::new();
    // The libraries of the profiles this shard's items need.
    let mut needed: Vec<usize> = items.iter().map(|i| i.profile).collect();
    needed.dedup();
    let mut ready = vec![false; profiles.len()];
    let conds: Vec<Cond> =
        s.masses.iter().flat_map(|&mass| s.speeds.iter().map(move |&speed| Cond { mass, speed })).collect();
    for p in needed {
        if s.live_only() {
            let plan = LivePlan {
                dir: cfg.library(&profiles[p]),
                graphs: cfg.graphs.clone(),
                profile: profiles[p].clone(),
                samples: s.samples.clone(),
                conds: conds.clone(),
                jobs: cfg.jobs,
            };
            match live_library::build(&plan) {
                Ok(out) if out.failures.is_empty() => ready[p] = true,
                Ok(out) => failures.push((
                    format!("{}: library", profiles[p].name),
                    out.failures.iter().map(|(w, e)| format!("{w}: {e}")).collect::<Vec<_>>().join("; "),
                )),
                Err(e) => failures.push((format!("{}: library", profiles[p].name), e.to_string())),
            }
            progress(Progress::Library(&profiles[p].name));
            continue;
        }
        let plan = Plan {
            dir: cfg.library(&profiles[p]),
            graphs: cfg.graphs.clone(),
            profile: profiles[p].clone(),
            samples: s.samples.clone(),
            conds: conds.clone(),
            gains: vec![0.6, 0.8, 1.0, 1.2, 1.4],
            epochs: s.epochs,
            iterations: s.iterations,
            jobs: cfg.jobs,
            shard: Shard::ALL,
            record_time: false,
        };
        match library::build(&plan, &|_| {}) {
            Ok(out) if out.failures.is_empty() => ready[p] = true,
            Ok(out) => failures.push((
                format!("{}: library", profiles[p].name),
                out.failures.summary(out.total, "items").trim_end().to_string(),
            )),
            Err(e) => failures.push((format!("{}: library", profiles[p].name), e.to_string())),
        }
        progress(Progress::Library(&profiles[p].name));
    }
    let todo: Vec<Item> = items.iter().copied().filter(|i| ready[i.profile]).collect();
    for i in items.iter().filter(|i| !ready[i.profile]) {
        failures.push((label(cfg, &profiles, i), "its profile's library failed".into()));
    }
    let never = AtomicBool::new(false);
    let work = |_: usize, i: Item| one(cfg, &profiles[i.profile], &s.samples[i.sample], &s.users[i.user]);
    let mut rows = Vec::new();
    for_each_ordered(todo.clone(), cfg.jobs, &never, work, |k, r| {
        let i = todo[k];
        progress(Progress::Row(&profiles[i.profile].name, &s.samples[i.sample], &s.users[i.user].name));
        match r.map_err(|p| StudyError::Config(format!("panicked: {p}"))).and_then(|r| r) {
            Ok(row) => rows.push(row),
            Err(e) => failures.push((label(cfg, &profiles, &i), e.to_string())),
        }
    });
    Ok(LiveStudy { rows, failures, seconds: t0.elapsed().as_secs_f64() })
}

fn label(cfg: &LiveConfig, profiles: &[Profile], i: &Item) -> String {
    format!("{}: {} under {}", profiles[i.profile].name, cfg.scope.samples[i.sample], cfg.scope.users[i.user].name)
}

/// One (profile, sample, user) item.
fn one(cfg: &LiveConfig, profile: &Profile, sample: &str, user: &User) -> Result<LiveRow, StudyError> {
    let s = &cfg.scope;
    let dir = cfg.work.join(&profile.name).join("live").join(format!("{sample}-{}", user.name));
    std::fs::create_dir_all(&dir).map_err(|e| StudyError::Io { path: dir.clone(), message: e.to_string() })?;
    let at = Stage { graphs: &cfg.graphs, scope: s, profile, sample, user, dir: &dir };
    let ran = chains::run(&at, &cfg.library(profile))?;
    let stroke = Stroke::of(user, sample, s.seconds, 1000.0)?;
    let display_floor = play::display_floor(&at, &stroke)?;
    let (achievable, target_floor) = if s.floor {
        let lab = match &profile.path {
            Some(p) => LabProfile::load(p).map_err(|e| StudyError::Config(e.issues_text()))?,
            None => LabProfile::default(),
        };
        let (stroke_floor, target_floor) = floors(&at, &stroke, &lab, &ran)?;
        (Some(stroke_floor), target_floor)
    } else {
        (None, None)
    };
    Ok(LiveRow {
        profile: profile.name.clone(),
        sample: sample.into(),
        user: user.name.clone(),
        nothing: ran.nothing,
        display_floor,
        chains: ran.chains,
        achievable,
        target_floor,
        dir,
    })
}

/// The best of `candidates` as played over the gain sweep (each written
/// as `dir/NAME-uK`): its sweep, the best of each reading over every
/// candidate, and its index.
struct Played {
    sweep: Vec<crate::gains::AtGain>,
    reached: Reading,
    best: usize,
}

fn play_best(
    at: &Stage<'_>,
    stroke: &Stroke,
    candidates: &[Candidate],
    name: &str,
    what: &str,
) -> Result<Played, StudyError> {
    let zeros = vec![0.0; stroke.len()];
    let mut best: Option<Played> = None;
    for (k, c) in candidates.iter().enumerate() {
        let file = play::write(
            &at.dir.join(format!("{name}-u{k}")),
            stroke.rate,
            &c.u,
            &zeros,
            &format!("evflow live study: {what} from {} (optimized through the display's twin)", c.start),
        )?;
        let sweep = play::sweep(at, &file, &at.scope.gains)?;
        let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
        let reached = Reading { rect: chosen.best_rect.rect, welch: chosen.best_welch.welch };
        match best.as_mut() {
            Some(b) if reached.welch >= b.reached.welch => b.reached = b.reached.min(reached),
            Some(b) => *b = Played { sweep, reached: b.reached.min(reached), best: k },
            None => best = Some(Played { sweep, reached, best: k }),
        }
    }
    let p = best.ok_or_else(|| StudyError::Config(format!("{what} had no start")))?;
    play::write(
        &at.dir.join(format!("{name}-best")),
        stroke.rate,
        &candidates[p.best].u,
        &zeros,
        &format!("evflow live study: {what} (optimized through the display's twin from {})", candidates[p.best].start),
    )?;
    Ok(p)
}

/// The stroke's floor and, when the live synthesis ran, the target's
/// floor. Both optimize through the twin of one stroke, so their starts
/// run in one queue ([`floor::optimize_goals`]); each floor's candidates
/// are the ones it reaches alone, and its seconds are the joint run's
/// seconds times its share of the evaluations.
///
/// The stroke's floor: the carrier starts for the real force and every
/// chain's actuation, optimized towards the real force; each optimum
/// played over the gain sweep, the best kept. The target's floor: the
/// carrier starts for the live synthesis' target and its own actuation,
/// optimized towards that target, played alike.
fn floors(
    at: &Stage<'_>,
    stroke: &Stroke,
    lab: &LabProfile,
    ran: &chains::ChainsRun,
) -> Result<(StrokeFloor, Option<TargetFloor>), StudyError> {
    let s = at.scope;
    let stroke_seeds: Vec<(String, Vec<f64>)> =
        ran.actuations.iter().map(|(c, u)| (c.label().to_string(), u.clone())).collect();
    let target_seeds: Vec<(String, Vec<f64>)> = ran
        .actuations
        .iter()
        .filter(|(c, _)| *c == Chain::Live)
        .map(|(c, u)| (c.label().to_string(), u.clone()))
        .collect();
    let t = Instant::now();
    let real = Goal::real(stroke)?;
    // The target's starts first: fewer evaluations then run alone or in
    // pairs at the queue's end (a probe of the nominal 2-user run, in
    // docs/benchmarks.md).
    let target_goal =
        if s.chains.contains(&Chain::Live) { Some(Goal::chain_target(stroke, &ran.live_target)?) } else { None };
    let mut goals: Vec<(&Goal, &floor::Seeds)> = Vec::new();
    if let Some(g) = &target_goal {
        goals.push((g, &target_seeds));
    }
    goals.push((&real, &stroke_seeds));
    let mut each = floor::optimize_goals(stroke, lab, &goals, s.floor_iterations)?;
    let seconds = t.elapsed().as_secs_f64();
    let (candidates, share) = each.pop().ok_or_else(|| StudyError::Config("the stroke's floor did not run".into()))?;
    let target = match each.pop() {
        Some((target_candidates, target_share)) => {
            let p = play_best(at, stroke, &target_candidates, "target-floor", "the target's floor")?;
            let c = &target_candidates[p.best];
            let seconds = seconds * target_share;
            Some(TargetFloor {
                sweep: p.sweep,
                reached: p.reached,
                start: c.start.clone(),
                objective: c.objective,
                seconds,
            })
        }
        None => None,
    };
    let p = play_best(at, stroke, &candidates, "floor", "the stroke's floor")?;
    let c = &candidates[p.best];
    // The best optimum without its reversals, played alike.
    let u = floor::sliding_only(&c.u, stroke);
    let file = play::write(
        &at.dir.join("floor-sliding"),
        stroke.rate,
        &u,
        &vec![0.0; stroke.len()],
        "evflow live study: the stroke's floor with nothing played around the reversals",
    )?;
    let sweep = play::sweep(at, &file, &s.gains)?;
    let chosen = choose(&sweep).ok_or_else(|| StudyError::Config("an empty gain sweep".into()))?;
    let stroke_floor = StrokeFloor {
        sweep: p.sweep,
        reached: p.reached,
        start: c.start.clone(),
        objective: c.objective,
        sliding_only: Reading { rect: chosen.best_rect.rect, welch: chosen.best_welch.welch },
        seconds: seconds * share,
    };
    Ok((stroke_floor, target))
}
