//! The record of a shard of `evflow report narx --shard K/N`
//! (`narx-shard.json` in its `--out`): which slice it ran, the arguments
//! every shard must share, the textures scored and left out, and every one
//! of its items' scores in full (floats as Rust's shortest exact text, so
//! they read back bit for bit, NaN and infinities included), so that
//! `evflow merge` can write the table one run would have written. Written
//! and read here, in one place.

use super::record_json::{count, field, list, read_doc, text, write_doc, Fault, RecordError};
use evflow_engine::batch::Shard;
use evflow_study::narx_settings::{Item, NarxConfig, SeedScore, Setting};
use evflow_study::setup::Cond;
use serde_json::{json, Value as Json};
use std::path::Path;

/// The name of the record in a shard's output folder.
pub const NARX_RECORD: &str = "narx-shard.json";

/// The arguments every shard of one report must share.
#[derive(Debug, Clone, PartialEq)]
pub struct NarxArguments {
    /// The condition.
    pub condition: Cond,
    /// The settings, in order.
    pub settings: Vec<Setting>,
    /// The texture samples.
    pub samples: Vec<String>,
    /// The gain sweep.
    pub gains: Vec<f64>,
    /// Seeds per setting.
    pub seeds: u32,
    /// Epochs at most per model.
    pub epochs: u32,
    /// Iterations of the optimized synthesis.
    pub iterations: usize,
    /// Whether training times are measured and shown.
    pub times: bool,
}

impl NarxArguments {
    /// The arguments of a study's config.
    pub fn of(cfg: &NarxConfig) -> Self {
        Self {
            condition: cfg.condition,
            settings: cfg.settings.clone(),
            samples: cfg.samples.clone(),
            gains: cfg.gains.clone(),
            seeds: cfg.seeds,
            epochs: cfg.epochs,
            iterations: cfg.iterations,
            times: cfg.record_time,
        }
    }

    /// Items in the whole report.
    pub fn total(&self) -> usize {
        self.settings.len() * self.seeds as usize
    }
}

/// What a shard of `report narx` ran and found.
#[derive(Debug, Clone, PartialEq)]
pub struct NarxRecord {
    /// Which slice.
    pub shard: Shard,
    /// The arguments.
    pub arguments: NarxArguments,
    /// The textures scored.
    pub textures: Vec<String>,
    /// The textures left out, with why.
    pub left_out: Vec<(String, String)>,
    /// The slice's items, in order.
    pub items: Vec<Item>,
}

fn exact(x: f64) -> String {
    format!("{x:?}")
}

impl NarxRecord {
    /// Writes the record into `dir` (through a temporary file).
    pub fn write(&self, dir: &Path) -> Result<(), RecordError> {
        let a = &self.arguments;
        let arguments = json!({
            "condition": format!("{}:{}", exact(a.condition.mass), exact(a.condition.speed)),
            "settings": a.settings.iter().map(Setting::spec).collect::<Vec<_>>(),
            "samples": a.samples,
            "gains": a.gains.iter().map(|g| exact(*g)).collect::<Vec<_>>(),
            "seeds": a.seeds,
            "epochs": a.epochs,
            "iterations": a.iterations,
            "times": a.times,
        });
        let items: Vec<Json> = self
            .items
            .iter()
            .map(|i| {
                let head = json!({ "index": i.index, "setting": a.settings[i.setting].name, "seed": i.seed });
                let mut o = head.as_object().cloned().unwrap_or_default();
                match &i.score {
                    Ok(s) => {
                        for (k, v) in [
                            ("es", json!(exact(s.es))),
                            ("best", json!(exact(s.best))),
                            ("seconds", json!(exact(s.seconds))),
                            ("epochs", json!(s.epochs)),
                            ("transitions", json!(exact(s.transitions))),
                            ("weights", json!(s.weights)),
                        ] {
                            o.insert(k.into(), v);
                        }
                    }
                    Err(why) => {
                        o.insert("failed".into(), json!(why));
                    }
                }
                Json::Object(o)
            })
            .collect();
        let left_out: Vec<Json> = self.left_out.iter().map(|(s, why)| json!({ "texture": s, "reason": why })).collect();
        let doc = json!({
            "report": "narx",
            "shard": self.shard.to_string(),
            "arguments": arguments,
            "total": a.total(),
            "textures": self.textures,
            "left_out": left_out,
            "items": items,
        });
        write_doc(dir, NARX_RECORD, &doc)
    }

    /// Reads the record in `dir`; errors name the file and what is wrong.
    pub fn read(dir: &Path) -> Result<NarxRecord, RecordError> {
        read_doc(dir, NARX_RECORD, parse)
    }
}

fn float(v: &Json, key: &str) -> Fault<f64> {
    field(v, key)?.as_str().and_then(|s| s.parse().ok()).ok_or_else(|| format!("`{key}`: not a number written as text"))
}
fn texts(v: &Json, key: &str) -> Fault<Vec<String>> {
    field(v, key)?
        .as_array()
        .and_then(|l| l.iter().map(|x| x.as_str().map(str::to_string)).collect::<Option<Vec<_>>>())
        .ok_or_else(|| format!("`{key}` is not a list of text"))
}

fn parse_arguments(a: &Json) -> Fault<NarxArguments> {
    let at = |e: String| format!("arguments: {e}");
    let condition = Cond::parse(text(a, "condition").map_err(at)?).map_err(|e| at(e.to_string()))?;
    let settings = texts(a, "settings")
        .map_err(at)?
        .iter()
        .map(|s| Setting::parse(s).map_err(|e| at(e.to_string())))
        .collect::<Fault<Vec<_>>>()?;
    let gains = texts(a, "gains")
        .map_err(at)?
        .iter()
        .map(|g| g.parse::<f64>().map_err(|_| at(format!("gain `{g}` is not a number"))))
        .collect::<Fault<Vec<_>>>()?;
    let small = |key: &str| {
        count(a, key).map_err(at).and_then(|n| u32::try_from(n).map_err(|_| at(format!("`{key}` is too large"))))
    };
    Ok(NarxArguments {
        condition,
        settings,
        samples: texts(a, "samples").map_err(at)?,
        gains,
        seeds: small("seeds")?,
        epochs: small("epochs")?,
        iterations: count(a, "iterations").map_err(at)? as usize,
        times: field(a, "times").map_err(at)?.as_bool().ok_or_else(|| at("`times` is not true or false".into()))?,
    })
}

fn parse_item(v: &Json, settings: &[Setting]) -> Fault<Item> {
    let name = text(v, "setting")?;
    let setting =
        settings.iter().position(|s| s.name == name).ok_or_else(|| format!("no setting `{name}` in the arguments"))?;
    let seed = u32::try_from(count(v, "seed")?).map_err(|_| "`seed` is too large".to_string())?;
    let score = match v.get("failed") {
        Some(why) => Err(why.as_str().ok_or("`failed` is not text")?.to_string()),
        None => Ok(SeedScore {
            es: float(v, "es")?,
            best: float(v, "best")?,
            seconds: float(v, "seconds")?,
            epochs: count(v, "epochs")? as usize,
            transitions: float(v, "transitions")?,
            weights: count(v, "weights")? as usize,
        }),
    };
    Ok(Item { index: count(v, "index")? as usize, setting, seed, score })
}

fn parse(doc: &Json) -> Fault<NarxRecord> {
    if doc.get("report").and_then(Json::as_str) != Some("narx") {
        return Err("not the record of a shard of `evflow report narx` (`report` is not \"narx\")".into());
    }
    let shard = Shard::parse(text(doc, "shard")?).map_err(|e| e.to_string())?;
    let arguments = parse_arguments(field(doc, "arguments")?)?;
    if count(doc, "total")? as usize != arguments.total() {
        return Err(format!("`total` is not {} settings × {} seeds", arguments.settings.len(), arguments.seeds));
    }
    let items = list(doc, "items")?
        .iter()
        .enumerate()
        .map(|(n, v)| parse_item(v, &arguments.settings).map_err(|e| format!("item {}: {e}", n + 1)))
        .collect::<Fault<Vec<_>>>()?;
    let left_out = list(doc, "left_out")?
        .iter()
        .map(|v| Ok((text(v, "texture")?.to_string(), text(v, "reason")?.to_string())))
        .collect::<Fault<Vec<_>>>()?;
    Ok(NarxRecord { shard, textures: texts(doc, "textures")?, left_out, items, arguments })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A record of shard `shard` holding items `range` of 2 settings × 2
    /// seeds, with awkward floats and a failure.
    pub(crate) fn record(shard: Shard) -> NarxRecord {
        let settings: Vec<Setting> =
            ["a=5/1/10/lm", "b=3/1/5/adam"].iter().map(|s| Setting::parse(s).unwrap()).collect();
        let arguments = NarxArguments {
            condition: Cond { mass: 60.0, speed: 0.1 + 0.2 },
            settings,
            samples: vec!["plastic-sheet".into(), "felt-fabric".into()],
            gains: vec![1.0 / 3.0, 1.4],
            seeds: 2,
            epochs: 3,
            iterations: 3,
            times: false,
        };
        let all: Vec<Item> = (0..4)
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
        NarxRecord {
            shard,
            items: all[shard.range(4)].to_vec(),
            arguments,
            textures: vec!["plastic-sheet".into()],
            left_out: vec![("felt-fabric".into(), "it broke".into())],
        }
    }

    #[test]
    fn a_record_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let rec = record(Shard { k: 1, n: 1 });
        rec.write(dir.path()).unwrap();
        assert!(!dir.path().join(format!(".{NARX_RECORD}.tmp")).exists());
        let back = NarxRecord::read(dir.path()).unwrap();
        // NaN is not equal to itself: compare the bits.
        let bits = |r: &NarxRecord| -> Vec<[u64; 4]> {
            r.items
                .iter()
                .filter_map(|i| i.score.as_ref().ok())
                .map(|s| [s.es.to_bits(), s.best.to_bits(), s.seconds.to_bits(), s.transitions.to_bits()])
                .collect()
        };
        assert_eq!(bits(&back), bits(&rec));
        assert_eq!(back.arguments, rec.arguments);
        assert_eq!((back.shard, &back.textures, &back.left_out), (rec.shard, &rec.textures, &rec.left_out));
        assert_eq!(back.items[1], rec.items[1]);
        assert_eq!(back.items.len(), 4);
    }

    #[test]
    fn bad_records_name_the_file_and_the_fault() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(NARX_RECORD);
        record(Shard { k: 1, n: 2 }).write(dir.path()).unwrap();
        let good: Json = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        type Spoil = fn(&mut Json);
        let cases: [(Spoil, &str); 5] = [
            (
                |d| d["report"] = json!("sweep"),
                "not the record of a shard of `evflow report narx` (`report` is not \"narx\")",
            ),
            (|d| d["total"] = json!(5), "`total` is not 2 settings × 2 seeds"),
            (|d| d["items"][0]["setting"] = json!("c"), "item 1: no setting `c` in the arguments"),
            (|d| d["items"][0]["es"] = json!(0.5), "item 1: `es`: not a number written as text"),
            (
                |d| d["arguments"]["settings"][0] = json!("a=5/1/10/sgd"),
                "arguments: setting `a=5/1/10/sgd`: the trainer is lm or adam",
            ),
        ];
        for (spoil, what) in cases {
            let mut doc = good.clone();
            spoil(&mut doc);
            std::fs::write(&path, doc.to_string()).unwrap();
            let e = NarxRecord::read(dir.path()).unwrap_err();
            assert!(matches!(e, RecordError::Invalid { .. }), "{e}");
            assert_eq!(e.to_string(), format!("{}: {what}", path.display()));
        }
    }
}
