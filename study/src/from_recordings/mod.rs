//! A model library from a lab's own recordings (issue 33, point 4): a
//! folder of excitation recordings of the display and a folder of texture
//! recordings, written as the sensor measured them (docs/rig.md) → the
//! library the live chains play (graphs/texture-live.toml,
//! graphs/texture-live-recorded.toml `--set library=LIB`):
//!
//! - `forces-SAMPLE/u-SAMPLE-TAG.{wav,json}`: per texture and condition,
//!   the force resampled to 1 kHz, high-passed at 10 Hz, over its longest
//!   forward constant-speed stretch ([`forces`]; unit `N`, gain 1, the
//!   condition in the sidecar — the layout `evflow library build` writes);
//! - `models/forward-TAG.json`: per excitation, the forward model
//!   (graphs/forward-build-recordings.toml, run on the 1 kHz recording
//!   [`excitation`] makes, whose `u` keeps its band up to 500 Hz);
//! - `models/narx-TAG.json`: per excitation, the inverse NARX model
//!   (graphs/model-build-recordings.toml), for the cells chains
//!   (graphs/synthesize-recordings.toml `--set models=LIB/models`);
//! - `index.json`: the [`crate::library::Index`] of `evflow library build`,
//!   one entry per texture and condition (no display was played, so its
//!   E_s fields are `null` and its gains empty).
//!
//! Everything is checked before anything is built ([`survey`]); the
//! library is built in `LIB/.partial` and moved into place when every item
//! is done, the index last, so a failed or interrupted build leaves no
//! half library (a rerun starts over). An existing library is never
//! overwritten.

pub mod excitation;
pub mod forces;
pub mod survey;

use crate::graphs::{run_graph, Sets};
use crate::library::{Condition, Entry, Es, Index, FORMAT};
use crate::setup::Cond;
use crate::StudyError;
use evflow_engine::batch::{for_each_ordered, Failures};
use evflow_nodes::synth::model_file::ForwardModel;
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use survey::Survey;

type Result<T> = std::result::Result<T, StudyError>;

use crate::error::io;

/// What to build from what.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The folder of excitation recordings (`u`, `force`, `velocity`).
    pub excitation: PathBuf,
    /// The folder of texture recordings (`force`, `velocity`, a material).
    pub textures: PathBuf,
    /// The library folder to create (absent or empty).
    pub out: PathBuf,
    /// The folder of the shipped graphs.
    pub graphs: PathBuf,
    /// Levenberg–Marquardt epochs at most per inverse model.
    pub epochs: u32,
    /// Runs at once.
    pub jobs: usize,
}

/// One step of the build.
#[derive(Debug, Clone, Copy)]
enum Item {
    /// The forward model of excitation k.
    Forward(usize),
    /// The inverse model of excitation k.
    Inverse(usize),
    /// The forces cell of texture k.
    Forces(usize),
}

/// What a build made.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The library (as given).
    pub dir: PathBuf,
    /// The models' conditions, in order.
    pub conditions: Vec<Cond>,
    /// The textures, in order.
    pub samples: Vec<String>,
    /// Forces cells written.
    pub cells: usize,
    /// The forward model files (in the library), in condition order.
    pub forward_models: Vec<PathBuf>,
    /// What a person should know: a binary excitation, a carrier gain ≤ 0,
    /// recordings not used.
    pub notes: Vec<String>,
}

/// The items' labels, for progress.
fn label(s: &Survey, item: Item) -> String {
    match item {
        Item::Forward(k) => format!("forward model at {}", s.excitation[k].cond.label()),
        Item::Inverse(k) => format!("inverse model at {}", s.excitation[k].cond.label()),
        Item::Forces(k) => format!("{} at {}", s.textures[k].material, s.textures[k].cond.label()),
    }
}

/// How many items [`build`] reports progress for, given its survey.
pub fn items(s: &Survey) -> usize {
    2 * s.excitation.len() + s.textures.len()
}

/// Checks that `out` can take a new library: absent, or empty but for a
/// `.partial` a failed build left.
fn fresh(out: &Path) -> Result<()> {
    match std::fs::read_dir(out) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(io(out, format!("cannot read the output folder: {e}"))),
        Ok(rd) => {
            let mut others = rd.filter_map(|e| e.ok()).filter(|e| e.file_name() != ".partial");
            match others.next() {
                None => Ok(()),
                Some(e) => Err(io(
                    out,
                    format!(
                        "not empty (it holds {}): from-recordings writes a new library and never overwrites one; \
                         give a new folder",
                        e.file_name().to_string_lossy()
                    ),
                )),
            }
        }
    }
}

/// Runs one item into its own folder under `partial`; returns the file it made.
fn run_item(inputs: &Inputs, s: &Survey, at_1khz: &[PathBuf], item: Item, partial: &Path) -> Result<PathBuf> {
    match item {
        Item::Forward(k) | Item::Inverse(k) => {
            let e = &s.excitation[k];
            // The 1 kHz recording, u exact (excitation.rs says why).
            let sets = Sets::new()
                .path("recording", &at_1khz[k])
                .num("rate", survey::CHAIN_RATE)
                .num("load_g", e.cond.mass)
                .num("velocity_cm_s", e.cond.speed)
                .and(excitation::passthrough());
            let (graph, sets, name) = match item {
                Item::Forward(_) => ("forward-build-recordings.toml", sets, format!("forward-{}.json", e.cond.tag())),
                _ => (
                    "model-build-recordings.toml",
                    sets.int("epochs", inputs.epochs),
                    format!("narx-{}.json", e.cond.tag()),
                ),
            };
            let dir = partial.join("work").join(name.trim_end_matches(".json"));
            run_graph(&inputs.graphs.join(graph), &sets, &dir)?;
            let made = dir.join(&name);
            let to = partial.join("models").join(&name);
            std::fs::create_dir_all(partial.join("models")).map_err(|e| io(&to, e))?;
            std::fs::rename(&made, &to).map_err(|err| io(&made, format!("the graph wrote no model here: {err}")))?;
            Ok(to)
        }
        Item::Forces(k) => {
            let t = &s.textures[k];
            let work = partial.join("work").join(format!("hp-{}-{}", t.material, t.cond.tag()));
            let grid = partial.join(format!("forces-{}", t.material));
            let (cell, _) = forces::cell(&inputs.graphs, t, &work, &grid)?;
            Ok(cell)
        }
    }
}

/// A model file's `training` section (its scores), as written there.
fn training(path: &Path) -> Json {
    evflow_engine::files::read_regular_to_string(path)
        .ok()
        .and_then(|t| serde_json::from_str::<Json>(&t).ok())
        .and_then(|d| d.get("training").cloned())
        .unwrap_or(Json::Null)
}

/// The index of the library `s` makes.
fn index(s: &Survey) -> Index {
    let displays: Vec<&str> = s.excitation.iter().filter_map(|e| e.display.as_deref()).collect();
    let profile = match displays.first() {
        Some(d) if displays.len() == s.excitation.len() && displays.iter().all(|x| x == d) => d.to_string(),
        _ => "lab recordings".to_string(),
    };
    let nan = Es { rect: f64::NAN, welch: f64::NAN };
    let entries = s
        .textures
        .iter()
        .map(|t| {
            let tag = t.cond.tag();
            let cell = format!("forces-{}/{}.json", t.material, crate::cells::name(&t.material, &t.cond));
            Entry {
                E_s: BTreeMap::new(),
                E_s_display_floor: nan,
                E_s_repeat: nan,
                cells: BTreeMap::from([("forces".to_string(), cell)]),
                condition: Condition { load_g: t.cond.mass, velocity_cm_s: t.cond.speed },
                forward_model: format!("models/forward-{tag}.json"),
                gain: BTreeMap::new(),
                model: format!("models/narx-{tag}.json"),
                profile: profile.clone(),
                tag,
                texture: t.material.clone(),
                training: Json::Null,
            }
        })
        .collect();
    Index {
        conditions: s.excitation.iter().map(|e| e.cond.tag()).collect(),
        entries,
        format: FORMAT.into(),
        samples: s.samples(),
        shard: None,
        version: 1,
    }
}

/// What a person should know about the survey and the models built.
fn notes(s: &Survey, models: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for e in &s.excitation {
        if e.binary {
            v.push(format!(
                "{}: a binary excitation (u = ±c) leaves the display's square-law amplitude unidentified; the \
                 forward model at {} is better made from a multilevel one (graphs/forward-build.toml's stepped \
                 5-level sequence, docs/rig.md)",
                e.path.display(),
                e.cond.label()
            ));
        }
        let f = models.join(format!("forward-{}.json", e.cond.tag()));
        if let Ok(m) = ForwardModel::load(&f) {
            if m.carrier_gain_n <= 0.0 {
                v.push(format!(
                    "models/forward-{}.json: carrier gain {:.4} N ≤ 0 — synth.live plays nothing at {}; record a \
                     multilevel excitation there",
                    e.cond.tag(),
                    m.carrier_gain_n,
                    e.cond.label()
                ));
            }
        }
    }
    for t in &s.textures {
        if !t.repeats.is_empty() {
            let others: Vec<String> = t.repeats.iter().map(|p| p.display().to_string()).collect();
            v.push(format!(
                "{} at {}: the cell is made from {} (the first by name); not used: {}",
                t.material,
                t.cond.label(),
                t.path.display(),
                others.join(", ")
            ));
        }
    }
    v
}

/// Builds the library: `progress` is called once per item done, with its
/// label. Fails, leaving no library, when any item fails (the error lists
/// each with its reason).
pub fn build(inputs: &Inputs, s: &Survey, progress: &(dyn Fn(&str) + Sync)) -> Result<Outcome> {
    fresh(&inputs.out)?;
    let created = !inputs.out.exists();
    std::fs::create_dir_all(&inputs.out).map_err(|e| io(&inputs.out, format!("cannot create: {e}")))?;
    let partial = inputs.out.join(".partial");
    let _ = std::fs::remove_dir_all(&partial);
    let result = build_in(inputs, s, &partial, progress);
    let _ = std::fs::remove_dir_all(&partial);
    if result.is_err() && created {
        let _ = std::fs::remove_dir(&inputs.out);
    }
    result
}

fn build_in(inputs: &Inputs, s: &Survey, partial: &Path, progress: &(dyn Fn(&str) + Sync)) -> Result<Outcome> {
    let mut todo: Vec<Item> = Vec::new();
    for k in 0..s.excitation.len() {
        todo.extend([Item::Forward(k), Item::Inverse(k)]);
    }
    todo.extend((0..s.textures.len()).map(Item::Forces));
    let at_1khz = s
        .excitation
        .iter()
        .map(|e| excitation::at_1khz(e, &partial.join("work").join("1khz")))
        .collect::<Result<Vec<PathBuf>>>()?;
    let never = AtomicBool::new(false);
    let mut failures = Failures::new();
    for_each_ordered(
        todo.clone(),
        inputs.jobs,
        &never,
        |_, item| run_item(inputs, s, &at_1khz, item, partial),
        |j, r| {
            let what = label(s, todo[j]);
            progress(&what);
            match r.map_err(|p| StudyError::Config(format!("panicked: {p}"))).and_then(|r| r) {
                Ok(_) => {}
                Err(e) => failures.push(what, e),
            }
        },
    );
    if !failures.is_empty() {
        return Err(StudyError::Config(format!(
            "{}\nnothing was written to {}",
            failures.summary(todo.len(), "items").trim_end(),
            inputs.out.display()
        )));
    }
    let _ = std::fs::remove_dir_all(partial.join("work"));
    let mut index = index(s);
    for e in &mut index.entries {
        e.training = training(&partial.join(&e.model));
    }
    let notes = notes(s, &partial.join("models"));
    // Into place: the models, each texture's cells, then the index.
    let mut moved = vec![PathBuf::from("models")];
    moved.extend(s.samples().iter().map(|m| PathBuf::from(format!("forces-{m}"))));
    for rel in &moved {
        let (from, to) = (partial.join(rel), inputs.out.join(rel));
        std::fs::rename(&from, &to).map_err(|e| io(&to, format!("cannot move into the library: {e}")))?;
    }
    let text = serde_json::to_string_pretty(&index).map_err(|e| io(&inputs.out, e))?;
    let path = inputs.out.join("index.json");
    evflow_engine::atomic_file::write_atomically(&path, text).map_err(|e| io(&path, format!("cannot write: {e}")))?;
    Ok(Outcome {
        dir: inputs.out.clone(),
        conditions: s.excitation.iter().map(|e| e.cond).collect(),
        samples: s.samples(),
        cells: s.textures.len(),
        forward_models: s
            .excitation
            .iter()
            .map(|e| inputs.out.join("models").join(format!("forward-{}.json", e.cond.tag())))
            .collect(),
        notes,
    })
}
