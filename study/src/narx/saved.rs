//! The record of a shard of `evflow report narx --shard K/N`
//! (`narx-shard.json` in its `--out`): which slice it ran, the study's
//! [`NarxScope`] (which every shard must share), the textures scored and
//! left out, and every one of its items' scores in full (floats as Rust's
//! shortest exact text, so they read back bit for bit, NaN and infinities
//! included), so that `evflow merge` can write the table one run would
//! have written. Saved as the texture and live studies' records are
//! ([`crate::shard_file`]).

use super::run::{Item, NarxConfig, NarxStudy, SeedScore};
use super::scope::NarxScope;
use crate::shard_file::{self, StudyRecord};
use crate::StudyError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The name of the record in a shard's output folder.
pub const NARX_RECORD: &str = "narx-shard.json";

/// One item as saved: its setting by name, its scores or why it failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedItem {
    /// Its index among every item of the study.
    pub index: usize,
    /// The setting's name.
    pub setting: String,
    /// The seed of the initial weights.
    pub seed: u32,
    /// Its scores, when it was scored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub score: Option<SeedScore>,
    /// Why it failed, when it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed: Option<String>,
}

/// What a shard of `report narx` ran and found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NarxRecord {
    /// Which slice, `K/N`.
    pub shard: String,
    /// Items (setting, seed) in the whole study.
    pub total: usize,
    /// The slice's items among them, `[start, end)`.
    pub range: [usize; 2],
    /// What the study covers.
    pub scope: NarxScope,
    /// The textures scored.
    pub textures: Vec<String>,
    /// The textures left out, with why.
    pub left_out: Vec<(String, String)>,
    /// The slice's items, in order.
    pub items: Vec<SavedItem>,
}

impl NarxRecord {
    /// What `study`, run with `cfg`, saves.
    pub fn of(study: &NarxStudy, cfg: &NarxConfig) -> Self {
        let range = cfg.range();
        let settings = &cfg.scope.settings;
        Self {
            shard: cfg.shard.to_string(),
            total: cfg.scope.total(),
            range: [range.start, range.end],
            scope: cfg.scope.clone(),
            textures: study.textures.clone(),
            left_out: study.left_out.clone(),
            items: study
                .items
                .iter()
                .map(|i| SavedItem {
                    index: i.index,
                    setting: settings[i.setting].name.clone(),
                    seed: i.seed,
                    score: i.score.as_ref().ok().cloned(),
                    failed: i.score.as_ref().err().cloned(),
                })
                .collect(),
        }
    }

    /// The items, their settings as indices into the scope's.
    pub fn items(&self) -> Result<Vec<Item>, StudyError> {
        let settings = &self.scope.settings;
        self.items
            .iter()
            .enumerate()
            .map(|(n, i)| {
                let bad = |m: String| StudyError::Config(format!("item {}: {m}", n + 1));
                let setting = settings
                    .iter()
                    .position(|s| s.name == i.setting)
                    .ok_or_else(|| bad(format!("no setting `{}` in the scope", i.setting)))?;
                let score = match (&i.score, &i.failed) {
                    (Some(s), None) => Ok(s.clone()),
                    (None, Some(why)) => Err(why.clone()),
                    _ => return Err(bad("give either `score` or `failed`".into())),
                };
                Ok(Item { index: i.index, setting, seed: i.seed, score })
            })
            .collect()
    }
}

impl StudyRecord for NarxRecord {
    const RECORD: &'static str = NARX_RECORD;
    const COMMAND: &'static str = "evflow report narx";
    const WHAT: &'static str = "a narx report shard's record";
    const UNIT: &'static str = "items";

    fn shard(&self) -> &str {
        &self.shard
    }

    fn total(&self) -> usize {
        self.total
    }

    fn range(&self) -> [usize; 2] {
        self.range
    }

    /// Reads the record in `dir`, checked: its total is the scope's, its
    /// slice its `K/N`'s, its items that slice in order, each naming a
    /// setting of the scope and either scored or failed. Errors name the
    /// file and what is wrong.
    fn read(dir: &Path) -> Result<Self, StudyError> {
        let saved = Self::read_unchecked(dir)?;
        let bad = |m: String| StudyError::Io { path: dir.join(NARX_RECORD), message: m };
        if saved.total != saved.scope.total() {
            let s = &saved.scope;
            return Err(bad(format!("`total` is not {} settings × {} seeds", s.settings.len(), s.seeds)));
        }
        shard_file::slice(dir, NARX_RECORD, &saved.shard, saved.total, saved.range, "items")?;
        if !saved.items.iter().map(|i| i.index).eq(saved.range[0]..saved.range[1]) {
            return Err(bad(format!("the items are not items {:?} in order", saved.range[0]..saved.range[1])));
        }
        saved.items().map_err(|e| bad(e.to_string()))?;
        Ok(saved)
    }
}

#[cfg(test)]
mod tests {
    use super::super::setting::Setting;
    use super::*;
    use crate::setup::Cond;
    use evflow_engine::batch::Shard;
    use serde_json::{json, Value as Json};

    /// Shard `shard` of 2 settings × 2 seeds, with awkward floats and a failure.
    fn record(shard: Shard) -> NarxRecord {
        let scope = NarxScope {
            condition: Cond { mass: 60.0, speed: 0.1 + 0.2 },
            settings: ["a=5/1/10/lm", "b=3/1/5/adam"].iter().map(|s| Setting::parse(s).unwrap()).collect(),
            samples: vec!["plastic-sheet".into(), "felt-fabric".into()],
            gains: vec![1.0 / 3.0, 1.4],
            seeds: 2,
            epochs: 3,
            iterations: 3,
            times: false,
        };
        let cfg = NarxConfig { scope, graphs: "g".into(), out: "o".into(), work: "w".into(), jobs: 1, shard };
        let items: Vec<Item> = cfg
            .range()
            .map(|index| Item {
                index,
                setting: index / 2,
                seed: (index % 2 + 1) as u32,
                score: if index == 1 {
                    Err("the recording is too short:\nsecond line".into())
                } else {
                    Ok(SeedScore {
                        es: 1.0 / (index + 3) as f64,
                        best: 5e-324,
                        seconds: index as f64 * 0.1,
                        epochs: 3,
                        transitions: if index == 2 { f64::NAN } else { f64::INFINITY },
                        weights: 86,
                    })
                },
            })
            .collect();
        let study = NarxStudy {
            textures: vec!["plastic-sheet".into()],
            left_out: vec![("felt-fabric".into(), "it broke".into())],
            items,
            scored: Vec::new(),
            failures: Vec::new(),
        };
        NarxRecord::of(&study, &cfg)
    }

    #[test]
    fn a_record_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let rec = record(Shard::ALL);
        rec.write(dir.path()).unwrap();
        assert!(!dir.path().join(format!("{NARX_RECORD}.tmp")).exists());
        let back = NarxRecord::read(dir.path()).unwrap();
        // NaN is not equal to itself: compare the bits.
        let bits = |r: &NarxRecord| -> Vec<[u64; 4]> {
            r.items
                .iter()
                .filter_map(|i| i.score.as_ref())
                .map(|s| [s.es.to_bits(), s.best.to_bits(), s.seconds.to_bits(), s.transitions.to_bits()])
                .collect()
        };
        assert_eq!(bits(&back), bits(&rec));
        assert_eq!(back.scope, rec.scope);
        assert_eq!((&back.shard, &back.textures, &back.left_out), (&rec.shard, &rec.textures, &rec.left_out));
        assert_eq!(back.items[1], rec.items[1]);
        let items = back.items().unwrap();
        assert_eq!(items.len(), 4);
        assert_eq!((items[3].setting, items[3].seed), (1, 2));
        assert_eq!(items[1].score, Err("the recording is too short:\nsecond line".into()));
    }

    #[test]
    fn bad_records_name_the_file_and_the_fault() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(NARX_RECORD);
        record(Shard { k: 1, n: 2 }).write(dir.path()).unwrap();
        let good: Json = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        type Spoil = fn(&mut Json);
        let cases: [(Spoil, &str); 7] = [
            (|d| d["total"] = json!(5), "`total` is not 2 settings × 2 seeds"),
            (|d| d["range"] = json!([0, 3]), "shard 1/2 of 4 items should hold items 0..2, not [0, 3]"),
            (|d| d["items"][0]["index"] = json!(1), "the items are not items 0..2 in order"),
            (|d| d["items"][0]["setting"] = json!("c"), "item 1: no setting `c` in the scope"),
            (|d| d["items"][1]["score"] = d["items"][0]["score"].clone(), "item 2: give either `score` or `failed`"),
            (|d| d["items"][0]["score"]["es"] = json!("half"), "not a narx report shard's record: "),
            (|d| d["scope"]["settings"][0] = json!("a=5/1/10/sgd"), "the trainer is lm or adam"),
        ];
        for (spoil, what) in cases {
            let mut doc = good.clone();
            spoil(&mut doc);
            std::fs::write(&path, doc.to_string()).unwrap();
            let e = NarxRecord::read(dir.path()).unwrap_err().to_string();
            assert!(e.starts_with(&path.display().to_string()) && e.contains(what), "{e}\nexpected: {what}");
        }
    }
}
