//! The model library (issue 17, point 3): for every texture sample × every
//! condition of a grid, the inverse NARX model of the condition and the
//! actuation cells U_ij of each method (inverse NARX, optimized synthesis,
//! fair playback) at their Table 5.1 gains and the recorded force itself
//! (`forces-SAMPLE`, newtons: what forces first and `synth.live` render from), in the folder layout the
//! texture-live grids read (`METHOD-SAMPLE/u-SAMPLE-TAG.{wav,json}`), with
//! `index.json` saying, per texture and condition, which model and cells,
//! the model's training scores and each method's E_s.
//!
//! Resumable: an item (a condition's models, a texture at a condition) is
//! built in `DIR/.partial/…` and moved into place when complete, then
//! entered into the index (rewritten through a temporary file after every
//! item). A rerun skips the items the index lists whose files are there,
//! and redoes the rest — a half-written item included, its partial folder
//! removed first.
//!
//! Sharded (`--shard K/N`), a build takes the K-th contiguous slice of the
//! grid's conditions: their models and every texture at them. Its index
//! says which shard it is; `evflow merge` joins the shards' folders into
//! the library one build would have made.

use super::cells::{write_actuation, write_force};
use super::models::{self, Models};
use super::recordings;
use super::row::{self, Method, Row, RowInputs};
use super::setup::{Cond, Profile};
use super::StudyError;
use evflow_engine::batch::{for_each_ordered, Failures, Shard};
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

type Result<T> = std::result::Result<T, StudyError>;

use crate::error::io;

/// What a library covers.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The library folder.
    pub dir: PathBuf,
    /// The folder of the shipped graphs (absolute).
    pub graphs: PathBuf,
    /// The lab profile the models and cells are made on.
    pub profile: Profile,
    /// Texture samples.
    pub samples: Vec<String>,
    /// The grid's conditions, in index order.
    pub conds: Vec<Cond>,
    /// The gain sweep of each cell (§5.3.2).
    pub gains: Vec<f64>,
    /// NARX training epochs at most.
    pub epochs: u32,
    /// The optimized synthesis' iterations at most.
    pub iterations: usize,
    /// Runs at once.
    pub jobs: usize,
    /// The slice of the conditions this build makes.
    pub shard: Shard,
    /// Write each model's training time into its file (without, two builds
    /// write the same bytes: the live study's shards share their libraries).
    pub record_time: bool,
}

/// The methods whose cells the library keeps: (method, recording channel, folder prefix).
const CELLS: [(Method, &str, &str); 3] = [
    (Method::NarxBinary, "u", "narx"),
    (Method::Optimized, "optimized_u", "optimized"),
    (Method::Playback, "playback_u", "playback"),
];

/// What a build did.
#[derive(Debug, Default)]
pub struct Outcome {
    /// Items found complete and skipped.
    pub skipped: usize,
    /// Items built.
    pub built: usize,
    /// Items that failed, with why.
    pub failures: Failures,
    /// Items in all.
    pub total: usize,
}

/// The library's `index.json`. Its fields are declared in the order of
/// their names, which is the order they are written in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Index {
    /// The plan's condition tags, in the library's order.
    pub conditions: Vec<String>,
    /// What the library holds, texture by texture, condition by condition.
    pub entries: Vec<Entry>,
    /// [`FORMAT`].
    pub format: String,
    /// The plan's texture samples, in order.
    pub samples: Vec<String>,
    /// The slice `K/N` of a sharded build; absent for the whole library.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<String>,
    /// The index format's version (1).
    pub version: u32,
}

/// One texture at one condition in the library.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct Entry {
    /// E_s of each method's cell at its chosen gain, by method folder prefix.
    pub E_s: BTreeMap<String, Es>,
    /// E_s of the display floor (what the display allows).
    pub E_s_display_floor: Es,
    /// E_s between two recordings of the same force (the repeat floor).
    pub E_s_repeat: Es,
    /// Each cell's recording sidecar (relative to the library), by method
    /// folder prefix, and `forces`: the recorded force.
    pub cells: BTreeMap<String, String>,
    /// The condition.
    pub condition: Condition,
    /// The forward model's file, relative to the library.
    pub forward_model: String,
    /// Each method's chosen gain (Table 5.1), by method folder prefix.
    pub gain: BTreeMap<String, f64>,
    /// The inverse NARX model's file, relative to the library.
    pub model: String,
    /// The lab profile the cells were made on.
    pub profile: String,
    /// The condition's tag (`85g-5cms`).
    pub tag: String,
    /// The texture sample.
    pub texture: String,
    /// The NARX model file's own `training` section (its scores), as written there.
    pub training: Json,
}

/// A condition of the grid as the index writes it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Condition {
    /// Normal load in grams.
    pub load_g: f64,
    /// Finger velocity in cm/s.
    pub velocity_cm_s: f64,
}

/// E_s with the rectangular and the Welch estimate; a value that could not
/// be computed (NaN) is written as `null` and read back as NaN.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Es {
    /// With the rectangular-window spectrum.
    #[serde(deserialize_with = "nan_if_null")]
    pub rect: f64,
    /// With the Welch spectrum.
    #[serde(deserialize_with = "nan_if_null")]
    pub welch: f64,
}

/// A number, or `null` (which JSON writes for NaN and the infinities) as NaN.
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

fn index_path(dir: &Path) -> PathBuf {
    dir.join("index.json")
}

/// Reads `dir`'s index; `None` when there is none. Errors name the file.
fn read_index_file(dir: &Path) -> Result<Option<Index>> {
    let p = index_path(dir);
    let text = match evflow_engine::files::read_regular_to_string(&p) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(io(&p, format!("cannot read: {e}"))),
    };
    serde_json::from_str(&text).map(Some).map_err(|e| io(&p, format!("not a library index: {e}")))
}

/// The index's entries from an earlier build (none when there is no index).
fn read_index(dir: &Path) -> Result<Vec<Entry>> {
    Ok(read_index_file(dir)?.map(|i| i.entries).unwrap_or_default())
}

/// Writes `text` to `path` through a temporary file beside it.
fn write_atomic(path: &Path, text: &str) -> Result<()> {
    evflow_engine::atomic_file::write_atomically(path, text).map_err(|e| io(path, format!("cannot write: {e}")))
}

/// The index's format name.
pub const FORMAT: &str = "evflow-model-library";

/// Writes the index: the plan's samples and condition tags (the library's
/// order), the shard when not the whole, and the entries.
fn write_index(plan: &Plan, entries: Vec<Entry>) -> Result<()> {
    let index = Index {
        conditions: plan.conds.iter().map(Cond::tag).collect(),
        entries,
        format: FORMAT.into(),
        samples: plan.samples.clone(),
        shard: (plan.shard != Shard::ALL).then(|| plan.shard.to_string()),
        version: 1,
    };
    save_index(&plan.dir, &index)
}

/// Writes `index` as `dir/index.json`, through a temporary file.
fn save_index(dir: &Path, index: &Index) -> Result<()> {
    write_atomic(&index_path(dir), &serde_json::to_string_pretty(index).map_err(|e| io(dir, e))?)
}

/// The key of an entry: texture and condition tag.
fn key(e: &Entry) -> (&str, &str) {
    (&e.texture, &e.tag)
}

/// Whether every file an entry names is in the library: its models, and
/// each cell's recording (the sidecar the index names and its samples).
fn complete(dir: &Path, e: &Entry) -> bool {
    let models = [&e.model, &e.forward_model].iter().all(|f| dir.join(f).is_file());
    let cells = e.cells.values().all(|f| {
        let p = dir.join(f);
        p.is_file() && p.with_extension("wav").is_file()
    });
    models && cells
}

/// A condition's models in the library (`models/narx-TAG.json`,
/// `models/forward-TAG.json`): kept when both are there, else built in a
/// partial folder and moved in. The flag says whether they were built now.
fn condition_models(plan: &Plan, c: &Cond) -> Result<(Models, bool)> {
    let final_dir = plan.dir.join("models");
    if let Ok(m) = models::given(&final_dir, c) {
        return Ok((m, false));
    }
    let partial = plan.dir.join(".partial").join(format!("models-{}", c.tag()));
    let _ = std::fs::remove_dir_all(&partial);
    let built = models::build(&plan.graphs, &plan.profile, c, plan.epochs, false, plan.record_time, &partial)?;
    std::fs::create_dir_all(&final_dir).map_err(|e| io(&final_dir, format!("cannot create: {e}")))?;
    // The forward model first: `given` needs both, so a crash between the
    // two moves leaves an item that is redone.
    for from in [&built.forward, &built.narx] {
        let to = final_dir.join(from.file_name().unwrap_or_default());
        std::fs::rename(from, &to).map_err(|e| io(&to, format!("cannot move into the library: {e}")))?;
    }
    let _ = std::fs::remove_dir_all(&partial);
    Ok((models::given(&final_dir, c)?, true))
}

/// Reads a model file's `training` section (its scores).
fn training(path: &Path) -> Json {
    evflow_engine::files::read_regular_to_string(path)
        .ok()
        .and_then(|t| serde_json::from_str::<Json>(&t).ok())
        .and_then(|d| d.get("training").cloned())
        .unwrap_or(Json::Null)
}

fn rel(dir: &Path, p: &Path) -> String {
    p.strip_prefix(dir).unwrap_or(p).to_string_lossy().replace('\\', "/")
}

/// One texture at one condition: recordings, the row (every method over
/// the gain sweep), the cells moved into the library; returns its entry.
fn texture_cell(plan: &Plan, m: &Models, sample: &str, c: &Cond) -> Result<Entry> {
    let partial = plan.dir.join(".partial").join(format!("{sample}-{}", c.tag()));
    let _ = std::fs::remove_dir_all(&partial);
    let rec_dir = partial.join("recordings");
    recordings::record_pair(&plan.graphs, &plan.profile, sample, c, &rec_dir)?;
    let inputs = RowInputs {
        graphs: &plan.graphs,
        profile: &plan.profile,
        sample,
        cond: *c,
        models: m,
        recordings: &rec_dir,
        gains: &plan.gains,
        iterations: plan.iterations,
        objective: "expected",
        optimized: None,
        dir: partial.join("row"),
    };
    let r: Row = row::run(&inputs)?;
    let mut cells = BTreeMap::new();
    let mut es = BTreeMap::new();
    let mut gains = BTreeMap::new();
    for (method, channel, folder) in CELLS {
        let Some(res) = r.method(method) else { continue };
        let gain = res.chosen.table51.gain;
        let staged = partial.join("cells").join(format!("{folder}-{sample}"));
        let written = write_actuation(&r.recording(gain), channel, &staged, sample, c, gain, method.carrier())?;
        let to_dir = plan.dir.join(format!("{folder}-{sample}"));
        std::fs::create_dir_all(&to_dir).map_err(|e| io(&to_dir, format!("cannot create: {e}")))?;
        let name = written.file_name().unwrap_or_default().to_string_lossy().into_owned();
        // A recording is NAME.wav + NAME.json: the sidecar last, so that a
        // reader never finds a sidecar without its samples.
        for ext in ["wav", "json"] {
            let from = staged.join(format!("{name}.{ext}"));
            let to = to_dir.join(format!("{name}.{ext}"));
            std::fs::rename(&from, &to).map_err(|e| io(&to, format!("cannot move into the library: {e}")))?;
        }
        cells.insert(folder.into(), rel(&plan.dir, &to_dir.join(format!("{name}.json"))));
        es.insert(folder.into(), Es { rect: res.chosen.table51.rect, welch: res.chosen.table51.welch });
        gains.insert(folder.into(), gain);
    }
    // The recorded force itself (newtons, gain 1): the grid that forces
    // first and the live synthesis (`synth.live`) render from.
    let rep1 = rec_dir.join(recordings::name(sample, c, 1));
    let staged = write_force(&rep1, &partial.join("cells").join(format!("forces-{sample}")), sample, c)?;
    let to_dir = plan.dir.join(format!("forces-{sample}"));
    std::fs::create_dir_all(&to_dir).map_err(|e| io(&to_dir, format!("cannot create: {e}")))?;
    let name = staged.file_name().unwrap_or_default().to_string_lossy().into_owned();
    for ext in ["wav", "json"] {
        let from = staged.with_file_name(format!("{name}.{ext}"));
        let to = to_dir.join(format!("{name}.{ext}"));
        std::fs::rename(&from, &to).map_err(|e| io(&to, format!("cannot move into the library: {e}")))?;
    }
    cells.insert("forces".into(), rel(&plan.dir, &to_dir.join(format!("{name}.json"))));
    let _ = std::fs::remove_dir_all(&partial);
    Ok(Entry {
        E_s: es,
        E_s_display_floor: Es { rect: r.display_floor.rect, welch: r.display_floor.welch },
        E_s_repeat: Es { rect: r.repeat.rect, welch: r.repeat.welch },
        cells,
        condition: Condition { load_g: c.mass, velocity_cm_s: c.speed },
        forward_model: rel(&plan.dir, &m.forward),
        gain: gains,
        model: rel(&plan.dir, &m.narx),
        profile: plan.profile.name.clone(),
        tag: c.tag(),
        texture: sample.to_string(),
        training: training(&m.narx),
    })
}

/// Builds (or completes) the library; `progress` is called once per item
/// received, with a label.
pub fn build(plan: &Plan, progress: &(dyn Fn(&str) + Sync)) -> Result<Outcome> {
    std::fs::create_dir_all(&plan.dir).map_err(|e| io(&plan.dir, format!("cannot create: {e}")))?;
    let mut entries = read_index(&plan.dir)?;
    // Entries whose files are gone are redone.
    entries.retain(|e| complete(&plan.dir, e));
    let conds: Vec<Cond> = plan.conds[plan.shard.range(plan.conds.len())].to_vec();
    let mut out = Outcome { total: conds.len() * (1 + plan.samples.len()), ..Outcome::default() };
    let never = AtomicBool::new(false);

    // The models of every condition (of this shard).
    let mut built: Vec<Option<Models>> = Vec::new();
    for_each_ordered(
        conds.clone(),
        plan.jobs,
        &never,
        |_, c| condition_models(plan, &c),
        |k, r| {
            progress(&format!("models at {}", conds[k].label()));
            match r.map_err(|p| StudyError::Config(format!("panicked: {p}"))).and_then(|r| r) {
                Ok((m, fresh)) => {
                    if fresh {
                        out.built += 1;
                    } else {
                        out.skipped += 1;
                    }
                    built.push(Some(m));
                }
                Err(e) => {
                    out.failures.push(format!("models at {}", conds[k].label()), e.to_string());
                    built.push(None);
                }
            }
        },
    );

    // Every texture at every condition whose models are there.
    let mut todo = Vec::new();
    for (k, c) in conds.iter().enumerate() {
        for s in &plan.samples {
            let done = entries.iter().any(|e| key(e) == (s.as_str(), c.tag().as_str()));
            if done {
                out.skipped += 1;
            } else if built[k].is_some() {
                todo.push((k, s.clone()));
            } else {
                out.failures.push(format!("{s} at {}", c.label()), "its condition's models failed");
            }
        }
    }
    let work = |_: usize, (k, s): (usize, String)| {
        let m = built[k].as_ref().expect("only conditions with models");
        texture_cell(plan, m, &s, &conds[k])
    };
    let mut write_error = None;
    for_each_ordered(todo.clone(), plan.jobs, &never, work, |j, r| {
        let (k, s) = &todo[j];
        let label = format!("{s} at {}", conds[*k].label());
        progress(&label);
        match r.map_err(|p| StudyError::Config(format!("panicked: {p}"))).and_then(|r| r) {
            Ok(entry) => {
                entries.retain(|e| key(e) != key(&entry));
                entries.push(entry);
                out.built += 1;
                // The index after every item: an interruption loses at most the items in flight.
                if let Err(e) = write_index(plan, sorted(plan, &entries)) {
                    write_error.get_or_insert(e);
                }
            }
            Err(e) => out.failures.push(label, e.to_string()),
        }
    });
    if let Some(e) = write_error {
        return Err(e);
    }
    write_index(plan, sorted(plan, &entries))?;
    let _ = std::fs::remove_dir(plan.dir.join(".partial"));
    Ok(out)
}

/// The entries in library order: texture by texture (as the plan lists
/// them, others after), condition by condition.
fn sorted(plan: &Plan, entries: &[Entry]) -> Vec<Entry> {
    let mut v = entries.to_vec();
    let rank = |e: &Entry| {
        let (s, t) = key(e);
        let si = plan.samples.iter().position(|x| x == s).unwrap_or(usize::MAX);
        let ci = plan.conds.iter().position(|c| c.tag() == t).unwrap_or(usize::MAX);
        (si, ci, s.to_string(), t.to_string())
    };
    v.sort_by_key(rank);
    v
}

/// One shard's library as `evflow merge` reads it.
pub struct ShardIndex {
    /// Its folder.
    pub dir: PathBuf,
    /// Which slice.
    pub shard: Shard,
    /// The plan's samples, in order.
    pub samples: Vec<String>,
    /// The plan's condition tags, in order.
    pub conditions: Vec<String>,
    /// Its entries.
    pub entries: Vec<Entry>,
}

/// Whether `dir` holds a library (its index.json).
pub fn is_library(dir: &Path) -> bool {
    matches!(read_index_file(dir), Ok(Some(i)) if i.format == FORMAT)
}

/// Reads a sharded library's index; errors name the file.
pub fn read_shard(dir: &Path) -> Result<ShardIndex> {
    let p = index_path(dir);
    let index = read_index_file(dir)?.ok_or_else(|| io(&p, "cannot read: no such file"))?;
    let shard = index.shard.as_deref().ok_or_else(|| io(&p, "not a shard (built without --shard)"))?;
    Ok(ShardIndex {
        dir: dir.to_path_buf(),
        shard: Shard::parse(shard).map_err(|e| io(&p, e))?,
        samples: index.samples,
        conditions: index.conditions,
        entries: index.entries,
    })
}

/// The merged index of every shard (checked to be the N slices of one
/// plan, sorted as one build sorts them) written into `out`.
pub fn merge_index(out: &Path, shards: &[ShardIndex]) -> Result<usize> {
    let first = &shards[0];
    for s in shards {
        if s.samples != first.samples || s.conditions != first.conditions || s.shard.n != first.shard.n {
            return Err(StudyError::Config(format!(
                "{} and {}: not shards of one library (samples, conditions or N differ)",
                first.dir.display(),
                s.dir.display()
            )));
        }
    }
    let mut entries: Vec<Entry> = shards.iter().flat_map(|s| s.entries.iter().cloned()).collect();
    let rank = |e: &Entry| {
        let (s, t) = key(e);
        (first.samples.iter().position(|x| x == s), first.conditions.iter().position(|x| x == t))
    };
    entries.sort_by_key(rank);
    let n = entries.len();
    let index = Index {
        conditions: first.conditions.clone(),
        entries,
        format: FORMAT.into(),
        samples: first.samples.clone(),
        shard: None,
        version: 1,
    };
    std::fs::create_dir_all(out).map_err(|e| io(out, format!("cannot create: {e}")))?;
    save_index(out, &index)?;
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn entry(texture: &str, tag: &str, floor: f64) -> Entry {
        Entry {
            E_s: BTreeMap::from([("narx".into(), Es { rect: 0.5, welch: 0.25 })]),
            E_s_display_floor: Es { rect: floor, welch: 0.125 },
            E_s_repeat: Es { rect: 0.1, welch: 0.2 },
            cells: BTreeMap::from([("forces".into(), "f.json".into()), ("narx".into(), "n.json".into())]),
            condition: Condition { load_g: 85.0, velocity_cm_s: 5.0 },
            forward_model: "models/forward-85g-5cms.json".into(),
            gain: BTreeMap::from([("narx".into(), 1.2)]),
            model: "models/narx-85g-5cms.json".into(),
            profile: "nominal".into(),
            tag: tag.into(),
            texture: texture.into(),
            training: json!({ "validation_mse": 0.003 }),
        }
    }

    #[test]
    fn the_index_is_written_as_the_hand_written_one_was_and_reads_back() {
        let index = Index {
            conditions: vec!["85g-5cms".into()],
            entries: vec![entry("felt", "85g-5cms", 0.75)],
            format: FORMAT.into(),
            samples: vec!["felt".into()],
            shard: Some("1/2".into()),
            version: 1,
        };
        // The document the library wrote before its index had types (keys
        // in the order of their names).
        let old = json!({ "format": FORMAT, "version": 1, "samples": ["felt"], "conditions": ["85g-5cms"], "shard": "1/2",
            "entries": [{
                "texture": "felt", "tag": "85g-5cms", "condition": { "load_g": 85.0, "velocity_cm_s": 5.0 },
                "profile": "nominal", "model": "models/narx-85g-5cms.json", "forward_model": "models/forward-85g-5cms.json",
                "training": { "validation_mse": 0.003 }, "cells": { "narx": "n.json", "forces": "f.json" },
                "gain": { "narx": 1.2 }, "E_s": { "narx": { "rect": 0.5, "welch": 0.25 } },
                "E_s_repeat": { "rect": 0.1, "welch": 0.2 }, "E_s_display_floor": { "rect": 0.75, "welch": 0.125 },
            }] });
        let text = serde_json::to_string_pretty(&index).unwrap();
        assert_eq!(text, serde_json::to_string_pretty(&old).unwrap());
        assert_eq!(serde_json::from_str::<Index>(&text).unwrap(), index);
        // A floor that could not be computed is written as null and read as NaN.
        let mut nan = index.clone();
        nan.entries[0].E_s_display_floor.rect = f64::NAN;
        let back: Index = serde_json::from_str(&serde_json::to_string(&nan).unwrap()).unwrap();
        assert!(back.entries[0].E_s_display_floor.rect.is_nan());
    }

    #[test]
    fn a_bad_index_is_named_and_a_missing_one_is_empty() {
        let dir = tempfile::tempdir().unwrap();
        assert!(read_index(dir.path()).unwrap().is_empty());
        assert!(!is_library(dir.path()));
        std::fs::write(dir.path().join("index.json"), r#"{"format": "evflow-model-library", "entries": 3}"#).unwrap();
        let e = read_index(dir.path()).unwrap_err().to_string();
        assert!(e.contains("index.json") && e.contains("not a library index"), "{e}");
        assert!(read_shard(dir.path()).is_err());
    }

    #[test]
    fn merging_shards_sorts_their_entries_as_one_build_does() {
        let dir = tempfile::tempdir().unwrap();
        let shard = |k: usize, entries: Vec<Entry>| ShardIndex {
            dir: dir.path().join(format!("s{k}")),
            shard: Shard { k, n: 2 },
            samples: vec!["a".into(), "b".into()],
            conditions: vec!["c1".into(), "c2".into()],
            entries,
        };
        let shards =
            [shard(2, vec![entry("b", "c2", 0.1), entry("a", "c2", 0.1)]), shard(1, vec![entry("b", "c1", 0.1)])];
        assert_eq!(merge_index(dir.path(), &shards).unwrap(), 3);
        let merged = read_index_file(dir.path()).unwrap().unwrap();
        let keys: Vec<(&str, &str)> = merged.entries.iter().map(key).collect();
        assert_eq!(keys, [("a", "c2"), ("b", "c1"), ("b", "c2")]);
        assert!(merged.shard.is_none() && is_library(dir.path()));
    }
}
