//! A shard of a texture study, saved and read back: `evflow report textures
//! --shard K/N` writes what its slice of the (profile, condition) cells
//! found — every row, every model, every failure — into
//! `textures-shard.json` in its output folder, and `evflow merge` reads the
//! shards back to write the tables one run would have written.
//!
//! Paths (a row's folder, the model files) are saved relative to the
//! shard's output folder and put back under the merge's; floats are saved
//! as exact text ([`super::exact`]), so a merged row is the row the shard
//! computed, bit for bit. The scope — everything that must agree across
//! shards for them to be one study — is saved beside.

use super::models::Models;
use super::row::Row;
use super::run::{Study, StudyConfig};
use super::scope::Scope;
use super::setup::Cond;
use super::shard_file::{self, SavedFailure, StudyRecord};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The name of a study shard's record in its output folder.
pub const RECORD: &str = "textures-shard.json";

/// The models of one profile and condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedModels {
    /// Lab profile.
    pub profile: String,
    /// Condition.
    pub cond: Cond,
    /// The model files (relative to the shard's folder when saved).
    pub models: Models,
}

/// One shard's study, as saved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedStudy {
    /// Which slice, `K/N`.
    pub shard: String,
    /// (profile, condition) cells in the whole study.
    pub cells: usize,
    /// The slice's cells among them, `[start, end)`.
    pub range: [usize; 2],
    /// What must agree across shards.
    pub scope: Scope,
    /// Every row the shard ran, in study order.
    pub rows: Vec<Row>,
    /// Every model the shard built, in study order.
    pub models: Vec<SavedModels>,
    /// Every step that failed, in study order.
    pub failures: Vec<SavedFailure>,
    /// The shard's wall-clock time, s.
    #[serde(with = "super::exact")]
    pub seconds: f64,
}

/// `p` relative to `base` when it lies inside it, else as it is.
fn relative(p: &Path, base: &Path) -> PathBuf {
    p.strip_prefix(base).map(Path::to_path_buf).unwrap_or_else(|_| p.to_path_buf())
}

fn rebase_models(m: &Models, f: &dyn Fn(&Path) -> PathBuf) -> Models {
    Models {
        narx: f(&m.narx),
        narx_multilevel: m.narx_multilevel.as_deref().map(f),
        forward: f(&m.forward),
        seconds: m.seconds,
    }
}

impl SavedStudy {
    /// What `study` (run with `cfg`, whose output folder is `base`) saves.
    pub fn of(study: &Study, cfg: &StudyConfig, base: &Path) -> Self {
        let rel = |p: &Path| relative(p, base);
        let all = cfg.all_cells().len();
        let range = cfg.shard.range(all);
        Self {
            shard: cfg.shard.to_string(),
            cells: all,
            range: [range.start, range.end],
            scope: cfg.scope.clone(),
            rows: study.rows.iter().map(|r| Row { dir: rel(&r.dir), ..r.clone() }).collect(),
            models: study
                .models
                .iter()
                .map(|(p, c, m)| SavedModels { profile: p.clone(), cond: *c, models: rebase_models(m, &rel) })
                .collect(),
            failures: study.failures.iter().map(|(s, r)| SavedFailure { step: s.clone(), reason: r.clone() }).collect(),
            seconds: study.seconds,
        }
    }

    /// The study of several shards' records (in K order), with every path
    /// put under `base`: rows and models one after another, the failures
    /// labelled with their shard, the times added up.
    pub fn join<'a>(shards: impl IntoIterator<Item = &'a SavedStudy>, base: &Path) -> Study {
        let under = |p: &Path| shard_file::under(base, p);
        let mut study = Study { rows: Vec::new(), models: Vec::new(), seconds: 0.0, failures: Vec::new() };
        for s in shards {
            study.rows.extend(s.rows.iter().map(|r| Row { dir: under(&r.dir), ..r.clone() }));
            study.models.extend(s.models.iter().map(|m| (m.profile.clone(), m.cond, rebase_models(&m.models, &under))));
            study.failures.extend(shard_file::failures_of(&s.shard, &s.failures));
            study.seconds += s.seconds;
        }
        study
    }
}

impl StudyRecord for SavedStudy {
    const RECORD: &'static str = RECORD;
    const COMMAND: &'static str = "evflow report textures";
    const WHAT: &'static str = "a study shard's record";
    const UNIT: &'static str = "cells";

    fn shard(&self) -> &str {
        &self.shard
    }

    fn total(&self) -> usize {
        self.cells
    }

    fn range(&self) -> [usize; 2] {
        self.range
    }
}

#[cfg(test)]
mod tests {
    use super::super::gains::{AtGain, Chosen};
    use super::super::row::{Achievable, Method, MethodResult, Reading};
    use super::super::setup::Profile;
    use super::*;
    use evflow_engine::batch::Shard;

    fn config(shard: Shard) -> StudyConfig {
        StudyConfig {
            profiles: vec![
                Profile::nominal(),
                Profile { name: "stiff".into(), path: Some("/g/lab/stiff.toml".into()) },
            ],
            scope: Scope {
                profiles: vec!["nominal".into(), "stiff".into()],
                samples: vec!["felt-fabric".into()],
                conds: vec![Cond { mass: 60.0, speed: 3.0 }, Cond { mass: 110.0, speed: 5.0 }],
                gains: vec![0.6, 1.0],
                epochs: 3,
                iterations: 4,
                multilevel: false,
                floor: true,
                objective: "expected".into(),
                times: true,
            },
            graphs: "/g".into(),
            work: "/out/work".into(),
            shard,
        }
    }

    fn row(profile: &str, cond: Cond) -> Row {
        let at = AtGain { gain: 0.6, rect: 0.1 + cond.mass, welch: f64::NAN, peak_ratio: f64::INFINITY };
        Row {
            profile: profile.into(),
            sample: "felt-fabric".into(),
            cond,
            repeat: Reading { rect: 1.0 / 3.0, welch: -0.0 },
            display_floor: Reading::default(),
            achievable: Some(Achievable {
                sweep: vec![at],
                reached: Reading { rect: 0.2, welch: 0.3 },
                objective: 1e-300,
                seconds: 2.5,
            }),
            methods: vec![MethodResult {
                method: Method::NarxBinary,
                sweep: vec![at, at],
                chosen: Chosen { table51: at, best_rect: at, best_welch: at },
                seconds: 0.25,
            }],
            dir: format!("/out/work/{profile}/rows/felt-fabric-{}", cond.tag()).into(),
        }
    }

    fn models(profile: &str, cond: Cond) -> Models {
        let d = PathBuf::from(format!("/out/work/{profile}/models"));
        Models {
            narx: d.join(format!("narx-{}.json", cond.tag())),
            narx_multilevel: None,
            forward: d.join("forward.json"),
            seconds: [1.0, 0.0, f64::NAN],
        }
    }

    /// The shard's study: its cells' rows and models, one failure.
    fn shard_study(cfg: &StudyConfig) -> Study {
        let cells = cfg.cells();
        Study {
            rows: cells.iter().map(|(p, c)| row(&p.name, *c)).collect(),
            models: cells.iter().map(|(p, c)| (p.name.clone(), *c, models(&p.name, *c))).collect(),
            seconds: 10.0,
            failures: vec![("stiff: felt-fabric at 60 g, 3 cm/s".into(), "it broke".into())],
        }
    }

    #[test]
    fn shards_saved_read_and_joined_are_the_one_study_under_the_new_folder() {
        let dir = tempfile::tempdir().unwrap();
        let mut saved = Vec::new();
        for k in 1..=3 {
            let mut cfg = config(Shard { k, n: 3 });
            cfg.scope.times = false;
            let d = dir.path().join(format!("s{k}"));
            std::fs::create_dir_all(&d).unwrap();
            SavedStudy::of(&shard_study(&cfg), &cfg, Path::new("/out")).write(&d).unwrap();
            assert!(SavedStudy::is_in(&d));
            saved.push(SavedStudy::read(&d).unwrap());
        }
        // 2 profiles × 2 conditions in 3 shards: 2, 1 and 1 cells.
        assert_eq!(saved.iter().map(|s| s.rows.len()).collect::<Vec<_>>(), [2, 1, 1]);
        assert_eq!(saved[0].rows[0].dir, Path::new("work/nominal/rows/felt-fabric-60g-3cms"));
        let joined = SavedStudy::join(&saved, Path::new("/merged"));
        // The whole study's rows, bit for bit (NaN, infinity, -0.0, 1e-300
        // included), in study order, under the merge's folder.
        let whole = config(Shard::ALL);
        let expected: Vec<Row> = whole
            .cells()
            .iter()
            .map(|(p, c)| {
                let r = row(&p.name, *c);
                Row { dir: Path::new("/merged").join(r.dir.strip_prefix("/out").unwrap()), ..r }
            })
            .collect();
        let bits =
            |rows: &[Row]| format!("{:?}", rows.iter().map(|r| serde_json::to_string(r).unwrap()).collect::<Vec<_>>());
        assert_eq!(bits(&joined.rows), bits(&expected));
        assert!(joined.rows[0].repeat.welch.is_sign_negative());
        assert!(joined.rows[0].methods[0].chosen.table51.welch.is_nan());
        assert_eq!(joined.models[3].2.narx, Path::new("/merged/work/stiff/models/narx-110g-5cms.json"));
        assert!(joined.models[0].2.seconds[2].is_nan());
        assert_eq!(joined.failures.len(), 3);
        assert_eq!(joined.failures[1].0, "stiff: felt-fabric at 60 g, 3 cm/s (shard 2/3)");
        assert_eq!(joined.seconds, 30.0);
        assert_eq!(StudyConfig::merged(saved[0].scope.clone(), Path::new("/m"), Shard::ALL).all_cells().len(), 4);
    }

    #[test]
    fn a_malformed_or_misplaced_record_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let e = SavedStudy::read(dir.path()).unwrap_err().to_string();
        assert!(e.contains(RECORD) && e.contains("--shard"), "{e}");
        std::fs::write(dir.path().join(RECORD), "{\"shard\": \"1/2\",\n \"cells\": 4,\n \"range\": [0, 2]\n}").unwrap();
        let e = SavedStudy::read(dir.path()).unwrap_err().to_string();
        assert!(e.contains(RECORD) && e.contains("missing field") && e.contains("line"), "{e}");
        // A record whose range is not its K/N's.
        let cfg = config(Shard { k: 1, n: 2 });
        let mut s = SavedStudy::of(&shard_study(&cfg), &cfg, Path::new("/out"));
        s.range = [0, 3];
        s.write(dir.path()).unwrap();
        let e = SavedStudy::read(dir.path()).unwrap_err().to_string();
        assert!(e.contains("should hold cells 0..2"), "{e}");
        s.shard = "3/2".into();
        s.write(dir.path()).unwrap();
        let e = SavedStudy::read(dir.path()).unwrap_err().to_string();
        assert!(e.contains("3/2"), "{e}");
    }
}
