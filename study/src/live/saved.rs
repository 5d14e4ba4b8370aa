//! A shard of a live study, saved and read back: `evflow report live
//! --shard K/N` writes the rows of its slice of the (profile, sample, user)
//! items into `live-shard.json`, with the scope every shard must share;
//! `evflow merge` reads the shards back and writes the tables one run
//! would have written. Floats are exact text (`study::exact`); a row's
//! folder is saved relative to the shard's output folder.

use super::row::LiveRow;
use super::run::{LiveConfig, LiveStudy};
use super::scope::LiveScope;
use crate::shard_file::{self, SavedFailure, StudyRecord};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The name of a live study shard's record in its output folder.
pub const RECORD: &str = "live-shard.json";

/// One shard's live study, as saved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LiveRecord {
    /// Which slice, `K/N`.
    pub shard: String,
    /// Items (profile, sample, user) in the whole study.
    pub items: usize,
    /// The slice's items among them, `[start, end)`.
    pub range: [usize; 2],
    /// What must agree across shards.
    pub scope: LiveScope,
    /// Every row the shard ran, in item order.
    pub rows: Vec<LiveRow>,
    /// Every step that failed, in order.
    pub failures: Vec<SavedFailure>,
    /// The shard's wall-clock time, s.
    #[serde(with = "crate::exact")]
    pub seconds: f64,
}

impl LiveRecord {
    /// What `study` (run with `cfg`, whose output folder is `base`) saves.
    pub fn of(study: &LiveStudy, cfg: &LiveConfig, base: &Path) -> Self {
        let all = cfg.all_items().len();
        let range = cfg.shard.range(all);
        Self {
            shard: cfg.shard.to_string(),
            items: all,
            range: [range.start, range.end],
            scope: cfg.scope.clone(),
            rows: study
                .rows
                .iter()
                .map(|r| LiveRow { dir: r.dir.strip_prefix(base).unwrap_or(&r.dir).to_path_buf(), ..r.clone() })
                .collect(),
            failures: study.failures.iter().map(|(s, r)| SavedFailure { step: s.clone(), reason: r.clone() }).collect(),
            seconds: study.seconds,
        }
    }

    /// The study of several shards' records (in K order), every row's
    /// folder put under `base`, the failures labelled with their shard, the
    /// times added up.
    pub fn join<'a>(shards: impl IntoIterator<Item = &'a LiveRecord>, base: &Path) -> LiveStudy {
        let mut study = LiveStudy { rows: Vec::new(), failures: Vec::new(), seconds: 0.0 };
        for s in shards {
            study.rows.extend(s.rows.iter().map(|r| LiveRow { dir: shard_file::under(base, &r.dir), ..r.clone() }));
            study.failures.extend(shard_file::failures_of(&s.shard, &s.failures));
            study.seconds += s.seconds;
        }
        study
    }
}

impl StudyRecord for LiveRecord {
    const RECORD: &'static str = RECORD;
    const COMMAND: &'static str = "evflow report live";
    const WHAT: &'static str = "a live study shard's record";
    const UNIT: &'static str = "items";

    fn shard(&self) -> &str {
        &self.shard
    }

    fn total(&self) -> usize {
        self.items
    }

    fn range(&self) -> [usize; 2] {
        self.range
    }
}

#[cfg(test)]
mod tests {
    use super::super::row::{Chain, ChainResult, StrokeFloor, TargetFloor};
    use super::*;
    use crate::gains::{AtGain, Chosen};
    use crate::row::Reading;
    use evflow_engine::batch::Shard;
    use std::path::PathBuf;

    fn row(k: usize) -> LiveRow {
        let at = AtGain { gain: 0.6, rect: 0.1 + k as f64, welch: f64::NAN, peak_ratio: f64::INFINITY };
        LiveRow {
            profile: "nominal".into(),
            sample: "felt-fabric".into(),
            user: format!("u{k}"),
            nothing: Reading { rect: 1.0 / 3.0, welch: -0.0 },
            display_floor: Reading { rect: 1e-300, welch: 0.5 },
            chains: vec![ChainResult {
                chain: Chain::Live,
                sweep: vec![at, at],
                chosen: Chosen { table51: at, best_rect: at, best_welch: at },
                iterations_per_tick: 4.0,
            }],
            achievable: Some(StrokeFloor {
                sweep: vec![at],
                reached: Reading { rect: 0.2, welch: 0.3 },
                start: "carrier ×1".into(),
                objective: 0.01,
                sliding_only: Reading { rect: 0.4, welch: 0.5 },
                seconds: 2.5,
            }),
            target_floor: (k != 1).then(|| TargetFloor {
                sweep: vec![at],
                reached: Reading { rect: 0.25, welch: f64::NAN },
                start: "live synthesis".into(),
                objective: 0.02,
                seconds: 1.25,
            }),
            dir: PathBuf::from(format!("/out/work/nominal/live/felt-fabric-u{k}")),
        }
    }

    #[test]
    fn shards_saved_read_and_joined_are_the_rows_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let mut scope = LiveScope::defaults();
        scope.users.truncate(3);
        scope.profiles.truncate(1);
        scope.samples.truncate(1);
        let rows: Vec<LiveRow> = (0..3).map(row).collect();
        let mut records = Vec::new();
        for k in 1..=2 {
            let cfg = LiveConfig {
                scope: scope.clone(),
                graphs: "/g".into(),
                work: "/out/work".into(),
                shard: Shard::parse(&format!("{k}/2")).unwrap(),
                jobs: 1,
            };
            let r = cfg.shard.range(3);
            let study = LiveStudy { rows: rows[r].to_vec(), failures: vec![("x".into(), "y".into())], seconds: 1.5 };
            let rec = LiveRecord::of(&study, &cfg, Path::new("/out"));
            let sub = dir.path().join(format!("s{k}"));
            std::fs::create_dir_all(&sub).unwrap();
            rec.write(&sub).unwrap();
            assert!(LiveRecord::is_in(&sub));
            records.push(LiveRecord::read(&sub).unwrap());
        }
        let joined = LiveRecord::join(&records, Path::new("/merged"));
        assert_eq!(joined.rows.len(), 3);
        for (a, b) in joined.rows.iter().zip(&rows) {
            assert_eq!(a.chains[0].sweep[0].rect.to_bits(), b.chains[0].sweep[0].rect.to_bits());
            assert!(a.chains[0].sweep[0].welch.is_nan() && a.chains[0].sweep[0].peak_ratio.is_infinite());
            assert_eq!(a.display_floor.rect.to_bits(), 1e-300f64.to_bits());
            assert_eq!(a.dir, Path::new("/merged/work/nominal/live").join(format!("felt-fabric-{}", b.user)));
        }
        assert_eq!(joined.failures.len(), 2);
        assert!(joined.failures[1].0.contains("shard 2/2"));
        // A record whose slice does not match its range is refused by name.
        let sub = dir.path().join("s1");
        let text =
            std::fs::read_to_string(sub.join(RECORD)).unwrap().replace("\"range\": [\n    0,", "\"range\": [\n    1,");
        std::fs::write(sub.join(RECORD), text).unwrap();
        let e = LiveRecord::read(&sub).unwrap_err().to_string();
        assert!(e.contains(RECORD) && e.contains("should hold"), "{e}");
        std::fs::write(sub.join(RECORD), "{").unwrap();
        assert!(LiveRecord::read(&sub).unwrap_err().to_string().contains("not a live study shard's record"));
    }
}
