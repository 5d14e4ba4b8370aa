//! Running the study: the default models, the textures, every item.

use super::scope::NarxScope;
use super::setting::Setting;
use crate::models::{self, Models};
use crate::recordings::record_pair;
use crate::row::{self, Method, RowInputs};
use crate::setup::Profile;
use crate::StudyError;
use evflow_engine::batch::{for_each_ordered, Shard};
use evflow_nodes::narx::model::Model;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// One study to run: its [`NarxScope`], where the graphs are and the
/// output and work go, and its slice.
#[derive(Debug, Clone)]
pub struct NarxConfig {
    /// What it covers and how.
    pub scope: NarxScope,
    /// The folder of the shipped graphs.
    pub graphs: PathBuf,
    /// The output folder: `models/base` and `models/SETTING/seed-N`.
    pub out: PathBuf,
    /// A folder for the work files (recordings, syntheses); the caller
    /// removes it.
    pub work: PathBuf,
    /// Items at once.
    pub jobs: usize,
    /// The slice of the items to run.
    pub shard: Shard,
}

impl NarxConfig {
    /// The items of this config's shard, as indices into [`NarxScope::items`].
    pub fn range(&self) -> Range<usize> {
        self.shard.range(self.scope.total())
    }
}

/// One model's scores: a (setting, seed) trained and every texture
/// synthesized with it (saved with its floats exact, NaN included).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SeedScore {
    /// E_s at the Table 5.1 gain, the mean over the textures scored.
    #[serde(with = "crate::exact")]
    pub es: f64,
    /// E_s at the best gain of the sweep, the mean over the textures scored.
    #[serde(with = "crate::exact")]
    pub best: f64,
    /// Training time, s (0 when not recorded).
    #[serde(with = "crate::exact")]
    pub seconds: f64,
    /// Epochs run.
    pub epochs: usize,
    /// Closed-loop transition agreement on the validation block (NaN without one).
    #[serde(with = "crate::exact")]
    pub transitions: f64,
    /// Weights of the network.
    pub weights: usize,
}

/// One item: a (setting, seed), scored or failed.
#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    /// Its index among every item of the study.
    pub index: usize,
    /// The setting's index.
    pub setting: usize,
    /// The seed of the initial weights.
    pub seed: u32,
    /// Its scores, or why it failed.
    pub score: Result<SeedScore, String>,
}

/// A setting's row: the means over the seeds that were scored.
#[derive(Debug, Clone, PartialEq)]
pub struct Scored {
    /// The setting.
    pub setting: Setting,
    /// Seeds scored (0: every seed failed, and the numbers below are NaN).
    pub seeds: usize,
    /// Seeds tried.
    pub of: u32,
    /// Weights of the network.
    pub weights: usize,
    /// Mean training time, s.
    pub seconds: f64,
    /// Mean epochs.
    pub epochs: f64,
    /// Mean closed-loop transition agreement.
    pub transitions: f64,
    /// Mean E_s at the Table 5.1 gain.
    pub es: f64,
    /// Mean E_s at the best gain.
    pub best: f64,
    /// Smallest and largest E_s (Table 5.1 gain) of one seed.
    pub spread: (f64, f64),
}

/// What a study (or a shard of one) found.
#[derive(Debug, Clone)]
pub struct NarxStudy {
    /// The textures scored (those whose recording and optimized synthesis worked).
    pub textures: Vec<String>,
    /// The textures left out: (sample, why).
    pub left_out: Vec<(String, String)>,
    /// The items run, in order (a shard's slice).
    pub items: Vec<Item>,
    /// Every setting's row over the items run.
    pub scored: Vec<Scored>,
    /// Everything that failed, (what, why), in order: textures, then items.
    pub failures: Vec<(String, String)>,
}

/// What an item is called in the list of failures: "wide, seed 3".
pub fn item_label(settings: &[Setting], item: &Item) -> String {
    format!("{}, seed {}", settings[item.setting].name, item.seed)
}

/// Every failure, in order: the textures left out, then the items.
pub fn failures(settings: &[Setting], left_out: &[(String, String)], items: &[Item]) -> Vec<(String, String)> {
    let textures = left_out.iter().map(|(s, why)| (format!("texture {s}"), why.clone()));
    let items = items.iter().filter_map(|i| i.score.as_ref().err().map(|why| (item_label(settings, i), why.clone())));
    textures.chain(items).collect()
}

/// Every setting's row: the means over its items that were scored, summed
/// in item order (so a merge of shards gives the same numbers as one run).
pub fn aggregate(settings: &[Setting], seeds: u32, items: &[Item]) -> Vec<Scored> {
    settings
        .iter()
        .enumerate()
        .map(|(i, st)| {
            let (mut es, mut best, mut seconds, mut epochs, mut transitions, mut weights) =
                (0.0, 0.0, 0.0, 0.0, 0.0, 0);
            let mut spread = (f64::INFINITY, f64::NEG_INFINITY);
            let mut n = 0;
            for s in items.iter().filter(|it| it.setting == i).filter_map(|it| it.score.as_ref().ok()) {
                es += s.es;
                best += s.best;
                spread = (spread.0.min(s.es), spread.1.max(s.es));
                seconds += s.seconds;
                epochs += s.epochs as f64;
                transitions += s.transitions;
                weights = s.weights;
                n += 1;
            }
            let mean = |x: f64| if n == 0 { f64::NAN } else { x / n as f64 };
            if n == 0 {
                spread = (f64::NAN, f64::NAN);
            }
            Scored {
                setting: st.clone(),
                seeds: n,
                of: seeds,
                weights,
                seconds: mean(seconds),
                epochs: mean(epochs),
                transitions: mean(transitions),
                es: mean(es),
                best: mean(best),
                spread,
            }
        })
        .collect()
}

/// Which points no other point beats in both coordinates (training time,
/// E_s); points with a NaN coordinate are on no front.
pub fn pareto(points: &[(f64, f64)]) -> Vec<bool> {
    let ok = |&(t, e): &(f64, f64)| !t.is_nan() && !e.is_nan();
    points
        .iter()
        .map(|p| {
            let &(t, e) = p;
            ok(p) && !points.iter().filter(|q| ok(q)).any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))
        })
        .collect()
}

/// Runs the study (the config's shard of it): the condition's default
/// models, each texture's recording and optimized synthesis, then every
/// item on `cfg.jobs` threads; `progress` is called with each item as it
/// is received, in order. Fails only when nothing can be scored: a
/// config that cannot work, the default models, or every texture failed.
pub fn run(cfg: &NarxConfig, progress: &mut dyn FnMut(&Item)) -> Result<NarxStudy, StudyError> {
    cfg.scope.check()?;
    let profile = Profile::nominal();
    let cond = cfg.scope.condition;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |e: std::io::Error| StudyError::Io { path, message: e.to_string() }
    };
    std::fs::create_dir_all(&cfg.out).map_err(io(&cfg.out))?;
    std::fs::create_dir_all(&cfg.work).map_err(io(&cfg.work))?;
    let base_dir = if cfg.shard.k == 1 { cfg.out.join("models").join("base") } else { cfg.work.join("base") };
    let base = models::build(&cfg.graphs, &profile, &cond, cfg.scope.epochs, false, cfg.scope.times, &base_dir)
        .map_err(|e| e.at(format!("the default models at {}", cond.label())))?;
    let textures = cfg.work.join("textures");
    let never = Default::default();
    // Each texture recorded, and its optimized actuation synthesized, once.
    let prepare = |_: usize, s: &String| -> Result<(PathBuf, f64), StudyError> {
        record_pair(&cfg.graphs, &profile, s, &cond, &textures)?;
        let dir = cfg.work.join("optimized").join(s);
        row::optimize(&row_inputs(cfg, &profile, s, &base, &textures, dir))
    };
    let mut prepared = Vec::new();
    let mut left_out = Vec::new();
    for_each_ordered(cfg.scope.samples.iter().collect(), cfg.jobs, &never, prepare, |i, r| {
        let s = cfg.scope.samples[i].clone();
        match r.map_err(|p| format!("panicked: {p}")).and_then(|r| r.map_err(|e| e.to_string())) {
            Ok(o) => prepared.push((s, o)),
            Err(why) => left_out.push((s, why)),
        }
    });
    if prepared.is_empty() {
        let why: Vec<String> = left_out.iter().map(|(s, why)| format!("{s}: {why}")).collect();
        return Err(StudyError::Config(format!("every texture failed:\n{}", why.join("\n"))));
    }
    let all = cfg.scope.items();
    let range = cfg.range();
    let one = |_: usize, (i, seed): (usize, u32)| -> Result<SeedScore, StudyError> {
        let st = &cfg.scope.settings[i];
        let dir = cfg.out.join("models").join(&st.name).join(format!("seed-{seed}"));
        let mut sets = st.overrides().int("train.seed", seed);
        if !cfg.scope.times {
            sets = sets.flag("train.record_time", false);
        }
        let path = models::inverse(&cfg.graphs, &profile, &cond, cfg.scope.epochs, &sets, &dir)?;
        let model = Model::load(&path)?;
        let m = Models { narx: path, narx_multilevel: None, forward: base.forward.clone(), seconds: [0.0; 3] };
        let (mut es, mut best) = (0.0, 0.0);
        let n = prepared.len() as f64;
        for (s, opt) in &prepared {
            let work = cfg.work.join(&st.name).join(format!("seed-{seed}")).join(s);
            let mut inputs = row_inputs(cfg, &profile, s, &m, &textures, work);
            inputs.optimized = Some(opt.clone());
            let r = row::run(&inputs).map_err(|e| e.at(format!("{s} at {}", cond.label())))?;
            let narx = r
                .method(Method::NarxBinary)
                .ok_or_else(|| StudyError::Config(format!("{s}: the study scored no NARX chain")))?;
            es += narx.chosen.table51.rect / n;
            best += narx.chosen.best_rect.rect / n;
        }
        let t = &model.training;
        Ok(SeedScore {
            es,
            best,
            seconds: t.seconds,
            epochs: t.epochs,
            transitions: t.closed_loop.as_ref().map_or(f64::NAN, |c| c.transition_agreement),
            weights: model.weights.len(),
        })
    };
    let mine = &all[range.clone()];
    let mut items = Vec::with_capacity(mine.len());
    for_each_ordered(mine.to_vec(), cfg.jobs, &never, one, |k, r| {
        let (index, (setting, seed)) = (range.start + k, mine[k]);
        let score = r.map_err(|p| format!("panicked: {p}")).and_then(|r| r.map_err(|e| e.to_string()));
        let item = Item { index, setting, seed, score };
        progress(&item);
        items.push(item);
    });
    let scored = aggregate(&cfg.scope.settings, cfg.scope.seeds, &items);
    let failures = failures(&cfg.scope.settings, &left_out, &items);
    Ok(NarxStudy { textures: prepared.into_iter().map(|(s, _)| s).collect(), left_out, items, scored, failures })
}

/// The study's inputs for `sample` with `models` (the optimized actuation
/// to be filled in by the caller when it has one).
fn row_inputs<'a>(
    cfg: &'a NarxConfig,
    profile: &'a Profile,
    sample: &'a str,
    models: &'a Models,
    recordings: &'a Path,
    dir: PathBuf,
) -> RowInputs<'a> {
    RowInputs {
        graphs: &cfg.graphs,
        profile,
        sample,
        cond: cfg.scope.condition,
        models,
        recordings,
        gains: &cfg.scope.gains,
        iterations: cfg.scope.iterations,
        objective: "expected",
        optimized: None,
        dir,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::Cond;

    #[test]
    fn the_pareto_front_keeps_what_nothing_beats_in_both() {
        // (1, 0.5) and (2, 0.4) and (0.5, 0.9) trade off; (3, 0.6) is beaten
        // by both of the first; a duplicate of a front point stays on it; a
        // failed setting (NaN) is on no front and beats nothing.
        let p = [(1.0, 0.5), (2.0, 0.4), (3.0, 0.6), (0.5, 0.9), (1.0, 0.5), (f64::NAN, f64::NAN)];
        assert_eq!(pareto(&p), vec![true, true, false, true, true, false]);
    }

    fn score(es: f64, seconds: f64) -> SeedScore {
        SeedScore { es, best: es / 2.0, seconds, epochs: 10, transitions: 0.5, weights: 86 }
    }

    #[test]
    fn failed_seeds_are_left_out_of_their_settings_means() {
        let settings: Vec<Setting> =
            ["a=5/1/10/lm", "b=3/1/5/adam", "c=5/1/1000/lm"].iter().map(|s| Setting::parse(s).unwrap()).collect();
        let ok = |index, setting, seed, s: SeedScore| Item { index, setting, seed, score: Ok(s) };
        let failed = |index, setting, seed| Item { index, setting, seed, score: Err(format!("broke {index}")) };
        let items = vec![
            ok(0, 0, 1, score(0.4, 1.0)),
            failed(1, 0, 2),
            ok(2, 0, 3, score(0.8, 3.0)),
            ok(3, 1, 1, score(0.6, 2.5)),
            ok(4, 1, 2, score(0.8, 2.5)),
            ok(5, 1, 3, score(0.7, 2.5)),
            failed(6, 2, 1),
            failed(7, 2, 2),
            failed(8, 2, 3),
        ];
        let s = aggregate(&settings, 3, &items);
        // a: the means over seeds 1 and 3 only.
        assert_eq!((s[0].seeds, s[0].of), (2, 3));
        assert!((s[0].es - 0.6).abs() < 1e-15 && (s[0].best - 0.3).abs() < 1e-15, "{:?}", s[0]);
        assert_eq!((s[0].seconds, s[0].epochs, s[0].spread), (2.0, 10.0, (0.4, 0.8)));
        assert_eq!((s[1].seeds, s[1].spread), (3, (0.6, 0.8)));
        assert!((s[1].es - 0.7).abs() < 1e-15);
        // c: every seed failed, no scores.
        assert_eq!((s[2].seeds, s[2].of), (0, 3));
        assert!(s[2].es.is_nan() && s[2].seconds.is_nan() && s[2].spread.0.is_nan());
        let f = failures(&settings, &[("felt-fabric".into(), "no recording".into())], &items);
        let labels: Vec<&str> = f.iter().map(|(l, _)| l.as_str()).collect();
        assert_eq!(labels, ["texture felt-fabric", "a, seed 2", "c, seed 1", "c, seed 2", "c, seed 3"]);
        assert_eq!(f[1].1, "broke 1");
        // The failed setting is on no front; b is slower and worse than a.
        let front = pareto(&s.iter().map(|s| (s.seconds, s.es)).collect::<Vec<_>>());
        assert_eq!(front, [true, false, false]);
    }

    #[test]
    fn items_are_settings_by_seeds_and_shards_cut_them_in_order() {
        let mut cfg = NarxConfig {
            scope: NarxScope {
                condition: Cond { mass: 60.0, speed: 5.0 },
                settings: ["a=5/1/10/lm", "b=3/1/5/adam"].iter().map(|s| Setting::parse(s).unwrap()).collect(),
                samples: vec!["plastic-sheet".into()],
                gains: vec![1.0],
                seeds: 2,
                epochs: 3,
                iterations: 3,
                times: true,
            },
            graphs: "graphs".into(),
            out: "out".into(),
            work: "work".into(),
            jobs: 1,
            shard: Shard { k: 2, n: 3 },
        };
        assert_eq!(cfg.scope.items(), [(0, 1), (0, 2), (1, 1), (1, 2)]);
        assert_eq!(cfg.range(), 2..3);
        cfg.scope.check().unwrap();
        cfg.scope.settings.push(Setting::parse("a=1/1/1/lm").unwrap());
        assert_eq!(cfg.scope.check().unwrap_err().to_string(), "settings: the name `a` is given twice");
        cfg.scope.settings.pop();
        cfg.scope.samples.push("plastic-sheet".into());
        assert_eq!(cfg.scope.check().unwrap_err().to_string(), "samples: `plastic-sheet` is given twice");
        cfg.scope.samples.pop();
        cfg.scope.samples.push("no-such-sample".into());
        assert!(cfg.scope.check().unwrap_err().to_string().starts_with("samples: "));
    }
}
