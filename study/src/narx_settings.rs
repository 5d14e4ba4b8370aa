//! Error against training time of the inverse NARX model over network
//! settings (issue 6, point 10; `evflow report narx`).
//!
//! For each network setting — hidden layers, tap delays, trainer — models
//! are trained for one condition with `graphs/model-build.toml` (one per
//! seed); every texture's force at that condition is synthesized with each
//! and played on the virtual display over the gain sweep
//! (`graphs/synthesize.toml`, every method in one run, as the texture
//! study does), the gain chosen by Table 5.1's rule (and, as a second
//! reading, the best E_s). The optimized synthesis the graph also plays is
//! computed once per texture (through the condition's forward model) and
//! reused.
//!
//! **Items and shards.** The items are the (setting, seed) pairs, settings
//! in the order given, seeds 1 … N within each; a shard (`K/N`) trains and
//! scores its contiguous slice of them. The condition's default models
//! (`models/base`) and the textures' recordings and optimized syntheses are
//! shared by every item and are computed by every shard: they are
//! deterministic, so each shard computes the same ones. Only shard 1 (or a
//! run without shards) keeps the default models in the output folder; the
//! others build them in the work folder, so that the shards' folders merge
//! without two versions of one file.
//!
//! **Failures.** One failing item does not lose the others: a failed
//! (setting, seed) is left out of its setting's means ([`Scored::seeds`]
//! says over how many seeds a row is), a setting whose every seed failed has
//! no scores, and a texture whose recording or optimized synthesis failed is
//! left out of every setting's scores; every failure is listed with its
//! reason ([`NarxStudy::failures`]).

use super::graphs::Sets;
use super::models::{self, Models};
use super::recordings::record_pair;
use super::row::{self, Method, RowInputs};
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_engine::batch::{for_each_ordered, Shard};
use evflow_nodes::narx::model::Model;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The settings compared by default; the first is evflow's default network.
pub const DEFAULT_SETTINGS: &[&str] = &[
    "default=15-10-5/1/10/lm",
    "one-layer-5=5/1/10/lm",
    "one-layer-15=15/1/10/lm",
    "wide=30-20-10/1/10/lm",
    "input-5=15-10-5/1/5/lm",
    "input-20=15-10-5/1/20/lm",
    "feedback-2=15-10-5/2/10/lm",
    "adam=15-10-5/1/10/adam",
    "adam-one-layer-5=5/1/10/adam",
];

/// One network setting: `NAME=HIDDEN/FEEDBACK/INPUT/TRAINER`.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// Its name (the folder of its models, the table's first column).
    pub name: String,
    /// Hidden layer sizes.
    pub hidden: Vec<usize>,
    /// Feedback taps k_y.
    pub feedback: usize,
    /// Input taps k_x.
    pub input: usize,
    /// The trainer: `lm` or `adam`.
    pub algorithm: String,
}

impl Setting {
    /// Parses `NAME=HIDDEN/FEEDBACK/INPUT/TRAINER`, hidden layers joined by
    /// `-` (e.g. `small=5/1/10/lm`).
    pub fn parse(s: &str) -> Result<Self, StudyError> {
        let bad = |m: &str| StudyError::Config(format!("setting `{s}`: {m}"));
        let (name, rest) = s.split_once('=').ok_or_else(|| bad("not NAME=HIDDEN/FEEDBACK/INPUT/TRAINER"))?;
        let parts: Vec<&str> = rest.split('/').collect();
        if parts.len() != 4 {
            return Err(bad("give HIDDEN/FEEDBACK/INPUT/TRAINER, e.g. 15-10-5/1/10/lm"));
        }
        let hidden = parts[0]
            .split('-')
            .map(|h| h.trim().parse::<usize>().ok().filter(|&h| h > 0))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad("hidden layers are sizes ≥ 1 joined by `-`"))?;
        let num = |x: &str, what: &str| {
            x.trim().parse::<usize>().map_err(|_| bad(&format!("{what} `{x}` is not a whole number")))
        };
        let algorithm = parts[3].trim().to_string();
        if algorithm != "lm" && algorithm != "adam" {
            return Err(bad("the trainer is lm or adam"));
        }
        let name = name.trim();
        if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." || name == "base" {
            return Err(bad("the name is a folder name: not empty, no `/`, not `base`"));
        }
        Ok(Self {
            name: name.into(),
            hidden,
            feedback: num(parts[1], "feedback")?,
            input: num(parts[2], "input")?,
            algorithm,
        })
    }

    /// The setting as [`Setting::parse`] reads it.
    pub fn spec(&self) -> String {
        let h: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        format!("{}={}/{}/{}/{}", self.name, h.join("-"), self.feedback, self.input, self.algorithm)
    }

    /// The values of graphs/model-build.toml that select it.
    pub fn overrides(&self) -> Sets {
        let hidden: Vec<f64> = self.hidden.iter().map(|&h| h as f64).collect();
        Sets::new()
            .nums("train.hidden", &hidden)
            .int("train.feedback", self.feedback as i64)
            .int("train.input", self.input as i64)
            .text("train.algorithm", &self.algorithm)
    }

    /// "15-10-5, k_y 1, k_x 10, LM".
    pub fn describe(&self) -> String {
        let h: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        format!("{}, k_y {}, k_x {}, {}", h.join("-"), self.feedback, self.input, self.algorithm.to_uppercase())
    }
}

/// What one study computes, and where.
#[derive(Debug, Clone)]
pub struct NarxConfig {
    /// The condition the models are trained and scored at.
    pub condition: Cond,
    /// The network settings, in the table's order.
    pub settings: Vec<Setting>,
    /// The texture samples scored.
    pub samples: Vec<String>,
    /// The gain sweep (§5.3.2).
    pub gains: Vec<f64>,
    /// Models per setting, from seeds 1 … `seeds`.
    pub seeds: u32,
    /// Epochs at most per model.
    pub epochs: u32,
    /// Iterations at most of the optimized synthesis.
    pub iterations: usize,
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
    /// Whether the setting models record their training time (off: the
    /// model files and every score are the same on every run).
    pub record_time: bool,
}

impl NarxConfig {
    /// Every item of the whole study, in order: (setting index, seed).
    pub fn items(&self) -> Vec<(usize, u32)> {
        let seeds = self.seeds;
        (0..self.settings.len()).flat_map(|i| (1..=seeds).map(move |seed| (i, seed))).collect()
    }

    /// The items of this config's shard, as indices into [`NarxConfig::items`].
    pub fn range(&self) -> Range<usize> {
        self.shard.range(self.settings.len() * self.seeds as usize)
    }

    /// Checks what can be checked before anything runs.
    pub fn check(&self) -> Result<(), StudyError> {
        let bad = |m: String| Err(StudyError::Config(m));
        if self.seeds == 0 {
            return bad("seeds: at least 1".into());
        }
        if self.settings.is_empty() {
            return bad("settings: at least one".into());
        }
        for (i, s) in self.settings.iter().enumerate() {
            if self.settings[..i].iter().any(|t| t.name == s.name) {
                return bad(format!("settings: the name `{}` is given twice", s.name));
            }
        }
        if self.samples.is_empty() {
            return bad("samples: at least one".into());
        }
        for (i, s) in self.samples.iter().enumerate() {
            evflow_nodes::lab::texture::samples::lookup(s).map_err(|e| StudyError::Config(format!("samples: {e}")))?;
            if self.samples[..i].contains(s) {
                return bad(format!("samples: `{s}` is given twice"));
            }
        }
        if self.gains.is_empty() || !self.gains.iter().all(|g| g.is_finite() && *g > 0.0) {
            return bad("gains: positive numbers".into());
        }
        Ok(())
    }
}

/// One model's scores: a (setting, seed) trained and every texture
/// synthesized with it.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedScore {
    /// E_s at the Table 5.1 gain, the mean over the textures scored.
    pub es: f64,
    /// E_s at the best gain of the sweep, the mean over the textures scored.
    pub best: f64,
    /// Training time, s (0 when not recorded).
    pub seconds: f64,
    /// Epochs run.
    pub epochs: usize,
    /// Closed-loop transition agreement on the validation block (NaN without one).
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
    cfg.check()?;
    let profile = Profile::nominal();
    let cond = cfg.condition;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |e: std::io::Error| StudyError::Io { path, message: e.to_string() }
    };
    std::fs::create_dir_all(&cfg.out).map_err(io(&cfg.out))?;
    std::fs::create_dir_all(&cfg.work).map_err(io(&cfg.work))?;
    let base_dir = if cfg.shard.k == 1 { cfg.out.join("models").join("base") } else { cfg.work.join("base") };
    let base = models::build(&cfg.graphs, &profile, &cond, cfg.epochs, false, cfg.record_time, &base_dir)
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
    for_each_ordered(cfg.samples.iter().collect(), cfg.jobs, &never, prepare, |i, r| {
        let s = cfg.samples[i].clone();
        match r.map_err(|p| format!("panicked: {p}")).and_then(|r| r.map_err(|e| e.to_string())) {
            Ok(o) => prepared.push((s, o)),
            Err(why) => left_out.push((s, why)),
        }
    });
    if prepared.is_empty() {
        let why: Vec<String> = left_out.iter().map(|(s, why)| format!("{s}: {why}")).collect();
        return Err(StudyError::Config(format!("every texture failed:\n{}", why.join("\n"))));
    }
    let all = cfg.items();
    let range = cfg.range();
    let one = |_: usize, (i, seed): (usize, u32)| -> Result<SeedScore, StudyError> {
        let st = &cfg.settings[i];
        let dir = cfg.out.join("models").join(&st.name).join(format!("seed-{seed}"));
        let mut sets = st.overrides().int("train.seed", seed);
        if !cfg.record_time {
            sets = sets.flag("train.record_time", false);
        }
        let path = models::inverse(&cfg.graphs, &profile, &cond, cfg.epochs, &sets, &dir)?;
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
    let scored = aggregate(&cfg.settings, cfg.seeds, &items);
    let failures = failures(&cfg.settings, &left_out, &items);
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
        cond: cfg.condition,
        models,
        recordings,
        gains: &cfg.gains,
        iterations: cfg.iterations,
        objective: "expected",
        optimized: None,
        dir,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::Value;

    #[test]
    fn settings_parse_into_model_build_overrides() {
        let s = Setting::parse("wide=30-20-10/2/15/adam").unwrap();
        assert_eq!((s.hidden.clone(), s.feedback, s.input, s.algorithm.as_str()), (vec![30, 20, 10], 2, 15, "adam"));
        let o = s.overrides();
        assert_eq!(o.get("train.hidden"), Some(&Value::FloatList(vec![30.0, 20.0, 10.0])));
        assert_eq!(o.get("train.feedback"), Some(&Value::Int(2)));
        assert_eq!(o.get("train.input"), Some(&Value::Int(15)));
        assert_eq!(o.get("train.algorithm"), Some(&Value::Text("adam".into())));
        assert_eq!(Setting::parse(&s.spec()).unwrap(), s);
        for bad in
            ["x", "x=15/1/10", "x=15-0/1/10/lm", "x=15/a/10/lm", "x=15/1/10/sgd", "a/b=5/1/10/lm", "base=5/1/1/lm"]
        {
            assert!(Setting::parse(bad).is_err(), "{bad}");
        }
        for d in DEFAULT_SETTINGS {
            Setting::parse(d).unwrap();
        }
    }

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
            condition: Cond { mass: 60.0, speed: 5.0 },
            settings: ["a=5/1/10/lm", "b=3/1/5/adam"].iter().map(|s| Setting::parse(s).unwrap()).collect(),
            samples: vec!["plastic-sheet".into()],
            gains: vec![1.0],
            seeds: 2,
            epochs: 3,
            iterations: 3,
            graphs: "graphs".into(),
            out: "out".into(),
            work: "work".into(),
            jobs: 1,
            shard: Shard { k: 2, n: 3 },
            record_time: true,
        };
        assert_eq!(cfg.items(), [(0, 1), (0, 2), (1, 1), (1, 2)]);
        assert_eq!(cfg.range(), 2..3);
        cfg.check().unwrap();
        cfg.settings.push(Setting::parse("a=1/1/1/lm").unwrap());
        assert_eq!(cfg.check().unwrap_err().to_string(), "settings: the name `a` is given twice");
        cfg.settings.pop();
        cfg.samples.push("plastic-sheet".into());
        assert_eq!(cfg.check().unwrap_err().to_string(), "samples: `plastic-sheet` is given twice");
        cfg.samples.pop();
        cfg.samples.push("no-such-sample".into());
        assert!(cfg.check().unwrap_err().to_string().starts_with("samples: "));
    }
}
